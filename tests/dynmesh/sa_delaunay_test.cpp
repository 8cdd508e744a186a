// sa_delaunay_test.cpp — src/hpu/sa_delaunay.hpp, the self-adjusting Delaunay triangulation:
// from scratch and after every update (single and batched, on random and on degenerate
// points) its triangles equal the static twin's (src/geometry/delaunay.hpp) on the current points;
// the engine's and the triangulation's invariants hold; the trace distance of an update is
// a small fraction of the from-scratch trace (printed, and bounded to catch a program that
// re-runs everything); the star building block, read in a later run, stays up to date.
#include "hpu/sa_delaunay.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <iterator>
#include <memory>
#include <random>
#include <set>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <sac/engine.hpp>

#include "geometry/delaunay.hpp"
#include "dynamic_test_support.hpp"
#include "same_triangles.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"

namespace {

using namespace dynmesh;
using detail::Delaunay;
using detail::SaDelaunay;
using detail::SaDelaunayProgram;
using detail::SaInputNode;
using detail::SaVertex;
using dynmesh_test::kSlowBuild;

// ------------------------------------------------------------------ the static twin

std::vector<Triangle> static_triangles(const Box<2>& box, std::span<const Point<2>> pts) {
  Delaunay dt(box);
  std::vector<Delaunay::Tid> created;
  Delaunay::Tid hint = dt.any_live();
  for (const auto& p : pts) {
    created.clear();
    if (dt.insert(p, hint, created) && !created.empty()) hint = created.back();
  }
  dt.check_invariants();
  return dt.triangles();
}

using dynmesh_test::same_triangles;

/// The static twin's star of each centre, as points (Delaunay::star's order).
std::vector<std::vector<Point<2>>> static_stars(const Box<2>& box, std::span<const Point<2>> pts,
                                                std::span<const Point<2>> centres) {
  Delaunay dt(box);
  std::vector<Delaunay::Tid> created;
  for (const auto& p : pts) {
    created.clear();
    dt.insert(p, dt.any_live(), created);
  }
  std::vector<std::vector<Point<2>>> out;
  std::vector<Delaunay::Vid> star;
  for (const auto& c : centres) {
    Delaunay::Vid v = 0;
    while (v < dt.num_vertices() && dt.point(v) != c) ++v;
    dt.star(v, star);
    std::vector<Point<2>>& ring = out.emplace_back();
    for (Delaunay::Vid u : star) ring.push_back(dt.point(u));
  }
  return out;
}

/// An interior vertex's ring is a cycle: start it at its (x, y)-smallest point.
std::vector<Point<2>> normalized_ring(std::vector<Point<2>> ring, const Point<2>& centre, const Box<2>& box) {
  const double x1 = box.origin[0] + box.side, y1 = box.origin[1] + box.side;
  const bool boundary = centre[0] == box.origin[0] || centre[1] == box.origin[1] || centre[0] == x1 || centre[1] == y1;
  if (!boundary && !ring.empty())
    std::rotate(ring.begin(), std::min_element(ring.begin(), ring.end(), xy_less), ring.end());
  return ring;
}

// ------------------------------------------------------------------ the mutator

/// Distinct random points in the open box, never a corner, never one used before.
class PointSource {
 public:
  PointSource(std::uint64_t seed, const Box<2>& box) : rng_(seed), box_(box) {
    const double x0 = box.origin[0], y0 = box.origin[1], x1 = x0 + box.side, y1 = y0 + box.side;
    used_ = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  }
  Point<2> fresh() {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (;;) {
      const Point<2> p{box_.origin[0] + u(rng_) * box_.side, box_.origin[1] + u(rng_) * box_.side};
      if (used_.insert(p).second) return p;
    }
  }
  std::vector<Point<2>> fresh(std::size_t n) {
    std::vector<Point<2>> out;
    for (std::size_t i = 0; i < n; ++i) out.push_back(fresh());
    return out;
  }
  std::size_t below(std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_); }
  bool coin() { return below(2) == 0; }
  std::mt19937_64& rng() { return rng_; }

 private:
  std::mt19937_64 rng_;
  Box<2> box_;
  std::set<Point<2>> used_;
};

/// Sink of a star read: the ring's points, written to a modifiable the test reads.
struct StarSink {
  sac::Mod<std::vector<Point<2>>>* out;
  void operator()(sac::Engine& e, std::span<SaVertex* const> ring, std::span<detail::SaTri* const>, bool) const {
    std::vector<Point<2>> pts;
    for (const SaVertex* v : ring) pts.push_back(v->p);
    e.write(*out, std::move(pts));
  }
};

/// The program on a mutator-owned list: inserts and deletes relink the list with
/// Engine::set; propagate() retires the nodes of deleted points.
class SaHarness {
 public:
  SaHarness(const Box<2>& box, std::span<const Point<2>> pts)
      : box_(box), dt_{&registry_, box}, program_{&dt_, &head_} {
    for (const auto& p : pts) order_.push_back(make_node(p));
    for (std::size_t i = 0; i < order_.size(); ++i)
      engine_.set(order_[i]->next, i + 1 < order_.size() ? order_[i + 1] : nullptr);
    engine_.set(head_, order_.empty() ? nullptr : order_.front());
    engine_.run([this](sac::Engine& e) { SaDelaunayProgram::main(e, &program_); });
  }

  void insert_at(std::size_t pos, const Point<2>& p) {
    SaInputNode* n = make_node(p);
    engine_.set(n->next, pos < order_.size() ? order_[pos] : nullptr);
    engine_.set(link_before(pos), n);
    order_.insert(order_.begin() + static_cast<std::ptrdiff_t>(pos), n);
  }
  void erase_at(std::size_t pos) {
    SaInputNode* n = order_[pos];
    engine_.set(link_before(pos), n->next.get());
    order_.erase(order_.begin() + static_cast<std::ptrdiff_t>(pos));
    erased_.push_back(n);
  }
  /// Propagates, then frees the erased nodes: nothing in the trace may read them any more.
  void propagate() {
    engine_.propagate();
    for (SaInputNode* n : erased_) {
      ASSERT_TRUE(engine_.unused(n->next)) << "the trace still reads an erased node";
      engine_.retire(n->next);
      nodes_.erase(std::find_if(nodes_.begin(), nodes_.end(), [n](const auto& q) { return q.get() == n; }));
    }
    erased_.clear();
  }

  std::size_t size() const { return order_.size(); }
  const Point<2>& point_at(std::size_t i) const { return order_[i]->point; }
  std::vector<Point<2>> points() const {
    std::vector<Point<2>> out;
    for (const SaInputNode* n : order_) out.push_back(n->point);
    return out;
  }
  std::vector<Triangle> triangles() const { return registry_.triangles(); }
  void check() const {
    engine_.check_invariants();
    registry_.check_invariants(box_);
  }
  const sac::Stats& stats() const { return engine_.stats(); }

  /// A second run, after the program's: the stars of these vertices, kept up to date.
  void watch_stars(std::span<const Point<2>> centres) {
    std::vector<SaVertex*> vs;
    for (const auto& c : centres) {
      SaVertex* v = nullptr;
      for (const detail::SaTri* t : registry_.all())
        for (SaVertex* x : t->v)
          if (x->p == c) v = x;
      ASSERT_NE(v, nullptr) << to_string(c) << " is not a vertex";
      vs.push_back(v);
      star_out_.emplace_back();
    }
    engine_.run([this, vs](sac::Engine& e) {
      for (std::size_t i = 0; i < vs.size(); ++i) SaDelaunay::read_star(e, vs[i], StarSink{&star_out_[i]});
    });
  }
  std::vector<std::vector<Point<2>>> stars() const {
    std::vector<std::vector<Point<2>>> out;
    for (const auto& m : star_out_) out.push_back(m.get());
    return out;
  }

 private:
  SaInputNode* make_node(const Point<2>& p) { return nodes_.emplace_back(std::make_unique<SaInputNode>(p)).get(); }
  sac::Mod<SaInputNode*>& link_before(std::size_t pos) { return pos == 0 ? head_ : order_[pos - 1]->next; }

  // Declared before the engine, so destroyed after it: its records and allocations refer
  // to these (SaTri's destructor to the registry).
  Box<2> box_;
  detail::SaTriRegistry registry_;
  std::vector<std::unique_ptr<SaInputNode>> nodes_;
  std::deque<sac::Mod<std::vector<Point<2>>>> star_out_;
  sac::Mod<SaInputNode*> head_;
  sac::Engine engine_;
  SaDelaunay dt_;
  SaDelaunayProgram program_;
  std::vector<SaInputNode*> order_;   // the list, in order
  std::vector<SaInputNode*> erased_;  // unlinked, freed after the next propagate()
};

/// The seed, printed (and traced by the caller's SCOPED_TRACE).
std::string seed_note(std::uint64_t seed) {
  std::printf("[ SaDelaunay ] seed %llu\n", static_cast<unsigned long long>(seed));
  return "seed " + std::to_string(seed);
}

void expect_matches_static(const SaHarness& h, const Box<2>& box) {
  const auto pts = h.points();
  EXPECT_TRUE(same_triangles(h.triangles(), static_triangles(box, pts)));
  EXPECT_NO_THROW(h.check());
}

// ------------------------------------------------------------------ from scratch

TEST(SaDelaunay, FromScratchUniformEqualsTheStaticTwin) {
  const std::uint64_t seed = 17;
  SCOPED_TRACE(seed_note(seed));
  const Box<2> box{{0, 0}, 1};
  PointSource src(seed, box);
  const auto pts = src.fresh(kSlowBuild ? 300 : 2000);
  SaHarness h(box, pts);
  expect_matches_static(h, box);
  EXPECT_EQ(h.triangles().size(), 2 * (pts.size() + 4) - 4 - 2);  // Euler, no point on a side
  std::printf("[ SaDelaunay ] from scratch, n = %zu: %llu events\n", pts.size(),
              static_cast<unsigned long long>(h.stats().events_created));
}

/// An integer grid including points on all four sides (not the corners, which are the
/// box's own): exactly cocircular quadruples everywhere, and side splits.
std::vector<Point<2>> grid_without_corners(int side) {
  std::vector<Point<2>> pts;
  for (int i = 0; i <= side; ++i)
    for (int j = 0; j <= side; ++j) {
      const bool corner = (i == 0 || i == side) && (j == 0 || j == side);
      if (!corner) pts.push_back({double(i), double(j)});
    }
  return pts;
}

TEST(SaDelaunay, FromScratchCocircularGridWithPointsOnTheSides) {
  const std::uint64_t seed = 23;
  SCOPED_TRACE(seed_note(seed));
  const int side = 12;
  const Box<2> box{{0, 0}, double(side)};
  auto pts = grid_without_corners(side);
  std::mt19937_64 rng(seed);
  for (int order = 0; order < 3; ++order) {
    SCOPED_TRACE("order " + std::to_string(order));
    std::shuffle(pts.begin(), pts.end(), rng);
    SaHarness h(box, pts);
    expect_matches_static(h, box);
    EXPECT_EQ(h.triangles().size(), std::size_t{2 * side * side});
  }
}

TEST(SaDelaunay, FromScratchCollinearPoints) {
  const std::uint64_t seed = 29;
  SCOPED_TRACE(seed_note(seed));
  const Box<2> box{{0, 0}, 8};
  std::set<Point<2>> s;
  for (int k = 0; k <= 128; ++k) s.insert({k / 16.0, 3.0});          // a line from side to side
  for (int k = 1; k < 128; ++k) s.insert({k / 16.0, k / 16.0});      // the diagonal, crossing it
  for (int k = 1; k < 64; ++k) s.insert({0.0, k / 8.0});             // on the left side
  std::vector<Point<2>> pts(s.begin(), s.end());
  std::mt19937_64 rng(seed);
  for (int order = 0; order < 2; ++order) {
    SCOPED_TRACE("order " + std::to_string(order));
    if (order > 0) std::shuffle(pts.begin(), pts.end(), rng);  // order 0: sorted, the worst walks
    SaHarness h(box, pts);
    expect_matches_static(h, box);
  }
  // A single line alone.
  std::vector<Point<2>> line;
  for (int k = 1; k < 128; ++k) line.push_back({k / 16.0, 5.0});
  std::shuffle(line.begin(), line.end(), rng);
  SaHarness h(box, line);
  expect_matches_static(h, box);
}

// ------------------------------------------------------------------ updates

TEST(SaDelaunay, EveryUpdateMatchesAFromScratchStaticBuild) {
  const std::uint64_t seed = 20240611;
  SCOPED_TRACE(seed_note(seed));
  const Box<2> box{{0, 0}, 1};
  PointSource src(seed, box);
  const std::size_t n = kSlowBuild ? 200 : 1000;
  const int updates = kSlowBuild ? 60 : 300;
  SaHarness h(box, src.fresh(n));
  expect_matches_static(h, box);
  const std::uint64_t scratch = h.stats().events_created;
  std::vector<std::uint64_t> distance, reexecuted;
  for (int u = 0; u < updates; ++u) {
    SCOPED_TRACE("update " + std::to_string(u));
    if (h.size() > 0 && src.coin()) h.erase_at(src.below(h.size()));
    else h.insert_at(src.below(h.size() + 1), src.fresh());
    h.propagate();
    distance.push_back(h.stats().last_trace_distance);
    reexecuted.push_back(h.stats().last_reexecuted);
    ASSERT_TRUE(same_triangles(h.triangles(), static_triangles(box, h.points())));
    if ((u + 1) % 25 == 0) {
      ASSERT_NO_THROW(h.check());
    }
  }
  const auto mean = [](const std::vector<std::uint64_t>& v) {
    double s = 0;
    for (auto x : v) s += double(x);
    return s / double(v.size());
  };
  const auto max = [](const std::vector<std::uint64_t>& v) {
    return static_cast<unsigned long long>(*std::max_element(v.begin(), v.end()));
  };
  const double mean_distance = mean(distance);
  // Trace distance: events created + undone by the propagation (sac/stats.hpp).
  std::printf("[ SaDelaunay ] n = %zu, %d updates: from scratch %llu events; per update trace distance "
              "mean %.1f (%.2f%% of from scratch) max %llu; reads re-executed mean %.1f max %llu\n",
              n, updates, static_cast<unsigned long long>(scratch), mean_distance,
              100.0 * mean_distance / double(scratch), max(distance), mean(reexecuted), max(reexecuted));
  // A figure, not a tight bound: a program that re-ran the triangulation would be near 100%.
  EXPECT_LT(mean_distance, 0.05 * double(scratch));
}

TEST(SaDelaunay, BatchesOfInsertionsAndDeletions) {
  const std::uint64_t seed = 31;
  SCOPED_TRACE(seed_note(seed));
  const Box<2> box{{0, 0}, 1};
  PointSource src(seed, box);
  SaHarness h(box, src.fresh(kSlowBuild ? 200 : 1000));
  for (int batch = 0; batch < 4; ++batch) {
    SCOPED_TRACE("batch " + std::to_string(batch));
    for (int i = 0; i < 10; ++i) h.insert_at(src.below(h.size() + 1), src.fresh());
    // Deletions may hit nodes inserted in this same batch (linked and unlinked unseen).
    for (int i = 0; i < 10; ++i) h.erase_at(src.below(h.size()));
    h.propagate();
    std::printf("[ SaDelaunay ] batch %d (10 insertions, 10 deletions): trace distance %llu of %llu live events\n",
                batch, static_cast<unsigned long long>(h.stats().last_trace_distance),
                static_cast<unsigned long long>(h.stats().live_events));
    expect_matches_static(h, box);
  }
}

/// Updates on the cocircular grid: insertion and deletion of points on the sides (splits
/// and merges of side edges) and in the middle of exactly cocircular groups.
TEST(SaDelaunay, UpdatesOnTheCocircularGridWithSides) {
  const std::uint64_t seed = 37;
  SCOPED_TRACE(seed_note(seed));
  const int side = 10;
  const Box<2> box{{0, 0}, double(side)};
  auto all = grid_without_corners(side);
  std::mt19937_64 rng(seed);
  std::shuffle(all.begin(), all.end(), rng);
  const std::vector<Point<2>> start(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(all.size() / 2));
  std::vector<Point<2>> absent(all.begin() + static_cast<std::ptrdiff_t>(all.size() / 2), all.end());
  SaHarness h(box, start);
  expect_matches_static(h, box);
  const auto below = [&](std::size_t k) { return std::uniform_int_distribution<std::size_t>(0, k - 1)(rng); };
  for (int u = 0; u < (kSlowBuild ? 40 : 150); ++u) {
    SCOPED_TRACE("update " + std::to_string(u));
    if (absent.empty() || (h.size() > 0 && below(2) == 0)) {
      const std::size_t i = below(h.size());
      absent.push_back(h.point_at(i));
      h.erase_at(i);
    } else {
      const std::size_t j = below(absent.size());
      h.insert_at(below(h.size() + 1), absent[j]);
      absent.erase(absent.begin() + static_cast<std::ptrdiff_t>(j));
    }
    h.propagate();
    ASSERT_TRUE(same_triangles(h.triangles(), static_triangles(box, h.points())));
    if ((u + 1) % 25 == 0) {
      ASSERT_NO_THROW(h.check());
    }
  }
}

// ------------------------------------------------------------------ stars

/// read_star in a run after the program's: equal to Delaunay::star for the corners and for
/// points that stay, from scratch and after each update.
TEST(SaDelaunay, StarsReadInTheTraceStayUpToDate) {
  const std::uint64_t seed = 41;
  SCOPED_TRACE(seed_note(seed));
  const Box<2> box{{0, 0}, 1};
  PointSource src(seed, box);
  auto pts = src.fresh(kSlowBuild ? 100 : 300);
  pts.push_back({0.5, 0.0});  // on a side
  SaHarness h(box, pts);
  std::vector<Point<2>> centres{{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0.0}};
  for (std::size_t i = 0; i < 8; ++i) centres.push_back(pts[i]);  // interior points that stay
  h.watch_stars(centres);
  const std::set<Point<2>> keep(centres.begin(), centres.end());
  const auto compare = [&] {
    const auto want = static_stars(box, h.points(), centres);
    const auto got = h.stars();
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < got.size(); ++i)
      EXPECT_EQ(normalized_ring(got[i], centres[i], box), normalized_ring(want[i], centres[i], box))
          << "star of " << to_string(centres[i]);
  };
  compare();
  for (int u = 0; u < (kSlowBuild ? 20 : 60); ++u) {
    SCOPED_TRACE("update " + std::to_string(u));
    if (src.coin()) {
      std::size_t i = src.below(h.size());
      while (keep.count(h.point_at(i))) i = src.below(h.size());
      h.erase_at(i);
    } else {
      // Near a watched centre half of the time, so its star changes.
      Point<2> p = src.fresh();
      if (src.coin()) {
        const Point<2>& c = centres[4 + src.below(centres.size() - 4)];
        p = {std::clamp(c[0] + (p[0] - 0.5) * 0.05, 0.001, 0.999), std::clamp(c[1] + (p[1] - 0.5) * 0.05, 0.0, 0.999)};
        if (keep.count(p)) continue;
        bool dup = false;
        for (const auto& q : h.points()) dup = dup || q == p;
        if (dup) continue;
      }
      h.insert_at(src.below(h.size() + 1), p);
    }
    h.propagate();
    compare();
  }
  EXPECT_NO_THROW(h.check());
}

}  // namespace
