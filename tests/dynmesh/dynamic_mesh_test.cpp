// Tests of dynmesh/dynamic_mesh.hpp: differential against the static twin (QuadtreeMesh,
// or HpuMesh at 20.7°, 25° and 30°) after every update, on random sequences with fixed,
// printed seeds; the checkers run on every mesh (Delaunay by exact predicates for hpu); the
// change feed replays exactly; bad input leaves everything as it was.
#include "dynamic_test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/mesh_check.hpp"
#include "dynmesh/quadtree_mesh.hpp"

namespace {

using namespace dynmesh;
using dynmesh_test::kSlowBuild;
using Kind = InputError::Kind;

const MeshOptions kQuadtree{.postprocess = Postprocess::Quadtree};
MeshOptions hpu(double angle) { return MeshOptions{.postprocess = Postprocess::Hpu, .min_angle = angle}; }

/// The mesh passes the checker with the bound (and Delaunay) and every point is a vertex.
testing::AssertionResult good_mesh(const Mesh& mesh, const Box<2>& box, const std::vector<Point<2>>& points,
                                   double bound = kQuadtreeMinAngle, bool delaunay = false) {
  MeshCheckOptions opts;
  opts.min_angle_deg = bound;
  opts.delaunay = delaunay;
  const MeshReport r = check_mesh(mesh, box, points, opts);
  if (!r.ok()) return testing::AssertionFailure() << r.summary();
  return testing::AssertionSuccess();
}

testing::AssertionResult agrees(const DynamicMesh& dyn, const std::vector<Point<2>>& points) {
  try {
    dyn.check_invariants();
  } catch (const std::exception& e) {
    return testing::AssertionFailure() << "check_invariants: " << e.what();
  }
  if (dyn.options().postprocess == Postprocess::Hpu) {
    const double bound = dyn.options().min_angle;
    const HpuMesh twin(dyn.box(), points, bound);
    const auto got = dyn.triangles();
    if (got != twin.triangles())
      return testing::AssertionFailure() << "triangles differ from the static twin HpuMesh: " << got.size()
                                         << " vs " << twin.triangles().size();
    if (dyn.num_triangles() != got.size()) return testing::AssertionFailure() << "num_triangles() is wrong";
    if (dyn.mesh() != twin.mesh()) return testing::AssertionFailure() << "mesh() differs from the static twin's";
    return good_mesh(twin.mesh(), dyn.box(), points, bound, true);
  }
  const QuadtreeMesh twin(dyn.box(), points);
  twin.check_invariants();
  const auto got = dyn.triangles();
  if (got != twin.triangles())
    return testing::AssertionFailure() << "triangles differ from the static twin: " << got.size() << " vs "
                                       << twin.triangles().size();
  if (dyn.refined_leaves() != twin.refined_leaves()) return testing::AssertionFailure() << "T' differs";
  return good_mesh(twin.mesh(), dyn.box(), points);
}

/// Runs `updates` random single and batched updates from a start set, comparing after each.
void run_differential_on(const Box<2>& box, const std::vector<Point<2>>& pool, std::size_t n, std::size_t updates,
                         std::uint64_t seed, const MeshOptions& options);

void run_differential(Distribution dist, std::size_t n, std::size_t updates, std::uint64_t seed,
                      double spread = 0x1p20, bool dyadic_box = false, const MeshOptions& options = kQuadtree) {
  SCOPED_TRACE("distribution " + std::string(distribution_name(dist)) + ", n " + std::to_string(n) + ", seed " +
               std::to_string(seed));
  auto pool = generate<2>(dist, 2 * n, seed, spread);
  Box<2> box = derive_box<2>(pool);
  if (dyadic_box) box = Box<2>{{-1.0, -1.0}, 4.0};
  run_differential_on(box, pool, n, updates, seed, options);
}

/// The first n of `pool` from scratch, then random updates drawing on the rest.
void run_differential_on(const Box<2>& box, const std::vector<Point<2>>& pool, std::size_t n, std::size_t updates,
                         std::uint64_t seed, const MeshOptions& options) {
  std::printf("[ DynamicMesh ] seed %llu, n %zu, %s\n", static_cast<unsigned long long>(seed), n,
              options.postprocess == Postprocess::Hpu ? ("hpu " + std::to_string(options.min_angle)).c_str()
                                                      : "quadtree");
  SCOPED_TRACE(options.postprocess == Postprocess::Hpu ? "hpu, angle " + std::to_string(options.min_angle)
                                                       : std::string("quadtree"));
  Rng rng(seed * 7 + 1);
  std::map<PointId, Point<2>> present;
  std::vector<Point<2>> absent(pool.begin() + static_cast<std::ptrdiff_t>(n), pool.end());
  std::vector<Point<2>> start(pool.begin(), pool.begin() + static_cast<std::ptrdiff_t>(n));
  DynamicMesh dyn(box, start, options);
  for (std::size_t i = 0; i < start.size(); ++i) present[i] = start[i];
  auto current = [&] {
    std::vector<Point<2>> v;
    for (const auto& [id, p] : present) v.push_back(p);
    return v;
  };
  ASSERT_TRUE(agrees(dyn, current()));
  std::vector<Triangle> mesh = dyn.triangles();
  for (std::size_t u = 0; u < updates; ++u) {
    SCOPED_TRACE("update " + std::to_string(u));
    dynmesh_test::random_update<2>(dyn, present, absent, rng);
    if (testing::Test::HasFatalFailure()) return;
    ASSERT_TRUE(apply_change(mesh, dyn.last_change())) << "the feed does not apply to the previous mesh";
    ASSERT_EQ(mesh, dyn.triangles()) << "the feed does not replay to the new mesh";
    ASSERT_TRUE(agrees(dyn, current()));
  }
}

std::size_t scaled(std::size_t n) { return kSlowBuild ? std::max<std::size_t>(n / 10, 6) : n; }

TEST(DynamicMeshDifferential, Uniform) { run_differential(Distribution::Uniform, 200, scaled(120), 11); }
TEST(DynamicMeshDifferential, Clusters) { run_differential(Distribution::Clusters, 200, scaled(120), 12); }
TEST(DynamicMeshDifferential, Spiral) { run_differential(Distribution::Spiral, 150, scaled(80), 13); }
TEST(DynamicMeshDifferential, Grid) { run_differential(Distribution::Grid, 150, scaled(80), 14); }
TEST(DynamicMeshDifferential, Collinear) { run_differential(Distribution::Collinear, 120, scaled(80), 15); }
TEST(DynamicMeshDifferential, CellBoundaries) { run_differential(Distribution::Boundary, 150, scaled(80), 16); }
TEST(DynamicMeshDifferential, ShrinkingDerivedBox) {
  for (const double spread : {0x1p10, 0x1p20, 0x1p30})
    run_differential(Distribution::Shrinking, 100, scaled(60), 17, spread);
}
TEST(DynamicMeshDifferential, ShrinkingDyadicBoxTo2e40) {
  for (const double spread : {0x1p30, 0x1p40}) run_differential(Distribution::Shrinking, 100, scaled(60), 18, spread, true);
}

TEST(DynamicMesh, TinySets) {
  const Box<2> box{{0.0, 0.0}, 1.0};
  for (const std::vector<Point<2>>& pts : std::vector<std::vector<Point<2>>>{
           {}, {{0.5, 0.5}}, {{0.3, 0.3}}, {{0.1, 0.7}}, {{0.25, 0.25}, {0.75, 0.75}}, {{0.0, 0.5}}, {{0.0, 0.0}}}) {
    SCOPED_TRACE(std::to_string(pts.size()) + " points");
    for (const MeshOptions& o : {kQuadtree, hpu(kHpuDefaultMinAngle), hpu(30)}) {
      DynamicMesh dyn(box, pts, o);
      EXPECT_TRUE(agrees(dyn, pts));
    }
  }
}

TEST(DynamicMesh, BoxesItsDoublesCannotMeshAreRefused) {
  // Found by fuzzing. o + L == o: both box corners on an axis are one number, so even the
  // empty set would mesh as degenerate triangles (each point was already refused).
  const std::vector<Box<2>> refused = {{{-1.8122712673485284e+145, -8.1249129568850047e+99}, 2.4374738870655016e+100}};
  for (const Box<2>& box : refused)
    for (const bool with_point : {false, true}) {
      SCOPED_TRACE("side " + format_exact(box.side) + (with_point ? ", one point" : ", no points"));
      std::vector<Point<2>> pts;
      if (with_point) pts.push_back({box.origin[0] + box.side / 3, box.origin[1] + box.side / 3});
      try {
        DynamicMesh dyn(box, pts, kQuadtree);
        ADD_FAILURE() << "DynamicMesh accepted the box";
      } catch (const InputError& e) {
        EXPECT_EQ(e.kind(), Kind::Resolution) << e.what();
      }
      EXPECT_THROW(QuadtreeMesh(box, pts), InputError);
    }
}

TEST(DynamicMesh, ExtremeBoxSidesAreMeshed) {
  // Found by fuzzing: the rules' angles overflowed or underflowed beyond sides of 2^±440 (an
  // angle of 14°, or no valid triangulation), and the centroid's sum overflowed near the
  // largest doubles. Each is now computed in a scaled frame, so every side validate_box()
  // accepts is meshed, within the bound, and dynamically as statically.
  const std::vector<Box<2>> boxes = {{{0.0, 0.0}, 0x1p441},   {{0.0, 0.0}, 0x1p-441}, {{0.0, 0.0}, 0x1p1000},
                                     {{0.0, 0.0}, 0x1p-960},  {{1e-280, -2e-280}, 0x1p-900},
                                     {{-3.3700738560978761e+305, -4.4934318081305018e+305}, 6.7401477121957522e+305}};
  for (const Box<2>& box : boxes) {
    SCOPED_TRACE("side " + format_exact(box.side));
    const double o0 = box.origin[0], o1 = box.origin[1], side = box.side;
    const std::vector<Point<2>> pts = {
        {o0 + side * 0.3, o1 + side * 0.45}, {o0 + side * 0.7, o1 + side * 0.6}, {o0 + side * 0.5, o1 + side * 0.5000001}};
    // The hpu mesh too: its edge classes and continuation rule are computed in a scaled
    // frame, so that squared lengths neither overflow nor underflow.
    for (const MeshOptions& o : {kQuadtree, hpu(kHpuDefaultMinAngle), hpu(30)}) {
      DynamicMesh dyn(box, pts, o);
      EXPECT_TRUE(agrees(dyn, pts));
      dyn.erase(pts[1]);
      EXPECT_TRUE(agrees(dyn, std::vector<Point<2>>{pts[0], pts[2]}));
      dyn.insert(pts[1]);
      EXPECT_TRUE(agrees(dyn, pts));
    }
  }
}

void bad_input_changes_nothing(const MeshOptions& options) {
  const auto pts = generate<2>(Distribution::Uniform, 50, 21);
  DynamicMesh dyn(derive_box<2>(pts), pts, options);
  const auto before = dyn.triangles();
  const auto events = dyn.live_events();
  auto rejected = [&](Kind kind, auto&& f) {
    try {
      f();
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      EXPECT_EQ(e.kind(), kind) << e.what();
    }
    EXPECT_EQ(dyn.triangles(), before);
    EXPECT_EQ(dyn.live_events(), events);
    EXPECT_NO_THROW(dyn.check_invariants());
  };
  rejected(Kind::NotFinite, [&] { dyn.insert({std::nan(""), 0.5}); });
  rejected(Kind::OutsideBox, [&] { dyn.insert({1e9, 0.5}); });
  rejected(Kind::Duplicate, [&] { dyn.insert(pts[3]); });
  rejected(Kind::Absent, [&] { dyn.erase(Point<2>{0.123456, 0.5}); });
  rejected(Kind::OutsideBox, [&] { dyn.erase(Point<2>{1e9, 0.5}); });
  rejected(Kind::Absent, [&] { dyn.erase(PointId{999}); });
  // A few grid units away: not a duplicate, but far below what the mesh can resolve.
  const Box<2> box = dyn.box();
  rejected(Kind::Resolution, [&] { dyn.insert({pts[4][0] + 3 * box.side * 0x1p-52, pts[4][1]}); });
  const std::vector<Edit<2>> batch = {{EditOp::Insert, {0.5, 0.5}}, {EditOp::Delete, pts[0]}, {EditOp::Delete, pts[0]}};
  rejected(Kind::Absent, [&] { dyn.apply(batch); });
}

TEST(DynamicMesh, BadInputChangesNothing) { bad_input_changes_nothing(kQuadtree); }
TEST(DynamicMeshHpu, BadInputChangesNothing) { bad_input_changes_nothing(hpu(kHpuDefaultMinAngle)); }

TEST(DynamicMeshHpu, AnglesOutOfRangeAreRefused) {
  const std::vector<Point<2>> pts = {{0.25, 0.5}, {0.5, 0.75}};
  for (const double angle : {0.0, 0.99, 30.01, 45.0, -5.0, std::nan(""), HUGE_VAL}) {
    SCOPED_TRACE("angle " + std::to_string(angle));
    try {
      DynamicMesh dyn(Box<2>{{0.0, 0.0}, 1.0}, pts, hpu(angle));
      ADD_FAILURE() << "DynamicMesh accepted the angle";
    } catch (const InputError& e) {
      EXPECT_EQ(e.kind(), Kind::Malformed) << e.what();
      EXPECT_NE(std::string(e.what()).find("--min-angle"), std::string::npos) << e.what();
    }
  }
}

TEST(DynamicMeshHpu, DefaultIsHpuAtTheSeedsBound) {
  const DynamicMesh dyn(Box<2>{{0.0, 0.0}, 1.0});
  EXPECT_EQ(dyn.options().postprocess, Postprocess::Hpu);
  EXPECT_EQ(dyn.options().min_angle, kHpuDefaultMinAngle);
  EXPECT_TRUE(agrees(dyn, {}));
}

TEST(DynamicMeshHpu, InputsAtTheBoxCornersAreItsOwnVertices) {
  // Found by fuzz_dynamic_mesh: where fl(o + L) rounds below o + L, the box admits inputs
  // on its far sides, corners included, which the input list must leave out like the near
  // corner (they are the box's vertices already). Here x1 = fl(o1 + 3) < o1 + 3.
  const Box<2> box{{1.2250000000000001, -0.44999999999999996}, 3.0};
  const double x1 = box.origin[0] + box.side;
  ASSERT_LT(x1 - box.origin[0], box.side);
  const std::vector<Point<2>> corners = {{x1, box.origin[1]}, box.origin};
  for (const double angle : {kHpuDefaultMinAngle, 30.0}) {
    std::vector<Point<2>> pts = {{2.7250000000000001, 1.05}, {4.0374999999999996, 0.48750000000000004}};
    DynamicMesh dyn(box, pts, hpu(angle));
    ASSERT_TRUE(agrees(dyn, pts));
    for (const Point<2>& c : corners) {
      SCOPED_TRACE("corner " + to_string(c));
      dyn.insert(c);
      pts.push_back(c);
      ASSERT_TRUE(agrees(dyn, pts));
    }
    for (const Point<2>& c : corners) {
      dyn.erase(c);
      pts.erase(std::find(pts.begin(), pts.end(), c));
      ASSERT_TRUE(agrees(dyn, pts));
    }
    DynamicMesh both(box, corners, hpu(angle));
    EXPECT_TRUE(agrees(both, corners));
  }
}

constexpr double kAngles[] = {kHpuDefaultMinAngle, 25.0, 30.0};

TEST(DynamicMeshHpuDifferential, Uniform) {
  for (const double a : kAngles) run_differential(Distribution::Uniform, 150, scaled(60), 31, 0x1p20, false, hpu(a));
}
TEST(DynamicMeshHpuDifferential, Clusters) {
  for (const double a : kAngles) run_differential(Distribution::Clusters, 150, scaled(60), 32, 0x1p20, false, hpu(a));
}
TEST(DynamicMeshHpuDifferential, CocircularGrid) {
  run_differential(Distribution::Grid, 120, scaled(60), 33, 0x1p20, false, hpu(kHpuDefaultMinAngle));
  run_differential(Distribution::Grid, 120, scaled(40), 34, 0x1p20, false, hpu(30));
}
TEST(DynamicMeshHpuDifferential, Collinear) {
  // At every bound: at 30° an update of exactly collinear points re-routes much of the
  // refinement (bench/RESULTS.md, "The costliest updates on every distribution").
  for (const double a : kAngles) run_differential(Distribution::Collinear, 100, scaled(60), 35, 0x1p20, false, hpu(a));
}
TEST(DynamicMeshHpuDifferential, CellBoundaries) {
  run_differential(Distribution::Boundary, 120, scaled(60), 36, 0x1p20, false, hpu(25));
}
TEST(DynamicMeshHpuDifferential, ShrinkingTo2e30) {
  for (const double spread : {0x1p10, 0x1p20, 0x1p30})
    run_differential(Distribution::Shrinking, 100, scaled(40), 37, spread, false, hpu(kHpuDefaultMinAngle));
}
TEST(DynamicMeshHpuDifferential, OnAndNearTheBoxSides) {
  // Inputs exactly on the box's lower sides (they change the sides' vertices, so the side
  // midpoints of every other input are recounted) and just inside every side.
  Rng rng(38);
  std::vector<Point<2>> pool;
  for (int i = 0; i < 160; ++i) {
    const double a = static_cast<double>(rng.below(1 << 20)) * 0x1p-20, b = static_cast<double>(1 + rng.below(999)) * 1e-3;
    switch (i % 5) {
      case 0: pool.push_back({a, 0.0}); break;
      case 1: pool.push_back({0.0, a}); break;
      case 2: pool.push_back({a, b * 1e-3}); break;
      case 3: pool.push_back({1.0 - b * 1e-4, a}); break;
      default: pool.push_back({a, static_cast<double>(rng.below(1 << 20)) * 0x1p-20}); break;
    }
  }
  std::sort(pool.begin(), pool.end());
  pool.erase(std::unique(pool.begin(), pool.end()), pool.end());
  std::vector<Point<2>> shuffled;
  while (!pool.empty()) {
    const std::size_t i = rng.below(pool.size());
    shuffled.push_back(pool[i]);
    pool.erase(pool.begin() + static_cast<std::ptrdiff_t>(i));
  }
  for (const double a : {kHpuDefaultMinAngle, 30.0})
    run_differential_on(Box<2>{{0.0, 0.0}, 1.0}, shuffled, shuffled.size() / 2, scaled(60), 38, hpu(a));
}

}  // namespace

namespace {

/// Mean trace distance of `updates` alternating deletions and insertions (fixed seeds) on
/// n uniform points, hpu at 20.7 degrees. Deterministic: it counts trace events.
double mean_hpu_distance(std::size_t n, std::size_t updates, std::uint64_t seed) {
  const auto pool = generate<2>(Distribution::Uniform, n + updates, seed);
  const std::vector<Point<2>> start(pool.begin(), pool.begin() + static_cast<std::ptrdiff_t>(n));
  DynamicMesh dyn(derive_box<2>(start), start, hpu(kHpuDefaultMinAngle));
  Rng rng(seed + 99);
  std::vector<PointId> ids;
  for (const auto& [id, p] : dyn.points()) ids.push_back(id);
  double sum = 0;
  std::size_t next = n, done = 0;
  for (std::size_t u = 0; u < updates; ++u) {
    if (u % 2 == 0) {
      const std::size_t k = rng.below(ids.size());
      dyn.erase(ids[k]);
      ids[k] = ids.back();
      ids.pop_back();
    } else {
      try {
        ids.push_back(dyn.insert(pool[next++]));
      } catch (const InputError&) {
        continue;
      }
    }
    sum += static_cast<double>(dyn.last_update().trace_distance);
    ++done;
  }
  return sum / static_cast<double>(done);
}

/// What re-ran, not only the result: an update's trace distance does not grow with n (the
/// target: at most 1.5 times between sizes, here 8x apart).
TEST(DynamicMeshHpu, TraceDistanceDoesNotGrowWithN) {
  const std::size_t small = kSlowBuild ? 150 : 500, large = kSlowBuild ? 1200 : 4000;
  const std::size_t updates = kSlowBuild ? 20 : 80;
  const double a = mean_hpu_distance(small, updates, 51), b = mean_hpu_distance(large, updates, 51);
  std::printf("[ DynamicMeshHpu ] mean trace distance per update: %.0f at n = %zu, %.0f at n = %zu\n", a, small, b,
              large);
  EXPECT_LE(b, 1.5 * a);
  EXPECT_GT(b, 0.0);
}

}  // namespace
