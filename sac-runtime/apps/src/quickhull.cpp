// The "quickhull" app: the self-adjusting quickhull of sacapps/quickhull.hpp, its
// conventional twin, and the App adapter.
#include "sacapps/quickhull.hpp"

#include <utility>

#include "sac/splitmix64.hpp"

#include "sacapps/contraction.hpp"
#include "sacapps/partition.hpp"

namespace sacapps::quickhull {
namespace {

// ------------------------------------------------------------------ policies (memo keys)

/// Filter predicate: strictly right of the edge a->b.
struct RightOf {
  Site a, b;
  bool operator()(const PointCell& c) const { return geom::right_of(a, b, c.value); }
  bool operator==(const RightOf&) const = default;
  std::size_t hash() const { return sac::hash_combine(a.hash(), b.hash()); }
};

/// Reducers over point lists: every value is a Site; Site{} (invalid) for the empty list.
struct Lowest {
  using value_type = Site;
  Site identity() const { return Site{}; }
  Site leaf(const PointCell& c) const { return site(c); }
  Site combine(const Site& s, const Site& t) const { return geom::lower(t, s) ? t : s; }
  bool operator==(const Lowest&) const = default;
  std::size_t hash() const { return 1; }
};

struct Highest {
  using value_type = Site;
  Site identity() const { return Site{}; }
  Site leaf(const PointCell& c) const { return site(c); }
  Site combine(const Site& s, const Site& t) const { return geom::higher(t, s) ? t : s; }
  bool operator==(const Highest&) const = default;
  std::size_t hash() const { return 2; }
};

struct FarthestRightOf {
  using value_type = Site;
  Site a, b;
  Site identity() const { return Site{}; }
  Site leaf(const PointCell& c) const { return site(c); }
  Site combine(const Site& s, const Site& t) const { return geom::farther(a, b, t, s) ? t : s; }
  bool operator==(const FarthestRightOf&) const = default;
  std::size_t hash() const { return sac::hash_combine(a.hash(), b.hash()); }
};

// ------------------------------------------------------------------ the self-adjusting program

/// What the edge a->b owns: the points beyond it and the farthest of them.
struct EdgeNode {
  PointList beyond;
  sac::Mod<Site> farthest;
};

/// What the whole hull owns: the two extreme points.
struct HullNode {
  sac::Mod<Site> lowest, highest;
};

void chain(sac::Engine& rt, Site a, Site b, const PointList* candidates, PointCell* rest,
           PointList* dst);

// The farthest point f beyond a->b is known: the output is chain(a, f) ++ f :: chain(f, b).
void chain_split(sac::Engine& rt, const Site& f, Site a, Site b, const PointList* beyond,
                 PointCell* rest, PointList* dst) {
  if (!f.valid()) {  // nothing beyond a->b: a->b is a hull edge
    rt.write(*dst, rest);
    return;
  }
  PointCell* vertex = rt.alloc<PointCell>(f.id, f.p, f.id);
  chain(rt, f, b, beyond, rest, &vertex->next);
  chain(rt, a, f, beyond, vertex, dst);
}

// Writes into *dst the hull vertices strictly right of a->b, from a to b, followed by rest.
void chain(sac::Engine& rt, Site a, Site b, const PointList* candidates, PointCell* rest,
           PointList* dst) {
  EdgeNode* edge = rt.alloc<EdgeNode>(std::pair(a.id, b.id));
  lists::filter(rt, *candidates, RightOf{a, b}, &edge->beyond);
  lists::reduce(rt, edge->beyond, FarthestRightOf{a, b}, &edge->farthest);
  rt.memo_read(edge->farthest,
               sac::fn<chain_split>(a, b, static_cast<const PointList*>(&edge->beyond), rest, dst));
}

void hull_from_extremes(sac::Engine& rt, const Site& hi, Site lo, const PointList* in,
                        PointList* dst) {
  PointCell* first = rt.alloc<PointCell>(lo.id, lo.p, lo.id);
  rt.write(*dst, first);
  if (hi.p == lo.p) {  // all points are equal
    rt.write(first->next, static_cast<PointCell*>(nullptr));
    return;
  }
  PointCell* top = rt.alloc<PointCell>(hi.id, hi.p, hi.id);
  chain(rt, lo, hi, in, top, &first->next);                          // the right side, upwards
  chain(rt, hi, lo, in, static_cast<PointCell*>(nullptr), &top->next);  // the left side, downwards
}

void hull_from_lowest(sac::Engine& rt, const Site& lo, const sac::Mod<Site>* highest,
                      const PointList* in, PointList* dst) {
  if (!lo.valid()) {  // no points
    rt.write(*dst, static_cast<PointCell*>(nullptr));
    return;
  }
  rt.read(*highest, sac::fn<hull_from_extremes>(lo, in, dst));
}

// ------------------------------------------------------------------ the conventional twin

void chain_conventional(const Site& a, const Site& b, const std::vector<Site>& candidates,
                        std::vector<Site>& out) {
  std::vector<Site> beyond;
  for (const Site& s : candidates)
    if (geom::right_of(a, b, s.p)) beyond.push_back(s);
  if (beyond.empty()) return;
  Site f = beyond[0];
  for (const Site& s : beyond)
    if (geom::farther(a, b, s, f)) f = s;
  chain_conventional(a, f, beyond, out);
  out.push_back(f);
  chain_conventional(f, b, beyond, out);
}

}  // namespace

void quickhull(sac::Engine& rt, const PointList& in, PointList* dst) {
  HullNode* hull = rt.alloc<HullNode>(&in);
  lists::reduce(rt, in, Lowest{}, &hull->lowest);
  lists::reduce(rt, in, Highest{}, &hull->highest);
  const sac::Mod<Site>* highest = &hull->highest;
  rt.memo_read(hull->lowest, sac::fn<hull_from_lowest>(highest, &in, dst));
}

std::vector<Site> quickhull_conventional(const std::vector<Site>& points) {
  std::vector<Site> out;
  if (points.empty()) return out;
  Site lo = points[0], hi = points[0];
  for (const Site& s : points) {
    if (geom::lower(s, lo)) lo = s;
    if (geom::higher(s, hi)) hi = s;
  }
  out.push_back(lo);
  if (hi.p == lo.p) return out;
  chain_conventional(lo, hi, points, out);
  out.push_back(hi);
  chain_conventional(hi, lo, points, out);
  return out;
}

// ------------------------------------------------------------------ the App adapters

Point PointApp::draw(std::uint64_t seed) const {
  auto unit = [](std::uint64_t x) { return static_cast<double>(x >> 11) * 0x1.0p-53; };  // [0, 1)
  std::uint64_t state = seed;  // the k-th try draws the k-th output of splitmix64(seed)
  for (;;) {
    const std::uint64_t r = sac::splitmix64(state);
    const Point p{unit(r), unit(sac::mix64(r))};
    if (distribution_ == Distribution::Square) return p;
    const double x = 2 * p.x - 1, y = 2 * p.y - 1;  // rejection sampling in the unit disk
    if (x * x + y * y < 1) return Point{x, y};
  }
}

const std::vector<Site>& PointApp::plain_input() {
  if (!plain_valid_) {
    plain_.clear();
    for (const PointCell* c = input_->head().get(); c; c = c->next.get())
      plain_.push_back(site(*c));
    plain_valid_ = true;
  }
  return plain_;
}

std::unique_ptr<App> QuickhullApp::clone_current() const {
  auto c = std::make_unique<QuickhullApp>(distribution_);
  c->copy_input_from(*this);
  return c;
}

void QuickhullApp::run_conventional() { conventional_ = quickhull_conventional(plain_input()); }

void QuickhullApp::run_self_adjusting() {
  begin_run();
  out_ = std::make_unique<PointList>();
  rt_->run([this](sac::Engine& rt) { quickhull(rt, input_->head(), out_.get()); });
}

bool QuickhullApp::verify() {
  if (!ran()) return false;
  run_conventional();
  std::vector<Site> got;
  for (const PointCell* c = out_->get(); c; c = c->next.get()) got.push_back(site(*c));
  return got == conventional_;
}

}  // namespace sacapps::quickhull

namespace sacapps {
std::unique_ptr<App> make_quickhull() { return std::make_unique<quickhull::QuickhullApp>(); }
}  // namespace sacapps
