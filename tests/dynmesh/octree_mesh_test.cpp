// Tests of dynmesh/octree_mesh.hpp and dynmesh/dynamic_octree_mesh.hpp: the static twin's
// mesh passes the tetrahedral mesh checker (positive, matched faces, the box's volume, every
// input a vertex, dihedral angles within the proved bound) on every distribution; the
// self-adjusting mesh equals the twin bit for bit after every update and batch, with fixed,
// printed seeds; the change feed replays exactly; bad input changes nothing.
#include "dynamic_test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_octree_mesh.hpp"
#include "dynmesh/octree_mesh.hpp"
#include "dynmesh/tet_mesh_check.hpp"

namespace {

using namespace dynmesh;
using dynmesh_test::kSlowBuild;
using Kind = InputError::Kind;

std::size_t scaled(std::size_t n) { return kSlowBuild ? std::max<std::size_t>(n / 8, 4) : n; }

testing::AssertionResult good_mesh(const TetMesh& mesh, const Box<3>& box, const std::vector<Point<3>>& points) {
  TetMeshCheckOptions opts;
  opts.min_dihedral_deg = kOctreeMinDihedral;
  opts.max_dihedral_deg = kOctreeMaxDihedral;
  const TetMeshReport r = check_tet_mesh(mesh, box, points, opts);
  if (!r.ok()) return testing::AssertionFailure() << r.summary();
  return testing::AssertionSuccess();
}

/// The dynamic mesh against the static twin, with the checkers; `full` also runs the mesh
/// checker (O(t log t)).
testing::AssertionResult agrees(const DynamicOctreeMesh& dyn, const std::vector<Point<3>>& points, bool full) {
  const OctreeMesh twin(dyn.box(), points);
  try {
    twin.check_invariants();
    if (full) dyn.check_invariants();
  } catch (const std::exception& e) {
    return testing::AssertionFailure() << "check_invariants: " << e.what();
  }
  const auto got = dyn.tetrahedra();
  if (got != twin.tetrahedra())
    return testing::AssertionFailure() << "tetrahedra differ from the static twin: " << got.size() << " vs "
                                       << twin.tetrahedra().size();
  if (dyn.num_tetrahedra() != got.size()) return testing::AssertionFailure() << "num_tetrahedra() is wrong";
  if (dyn.refined_leaves() != twin.refined_leaves()) return testing::AssertionFailure() << "T' differs";
  return testing::AssertionSuccess();  // with `full`, dyn.check_invariants() ran the mesh checker
}

/// The first n of `pool` from scratch, then random single and batched updates drawing on the
/// rest, compared with the twin after each; the mesh checker every `full_every` updates.
void run_differential_on(const Box<3>& box, const std::vector<Point<3>>& pool, std::size_t n, std::size_t updates,
                         std::uint64_t seed, std::size_t full_every = 8) {
  std::printf("[ DynamicOctreeMesh ] seed %llu, n %zu\n", static_cast<unsigned long long>(seed), n);
  Rng rng(seed * 7 + 1);
  std::map<PointId, Point<3>> present;
  std::vector<Point<3>> absent(pool.begin() + static_cast<std::ptrdiff_t>(n), pool.end());
  const std::vector<Point<3>> start(pool.begin(), pool.begin() + static_cast<std::ptrdiff_t>(n));
  DynamicOctreeMesh dyn(box, start);
  for (std::size_t i = 0; i < start.size(); ++i) present[i] = start[i];
  auto current = [&] {
    std::vector<Point<3>> v;
    for (const auto& [id, p] : present) v.push_back(p);
    return v;
  };
  ASSERT_TRUE(agrees(dyn, current(), true));
  std::vector<Tetrahedron> mesh = dyn.tetrahedra();
  for (std::size_t u = 0; u < updates; ++u) {
    SCOPED_TRACE("update " + std::to_string(u));
    dynmesh_test::random_update<3>(dyn, present, absent, rng);
    if (testing::Test::HasFatalFailure()) return;
    ASSERT_TRUE(apply_change(mesh, dyn.last_change())) << "the feed does not apply to the previous mesh";
    ASSERT_EQ(mesh, dyn.tetrahedra()) << "the feed does not replay to the new mesh";
    ASSERT_TRUE(agrees(dyn, current(), (u + 1) % full_every == 0));
  }
}

void run_differential(Distribution dist, std::size_t n, std::size_t updates, std::uint64_t seed,
                      double spread = 0x1p20, std::size_t full_every = 8) {
  SCOPED_TRACE("distribution " + std::string(distribution_name(dist)) + ", n " + std::to_string(n) + ", seed " +
               std::to_string(seed));
  const auto pool = generate<3>(dist, 2 * n, seed, spread);
  run_differential_on(derive_box<3>(pool), pool, n, updates, seed, full_every);
}

TEST(DynamicOctreeMeshDifferential, Uniform) { run_differential(Distribution::Uniform, 30, scaled(40), 101); }
TEST(DynamicOctreeMeshDifferential, Clusters) { run_differential(Distribution::Clusters, 20, scaled(32), 102); }
TEST(DynamicOctreeMeshDifferential, Spiral) { run_differential(Distribution::Spiral, 30, scaled(40), 103); }
TEST(DynamicOctreeMeshDifferential, Curves) { run_differential(Distribution::Curves, 24, scaled(32), 104); }
TEST(DynamicOctreeMeshDifferential, Lattice) { run_differential(Distribution::Grid, 30, scaled(40), 105); }
TEST(DynamicOctreeMeshDifferential, CellBoundaries) { run_differential(Distribution::Boundary, 30, scaled(40), 106); }
TEST(DynamicOctreeMeshDifferential, ShrinkingTo2e30) {
  for (const double spread : {0x1p10, 0x1p20, 0x1p30}) run_differential(Distribution::Shrinking, 16, scaled(20), 107, spread);
}
TEST(DynamicOctreeMeshDifferential, LargerUniformTwinOnly) {
  // More points, the twin after every update and the mesh checker every 20th.
  run_differential(Distribution::Uniform, scaled(120), scaled(24), 108, 0x1p20, 12);
}

TEST(DynamicOctreeMesh, PointsOnTheBoxFacesEdgesAndCorners) {
  // Points on the box's faces, edges and at its lowest corner keep to them: the block of a
  // point on a face is the half of the block inside the box.
  const Box<3> box{{0.0, 0.0, 0.0}, 1.0};
  std::vector<Point<3>> pts = {{0.0, 0.3, 0.6},  {0.4, 0.0, 0.7},   {0.55, 0.45, 0.0}, {0.0, 0.0, 0.5},
                               {0.3, 0.0, 0.0},  {0.0, 0.8, 0.0},   {0.0, 0.0, 0.0},   {0.5, 0.5, 0.5},
                               {0.71, 0.2, 0.0}, {0.0, 0.65, 0.33}, {0.9, 0.9, 0.9}};
  DynamicOctreeMesh dyn(box, pts);
  EXPECT_TRUE(agrees(dyn, pts, true));
  for (std::size_t i = 0; i < pts.size(); ++i) {
    SCOPED_TRACE("erase and reinsert point " + std::to_string(i));
    dyn.erase(pts[i]);
    std::vector<Point<3>> rest = pts;
    rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(i));
    EXPECT_TRUE(agrees(dyn, rest, true));
    dyn.insert(pts[i]);
    EXPECT_TRUE(agrees(dyn, pts, i % 4 == 0));
  }
}

TEST(DynamicOctreeMesh, TinySets) {
  const Box<3> box{{0.0, 0.0, 0.0}, 1.0};
  for (const std::vector<Point<3>>& pts : std::vector<std::vector<Point<3>>>{
           {}, {{0.5, 0.5, 0.5}}, {{0.3, 0.3, 0.3}}, {{0.1, 0.7, 0.2}}, {{0.25, 0.25, 0.25}, {0.75, 0.75, 0.75}}}) {
    SCOPED_TRACE(std::to_string(pts.size()) + " points");
    DynamicOctreeMesh dyn(box, pts);
    EXPECT_TRUE(agrees(dyn, pts, true));
  }
  // The empty box is Kuhn's six tetrahedra.
  EXPECT_EQ(DynamicOctreeMesh(box).num_tetrahedra(), 6u);
}

TEST(DynamicOctreeMesh, NonDyadicAndExtremeBoxes) {
  const std::vector<Box<3>> boxes = {{{0.1, -0.3, 7.0}, 3.0}, {{0.0, 0.0, 0.0}, 0x1p300}, {{0.0, 0.0, 0.0}, 0x1p-300},
                                     {{-1e6, 2e6, 3.5e6}, 0.75e6}};
  for (const Box<3>& box : boxes) {
    SCOPED_TRACE("side " + std::to_string(box.side));
    const double s = box.side;
    const std::vector<Point<3>> pts = {{box.origin[0] + s * 0.3, box.origin[1] + s * 0.45, box.origin[2] + s * 0.5},
                                       {box.origin[0] + s * 0.7, box.origin[1] + s * 0.6, box.origin[2] + s * 0.41},
                                       {box.origin[0] + s * 0.5, box.origin[1] + s * 0.5000001, box.origin[2] + s * 0.6}};
    DynamicOctreeMesh dyn(box, pts);
    EXPECT_TRUE(agrees(dyn, pts, true));
    dyn.erase(pts[1]);
    EXPECT_TRUE(agrees(dyn, {pts[0], pts[2]}, true));
    dyn.insert(pts[1]);
    EXPECT_TRUE(agrees(dyn, pts, true));
  }
}

TEST(DynamicOctreeMesh, BadInputChangesNothing) {
  const auto pts = generate<3>(Distribution::Uniform, 30, 21);
  DynamicOctreeMesh dyn(derive_box<3>(pts), pts);
  const auto before = dyn.tetrahedra();
  const auto events = dyn.live_events();
  auto rejected = [&](Kind kind, auto&& f) {
    try {
      f();
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      EXPECT_EQ(e.kind(), kind) << e.what();
    }
    EXPECT_EQ(dyn.tetrahedra(), before);
    EXPECT_EQ(dyn.live_events(), events);
    EXPECT_NO_THROW(dyn.check_invariants());
  };
  rejected(Kind::NotFinite, [&] { dyn.insert({std::nan(""), 0.5, 0.5}); });
  rejected(Kind::OutsideBox, [&] { dyn.insert({1e9, 0.5, 0.5}); });
  rejected(Kind::Duplicate, [&] { dyn.insert(pts[3]); });
  rejected(Kind::Absent, [&] { dyn.erase(Point<3>{0.123456, 0.5, 0.5}); });
  rejected(Kind::Absent, [&] { dyn.erase(PointId{999}); });
  const Box<3> box = dyn.box();
  // A few grid units away: not a duplicate, but beyond what the mesh's doubles resolve.
  rejected(Kind::Resolution, [&] { dyn.insert({pts[4][0] + 3 * box.side * 0x1p-52, pts[4][1], pts[4][2]}); });
  // Just inside a box face it is not on.
  rejected(Kind::Resolution, [&] { dyn.insert({box.origin[0] + box.side * 0x1p-49, 0.5 * (pts[0][1] + pts[1][1]), pts[0][2]}); });
  const std::vector<Edit<3>> batch = {{EditOp::Insert, {0.5, 0.5, 0.5}}, {EditOp::Delete, pts[0]}, {EditOp::Delete, pts[0]}};
  rejected(Kind::Absent, [&] { dyn.apply(batch); });
}

TEST(OctreeMesh, DyadicBoxesStopWhereTheProofsMarginEnds) {
  // A pair 6 grid units apart in a dyadic box: with blocks at level 51 the rounded x − o put
  // a point s/8 outside its region and gave a dihedral angle of 12.995°. The mesh now refuses
  // spreads beyond level 42 in a dyadic box, where the proof's margin covers the rounding.
  const Box<3> box{{-0.5, -0.5, -0.5}, 1.0};
  const double a = 0x1.333333333332bp-2;
  const std::vector<Point<3>> pts = {{a, a, a}, {a + 6 * 0x1p-52, a, a}};
  try {
    DynamicOctreeMesh dyn(box, pts);
    ADD_FAILURE() << "the pair was meshed";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), Kind::Resolution) << e.what();
  }
  EXPECT_THROW(OctreeMesh(box, pts), InputError);
  // At the deepest level allowed the bound holds.
  const std::vector<Point<3>> near = {{a, a, a}, {a + 0x1p-41, a, a}};
  const OctreeMesh m(box, near);
  EXPECT_TRUE(good_mesh(m.mesh(), box, near));
}

TEST(OctreeMesh, RefinedTreeCheckerCatchesAMissingBlockCell) {
  const Box<3> box{{0.0, 0.0, 0.0}, 1.0};
  const std::vector<Point<3>> pts = {{0.3, 0.3, 0.3}, {0.7, 0.6, 0.65}};
  const OctreeMesh m(box, pts);
  EXPECT_NO_THROW(m.check_invariants());
  std::vector<Leaf<3>> leaves(m.refined_leaves().begin(), m.refined_leaves().end());
  const std::vector<Position<3>> qs = {locate(box, pts[0]), locate(box, pts[1])};
  EXPECT_NO_THROW(require_refined_tree(leaves, qs));
  // Dropping each same-size neighbour of a point leaf in turn: exactly the seven other cells
  // of its block are missed.
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    if (leaves[i].npoints != 1) continue;
    int missed = 0;
    for_each_neighbour(leaves[i].cell, [&](const CellId<3>& nb) {
      auto broken = leaves;
      const auto it = std::find_if(broken.begin(), broken.end(), [&](const Leaf<3>& l) { return l.cell == nb; });
      if (it == broken.end()) return;
      broken.erase(it);
      try {
        require_refined_tree(broken, qs);
      } catch (const InvariantError&) {
        ++missed;
      }
    });
    EXPECT_EQ(missed, 7);
    auto twice = leaves;
    twice.push_back(leaves[i]);
    EXPECT_THROW(require_refined_tree(twice, qs), InvariantError);
    auto unheld = leaves;
    unheld[i].npoints = 0;
    EXPECT_THROW(require_refined_tree(unheld, qs), InvariantError);
  }
}

TEST(OctreeMesh, EveryDistributionIsAQualityTiling) {
  for (const Distribution dist : all_distributions()) {
    SCOPED_TRACE(std::string(distribution_name(dist)));
    const auto pts = generate<3>(dist, scaled(200), 5);
    const Box<3> box = derive_box<3>(pts);
    const OctreeMesh m(box, pts);
    EXPECT_NO_THROW(m.check_invariants());
    EXPECT_TRUE(good_mesh(m.mesh(), box, pts));
  }
}

}  // namespace
