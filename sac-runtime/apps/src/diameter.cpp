// The "diameter" app: the self-adjusting diameter of sacapps/diameter.hpp, its conventional
// twin, and the App adapter.
#include "sacapps/diameter.hpp"

#include <algorithm>

#include "sacapps/contraction.hpp"

namespace sacapps::diameter {
namespace {

using quickhull::PointCell;
using quickhull::PointList;

/// Reducer over hull vertices: the largest squared distance from `from`.
struct FarthestFrom {
  using value_type = double;
  Site from;
  double identity() const { return 0; }
  double leaf(const PointCell& c) const { return geom::dist2(from.p, c.value); }
  double combine(double a, double b) const { return std::max(a, b); }
  bool operator==(const FarthestFrom&) const = default;
  std::size_t hash() const { return from.hash(); }
};

/// Reducer over the per-vertex results (an RList<double>): the largest.
struct Largest {
  using value_type = double;
  double identity() const { return 0; }
  double combine(double a, double b) const { return std::max(a, b); }
  bool operator==(const Largest&) const = default;
  std::size_t hash() const { return 3; }
};

/// What the computation owns: the hull and, per hull vertex, its farthest distance.
struct DiameterNode {
  PointList hull;
  lists::RList<double> spans;
};

// For hull vertex v (and the vertices after it): a cell whose value is v's farthest distance.
void spans_step(sac::Engine& rt, PointCell* v, const PointList* hull, lists::RList<double>* dst) {
  if (!v) {
    rt.write(*dst, static_cast<lists::RCell<double>*>(nullptr));
    return;
  }
  lists::RCell<double>* span = rt.alloc<lists::RCell<double>>(v->id, v->id);
  lists::reduce(rt, *hull, FarthestFrom{quickhull::site(*v)}, &span->value);
  rt.write(*dst, span);
  rt.memo_read(v->next, sac::fn<spans_step>(hull, &span->next));
}

}  // namespace

void diameter(sac::Engine& rt, const PointList& in, sac::Mod<double>* dst) {
  DiameterNode* node = rt.alloc<DiameterNode>(&in);
  quickhull::quickhull(rt, in, &node->hull);
  const PointList* hull = &node->hull;
  rt.memo_read(*hull, sac::fn<spans_step>(hull, &node->spans));
  lists::reduce(rt, node->spans, Largest{}, dst);
}

double diameter_conventional(const std::vector<Site>& points) {
  const std::vector<Site> hull = quickhull::quickhull_conventional(points);
  double best = 0;
  for (const Site& v : hull)
    for (const Site& w : hull) best = std::max(best, geom::dist2(v.p, w.p));
  return best;
}

std::unique_ptr<App> DiameterApp::clone_current() const {
  auto c = std::make_unique<DiameterApp>(distribution_);
  c->copy_input_from(*this);
  return c;
}

void DiameterApp::run_conventional() { conventional_ = diameter_conventional(plain_input()); }

void DiameterApp::run_self_adjusting() {
  begin_run();
  out_ = std::make_unique<sac::Mod<double>>();
  rt_->run([this](sac::Engine& rt) { diameter(rt, input_->head(), out_.get()); });
}

bool DiameterApp::verify() {
  if (!ran()) return false;
  run_conventional();
  return out_->get() == conventional_;
}

}  // namespace sacapps::diameter

namespace sacapps {
std::unique_ptr<App> make_diameter() { return std::make_unique<diameter::DiameterApp>(); }
}  // namespace sacapps
