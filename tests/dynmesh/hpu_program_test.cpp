// hpu_program_test.cpp — src/hpu/hpu_program.hpp, DynHPU's off-center refinement as a
// self-adjusting program: from scratch (uniform, clustered, points near and on the box
// sides, a grid) and after every update of a dynamic run, its triangles equal the static
// twin HpuMesh's on the current points at 20.7°, 25° and 30°; the engine's and the
// triangulation's invariants hold; the per-update trace distance is printed against the
// from-scratch trace, and bounded to catch a program that re-runs everything.
#include "hpu/hpu_program.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <sac/engine.hpp>

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/edit.hpp"
#include "hpu/hpu_geometry.hpp"
#include "hpu/hpu_inputs.hpp"
#include "hpu/sa_delaunay.hpp"
#include "../sanitized.hpp"
#include "same_triangles.hpp"

namespace {

using namespace dynmesh;
using detail::HpuProgram;
using detail::SaInputNode;
using test_support::kSanitized;

using dynmesh_test::same_triangles;

/// The program on the mutator's input list (HpuInputs: the inputs and their side
/// midpoints in insertion order). set_points() turns the new point set into edits, relinks
/// the list, propagates, and frees the nodes that left.
class HpuHarness {
 public:
  HpuHarness(const Box<2>& box, const std::vector<Point<2>>& pts, double angle)
      : box_(box), inputs_(box), dt_{&registry_, box}, program_(&dt_, &inputs_.head(), angle) {
    set_list(pts);
    engine_.run([this](sac::Engine& e) { HpuProgram::main(e, &program_); });
    registry_.clear_change();
  }
  ~HpuHarness() { registry_.close(); }

  void set_points(const std::vector<Point<2>>& pts) {
    set_list(pts);
    engine_.propagate();
    inputs_.release(engine_);
  }

  std::vector<Triangle> triangles() const { return registry_.triangles(); }
  MeshChange take_change() { return registry_.take_change(); }
  void check() const {
    engine_.check_invariants();
    registry_.check_invariants(box_);
    const std::vector<Point<2>> now(points_.begin(), points_.end());
    inputs_.check_invariants(now);
  }
  const sac::Stats& stats() const { return engine_.stats(); }
  /// For the checker's negative test: the feed counts one live triangle too many.
  void corrupt_live_count() { registry_.corrupt_live_count_for_testing(); }

 private:
  void set_list(const std::vector<Point<2>>& pts) {
    const std::set<Point<2>> next(pts.begin(), pts.end());
    std::vector<Edit<2>> edits;
    for (const Point<2>& p : points_)
      if (!next.count(p)) edits.push_back({EditOp::Delete, p});
    for (const Point<2>& p : next)
      if (!points_.count(p)) edits.push_back({EditOp::Insert, p});
    inputs_.commit(engine_, inputs_.plan(edits));
    points_ = next;
  }

  // Declared before the engine, so destroyed after it.
  Box<2> box_;
  detail::SaTriRegistry registry_;
  detail::HpuInputs inputs_;
  std::set<Point<2>> points_;
  sac::Engine engine_;
  detail::SaDelaunay dt_;
  HpuProgram program_;
};

std::string seed_note(std::uint64_t seed) {
  std::printf("[ HpuProgram ] seed %llu\n", static_cast<unsigned long long>(seed));
  return "seed " + std::to_string(seed);
}

constexpr double kAngles[] = {kHpuDefaultMinAngle, 25.0, 30.0};

void expect_from_scratch(const Box<2>& box, const std::vector<Point<2>>& pts) {
  for (const double angle : kAngles) {
    SCOPED_TRACE("angle " + std::to_string(angle));
    const HpuMesh twin(box, pts, angle);
    HpuHarness h(box, pts, angle);
    std::printf("[ HpuProgram ] n = %zu, %.1f°: %zu triangles, %zu off-centers, %zu side splits\n", pts.size(), angle,
                twin.triangles().size(), twin.stats().off_centers, twin.stats().side_splits);
    EXPECT_TRUE(same_triangles(h.triangles(), twin.triangles()));
    EXPECT_NO_THROW(h.check());
  }
}

// ------------------------------------------------------------------ from scratch

TEST(HpuProgram, FromScratchUniform) {
  const std::uint64_t seed = 101;
  SCOPED_TRACE(seed_note(seed));
  const Box<2> box{{0, 0}, 1};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Point<2>> pts;
  for (int i = 0; i < (kSanitized ? 80 : 300); ++i) pts.push_back({u(rng), u(rng)});
  expect_from_scratch(box, pts);
}

TEST(HpuProgram, FromScratchClustered) {
  const std::uint64_t seed = 103;
  SCOPED_TRACE(seed_note(seed));
  const auto pts = generate<2>(Distribution::Clusters, kSanitized ? 80 : 300, seed);
  expect_from_scratch(derive_box<2>(pts), pts);
}

TEST(HpuProgram, FromScratchPointsNearAndOnTheSides) {
  const std::uint64_t seed = 107;
  SCOPED_TRACE(seed_note(seed));
  const Box<2> box{{0, 0}, 4};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.01, 3.99);
  std::set<Point<2>> s;
  for (int i = 0; i < (kSanitized ? 8 : 20); ++i) {
    const double t = u(rng), w = u(rng) * 0.002;
    // Points lie in [o, o + L) (box.hpp): on the near sides, close to all four.
    s.insert({t, 0.0});                 // on the bottom
    s.insert({0.0, t});                 // on the left
    s.insert({3.999 - w, t});           // near the right
    s.insert({t, 3.999 - w});           // near the top
    s.insert({w + 0.001, u(rng)});      // near the left
  }
  s.insert({2.0, 0.0});
  s.insert({0.0, 2.0});
  s.insert({0.0, 0.0});  // the near corner, an input too
  for (int i = 0; i < 10; ++i) s.insert({u(rng), u(rng)});
  expect_from_scratch(box, std::vector<Point<2>>(s.begin(), s.end()));
}

TEST(HpuProgram, FromScratchSmallGrids) {
  const std::uint64_t seed = 109;
  SCOPED_TRACE(seed_note(seed));
  const Box<2> box{{0, 0}, 8};
  // A square grid (cocircular everywhere, nothing to refine) with one point on a side, and a
  // grid of 1 × 1/4 cells (skinny cocircular triangles, refined).
  for (const double dy : {1.0, 0.25}) {
    SCOPED_TRACE("dy " + std::to_string(dy));
    std::vector<Point<2>> pts;
    for (int i = 1; i < 8; ++i)
      for (double y = dy; y < 8.0; y += dy) pts.push_back({double(i), y});
    pts.push_back({4.0, 0.0});
    expect_from_scratch(box, pts);
  }
}

// ------------------------------------------------------------------ updates

/// Random updates (insert a fresh point or delete a present one), each propagated and
/// compared with a fresh twin; the invariants every 10. Returns the per-update trace
/// distances and sets `scratch` to the from-scratch event count.
template <class Fresh>
std::vector<std::uint64_t> run_updates(const Box<2>& box, std::vector<Point<2>> pts, Fresh fresh, double angle,
                                       int updates, std::mt19937_64& rng, std::uint64_t& scratch) {
  std::vector<std::uint64_t> distance;
  HpuHarness h(box, pts, angle);
  EXPECT_TRUE(same_triangles(h.triangles(), HpuMesh(box, pts, angle).triangles()));
  scratch = h.stats().events_created;
  std::vector<Triangle> mesh = h.triangles();
  for (int k = 0; k < updates; ++k) {
    SCOPED_TRACE("update " + std::to_string(k));
    if (!pts.empty() && rng() % 2 == 0) pts.erase(pts.begin() + static_cast<std::ptrdiff_t>(rng() % pts.size()));
    else pts.push_back(fresh());
    h.set_points(pts);
    distance.push_back(h.stats().last_trace_distance);
    // The change feed replays: the last mesh, less what it removed, plus what it added.
    EXPECT_TRUE(apply_change(mesh, h.take_change()));
    EXPECT_EQ(mesh, h.triangles()) << "the feed does not replay to the new mesh";
    const bool same = same_triangles(h.triangles(), HpuMesh(box, pts, angle).triangles());
    EXPECT_TRUE(same);
    if (!same) break;
    if ((k + 1) % 10 == 0) {
      EXPECT_NO_THROW(h.check());
    }
  }
  return distance;
}

TEST(HpuProgram, EveryUpdateMatchesAFromScratchTwin) {
  const std::uint64_t seed = 20261123;
  SCOPED_TRACE(seed_note(seed));
  const Box<2> box{{0, 0}, 1};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t n = kSanitized ? 60 : 200;
  const int updates = kSanitized ? 15 : 60;
  std::set<Point<2>> used;
  const auto fresh = [&] {
    for (;;) {
      const Point<2> p{u(rng), u(rng)};
      if (used.insert(p).second) return p;
    }
  };
  std::vector<Point<2>> pts;
  for (std::size_t i = 0; i < n; ++i) pts.push_back(fresh());
  std::uint64_t scratch = 0;
  const auto distance = run_updates(box, pts, fresh, kHpuDefaultMinAngle, updates, rng, scratch);
  ASSERT_EQ(distance.size(), std::size_t(updates));
  std::vector<std::uint64_t> sorted = distance;
  std::sort(sorted.begin(), sorted.end());
  double mean = 0;
  for (auto x : distance) mean += double(x);
  mean /= double(distance.size());
  const auto pct = [&](double x) { return 100.0 * x / double(scratch); };
  // Trace distance: events created + undone by the propagation (sac/stats.hpp).
  std::printf("[ HpuProgram ] n = %zu, %d updates: from scratch %llu events; per update trace distance mean %.1f "
              "(%.2f%%) median %llu (%.2f%%) max %llu (%.2f%%)\n",
              n, updates, static_cast<unsigned long long>(scratch), mean, pct(mean),
              static_cast<unsigned long long>(sorted[sorted.size() / 2]), pct(double(sorted[sorted.size() / 2])),
              static_cast<unsigned long long>(sorted.back()), pct(double(sorted.back())));
  // A figure, not a tight bound: a program that re-ran the refinement would be near 100%.
  EXPECT_LT(mean, 0.25 * double(scratch));
}

/// Updates next to and on the box's near sides at 30°: side midpoints come and go with
/// them (the mutator's list changes by more than one point), and the refinement splits
/// sides.
TEST(HpuProgram, UpdatesNearTheSidesAt30Degrees) {
  const std::uint64_t seed = 127;
  SCOPED_TRACE(seed_note(seed));
  const Box<2> box{{0, 0}, 4};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.01, 3.99);
  std::set<Point<2>> used;
  const auto fresh = [&] {
    for (;;) {
      const double t = u(rng), w = u(rng) * 0.01;
      const std::uint64_t kind = rng() % 4;
      const Point<2> p = kind == 0 ? Point<2>{t, 0.0} : kind == 1 ? Point<2>{0.0, t} : kind == 2 ? Point<2>{3.99 - w, t}
                                                                                                 : Point<2>{t, u(rng)};
      if (used.insert(p).second) return p;
    }
  };
  std::vector<Point<2>> pts;
  for (int i = 0; i < (kSanitized ? 20 : 60); ++i) pts.push_back(fresh());
  std::uint64_t scratch = 0;
  const auto distance = run_updates(box, pts, fresh, 30.0, kSanitized ? 10 : 40, rng, scratch);
  double mean = 0;
  for (auto x : distance) mean += double(x);
  std::printf("[ HpuProgram ] near the sides, 30°: from scratch %llu events; per update trace distance mean %.1f\n",
              static_cast<unsigned long long>(scratch), mean / double(std::max<std::size_t>(1, distance.size())));
}

}  // namespace

namespace {

// ------------------------------------------------------------------ the side crossed

/// Sink of side_edge_at: the edge's end points, written to a modifiable the test reads.
struct EdgeSink {
  sac::Mod<std::pair<Point<2>, Point<2>>>* out;
  friend bool operator==(const EdgeSink&, const EdgeSink&) = default;
  std::size_t hash() const noexcept { return sac::Hash<void*>{}(out); }
  void operator()(sac::Engine& e, detail::SaVertex* a, detail::SaVertex* b) const { e.write(*out, std::pair{a->p, b->p}); }
};

/// The refinement's side rule (never reached on the inputs above: no vertex encroaches a box
/// edge, so an empty leaf crosses a side only in degenerate cases), tested on its own:
/// side_edge_at on a triangulation with many side vertices equals the twin's
/// std::map::upper_bound rule, for X at every side vertex, between them, and at both ends.
TEST(HpuProgram, SideEdgeAtFollowsTheTwinsUpperBoundRule) {
  const std::uint64_t seed = 113;
  SCOPED_TRACE(seed_note(seed));
  const Box<2> box{{0, 0}, 8};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 8.0);
  std::set<Point<2>> s;
  for (int i = 0; i < 40; ++i) s.insert({u(rng), u(rng)});
  for (int i = 0; i < 6; ++i) s.insert({u(rng), 0.0}), s.insert({0.0, u(rng)});
  s.insert({0.0, 4.0});
  std::vector<Point<2>> inputs(s.begin(), s.end());
  for (const auto& m : detail::side_midpoints(box, inputs)) s.insert(m);
  // The triangulation of the points, then queries in a second run.
  detail::SaTriRegistry registry;
  std::vector<std::unique_ptr<SaInputNode>> nodes;
  std::deque<sac::Mod<std::pair<Point<2>, Point<2>>>> outs;
  sac::Mod<SaInputNode*> head;
  sac::Engine engine;
  detail::SaDelaunay dt{&registry, box};
  detail::SaDelaunayProgram program{&dt, &head};
  for (const auto& p : s) nodes.push_back(std::make_unique<SaInputNode>(p));
  for (std::size_t i = 0; i < nodes.size(); ++i)
    engine.set(nodes[i]->next, i + 1 < nodes.size() ? nodes[i + 1].get() : nullptr);
  engine.set(head, nodes.front().get());
  engine.run([&](sac::Engine& e) { detail::SaDelaunayProgram::main(e, &program); });
  detail::SaTri* start = nullptr;
  std::set<Point<2>> verts;
  for (detail::SaTri* t : registry.all())
    if (t->alive()) {
      start = t;
      for (const auto* v : t->v) verts.insert(v->p);
    }
  ASSERT_NE(start, nullptr);
  struct Query {
    int side;
    Point<2> x;
    std::pair<Point<2>, Point<2>> want;
  };
  std::vector<Query> queries;
  for (int side = 0; side < 4; ++side) {
    const unsigned along = side % 2 == 0 ? 0 : 1;
    const double across = side == 0 || side == 3 ? 0.0 : 8.0;
    std::map<double, Point<2>> line;
    for (const auto& p : verts)
      if (p[1 - along] == across) line[p[along]] = p;
    std::vector<double> xs{0.0, 8.0};
    for (auto it = line.begin(); it != line.end(); ++it) {
      xs.push_back(it->first);
      if (std::next(it) != line.end()) xs.push_back(0.5 * (it->first + std::next(it)->first));
    }
    for (const double x : xs) {
      auto it = line.upper_bound(x);
      if (it == line.end()) --it;
      if (it == line.begin()) ++it;
      Point<2> p;
      p[along] = x;
      p[1 - along] = across;
      queries.push_back({side, p, {std::prev(it)->second, it->second}});
      outs.emplace_back();
    }
  }
  engine.run([&](sac::Engine& e) {
    for (std::size_t i = 0; i < queries.size(); ++i)
      HpuProgram::side_edge_at(e, queries[i].side, queries[i].x, start, EdgeSink{&outs[i]});
  });
  for (std::size_t i = 0; i < queries.size(); ++i) {
    auto got = outs[i].get();
    if (xy_less(got.second, got.first)) std::swap(got.first, got.second);
    EXPECT_EQ(got, queries[i].want) << "side " << queries[i].side << " at " << to_string(queries[i].x);
  }
}

}  // namespace

namespace {

/// The continuation rule decides the same at every scale: its squares are computed in a
/// frame scaled by a power of two, so they neither overflow (a box side of 2^600, where the
/// unscaled squares were infinite and their difference NaN) nor underflow.
TEST(HpuGeometry, CircumradiusRuleIsScaleFree) {
  const Point<2> a{0.0, 0.0}, b{3.0, 0.25}, c{1.0, 2.5};
  for (const int s : {0, 600, -600, 1000, -1000}) {
    SCOPED_TRACE("scale 2^" + std::to_string(s));
    const auto at = [s](const Point<2>& p) { return Point<2>{std::ldexp(p[0], s), std::ldexp(p[1], s)}; };
    for (int j = -3; j <= 3; ++j)
      EXPECT_EQ(detail::circumradius_above(at(a), at(b), at(c), j + s), detail::circumradius_above(a, b, c, j))
          << "class " << j;
    // The circumradius here is about 1.6: above 2^0 and below 2^1.
    EXPECT_TRUE(detail::circumradius_above(at(a), at(b), at(c), s - 1));
    EXPECT_FALSE(detail::circumradius_above(at(a), at(b), at(c), s));
    // Flat triangles count as above.
    EXPECT_TRUE(detail::circumradius_above(at(a), at(b), at(Point<2>{6.0, 0.5}), s + 5));
  }
}

}  // namespace

namespace {

/// HpuInputs' checker fails on a list that lost a point, that holds one too many, or whose
/// order is broken, and passes on the list it keeps (the negative test of its checker).
TEST(HpuInputs, CheckerCatchesABrokenList) {
  const Box<2> box{{0, 0}, 1};
  // Points near the bottom side, so that the list holds side midpoints too.
  const std::vector<Point<2>> pts = {{0.3, 0.01}, {0.7, 0.4}, {0.55, 0.8}, {0.2, 0.6}};
  sac::Engine engine;
  detail::HpuInputs inputs(box);
  std::vector<Edit<2>> edits;
  for (const Point<2>& p : pts) edits.push_back({EditOp::Insert, p});
  inputs.commit(engine, inputs.plan(edits));
  ASSERT_NO_THROW(inputs.check_invariants(pts));
  EXPECT_GT(inputs.size(), pts.size()) << "the bottom side's midpoints are listed";
  // A point the list does not hold, and one it holds that is not an input.
  std::vector<Point<2>> more = pts;
  more.push_back({0.9, 0.9});
  EXPECT_THROW(inputs.check_invariants(more), InvariantError);
  EXPECT_THROW(inputs.check_invariants(std::vector<Point<2>>(pts.begin(), pts.end() - 1)), InvariantError);
  // The list cut after its first node, then two nodes swapped.
  detail::SaInputNode* first = inputs.head().get();
  detail::SaInputNode* second = first->next.get();
  detail::SaInputNode* third = second->next.get();
  engine.set(first->next, static_cast<detail::SaInputNode*>(nullptr));
  EXPECT_THROW(inputs.check_invariants(pts), InvariantError);
  engine.set(inputs.head(), second);
  engine.set(second->next, first);
  engine.set(first->next, third);
  EXPECT_THROW(inputs.check_invariants(pts), InvariantError);
  engine.set(inputs.head(), first);
  engine.set(first->next, second);
  engine.set(second->next, third);
  EXPECT_NO_THROW(inputs.check_invariants(pts));
}

/// SaTriRegistry's checker catches a feed whose live count disagrees with the triangles.
TEST(SaTriRegistry, CheckerCatchesAWrongLiveCount) {
  const Box<2> box{{0, 0}, 1};
  HpuHarness h(box, {{0.25, 0.5}, {0.75, 0.5}, {0.5, 0.25}}, kHpuDefaultMinAngle);
  ASSERT_NO_THROW(h.check());
  h.corrupt_live_count();
  EXPECT_THROW(h.check(), InvariantError);
}

}  // namespace
