// tet_mesh_check_test.cpp — tet_mesh_check.hpp: valid tetrahedral meshes pass, every kind of
// corruption is reported as its own defect, and the dihedral angles and radius-edge ratios
// of known tetrahedra come out right.
#include "dynmesh/tet_mesh_check.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "dynmesh/errors.hpp"
#include "dynmesh/predicates.hpp"
#include "dynmesh/tet_mesh.hpp"
#include "kuhn_meshes.hpp"

namespace {

using namespace dynmesh;
using dynmesh_test::cube;
using dynmesh_test::kuhn;
using dynmesh_test::kuhn_cube;
using dynmesh_test::kuhn_grid;
using Tet = std::array<std::uint32_t, 4>;

// a, b, c, d in the order that makes them positively oriented (c and d swapped if needed),
// canonical.
Tetrahedron positive(const Point<3>& a, const Point<3>& b, const Point<3>& c, const Point<3>& d) {
  return orient3d(a, b, c, d) < 0 ? canonical_tetrahedron(a, b, d, c) : canonical_tetrahedron(a, b, c, d);
}

// The unit cube as twelve tetrahedra coned from its centre over its faces, each face split by
// the diagonal Kuhn's tetrahedra do not use: it shares no face with kuhn_cube().
std::vector<Tetrahedron> cone_cube() {
  const Point<3> centre{0.5, 0.5, 0.5};
  std::vector<Tetrahedron> out;
  for (int axis = 0; axis < 3; ++axis)
    for (const double side : {0.0, 1.0}) {
      const int b = (axis + 1) % 3, c = (axis + 2) % 3;
      const auto corner = [&](double s, double t) {
        Point<3> p{};
        p[axis] = side;
        p[b] = s;
        p[c] = t;
        return p;
      };
      out.push_back(positive(corner(0, 0), corner(1, 0), corner(0, 1), centre));
      out.push_back(positive(corner(1, 1), corner(1, 0), corner(0, 1), centre));
    }
  return out;
}

// The mesh with one more vertex p (not used by any tetrahedron), numbered in canonical order.
TetMesh with_vertex(TetMesh m, const Point<3>& p) {
  const auto at = std::lower_bound(m.vertices.begin(), m.vertices.end(), p, xyz_less);
  const auto position = static_cast<std::uint32_t>(at - m.vertices.begin());
  m.vertices.insert(at, p);
  for (Tet& t : m.tetrahedra)
    for (std::uint32_t& i : t)
      if (i >= position) ++i;
  return m;
}

std::size_t count(const TetMeshReport& r, TetMeshDefect d) { return r.counts[static_cast<std::size_t>(d)]; }

// The defects present, for messages and for "exactly these" assertions.
std::vector<TetMeshDefect> kinds(const TetMeshReport& r) {
  std::vector<TetMeshDefect> out;
  for (std::size_t k = 0; k < kTetMeshDefectKinds; ++k)
    if (r.counts[k] != 0) out.push_back(static_cast<TetMeshDefect>(k));
  return out;
}

bool mentions(const TetMeshReport& r, TetMeshDefect d) {
  const std::string prefix = std::string(defect_name(d)) + ": ";
  return std::any_of(r.problems.begin(), r.problems.end(),
                     [&](const std::string& p) { return p.rfind(prefix, 0) == 0; });
}

std::array<double, 6> sorted_angles(const Tetrahedron& t) {
  std::array<double, 6> a = dihedral_angles_deg(t);
  std::sort(a.begin(), a.end());
  return a;
}

void expect_angles_near(const std::array<double, 6>& got, const std::array<double, 6>& want) {
  for (std::size_t k = 0; k < 6; ++k) EXPECT_NEAR(got[k], want[k], 1e-9) << "angle " << k;
}

constexpr std::array<double, 6> kKuhnAngles{45, 45, 60, 90, 90, 90};

// ---- dihedral angles and radius-edge ratios ------------------------------------------------

TEST(TetMeshCheck, DihedralAnglesOfTheRegularTetrahedron) {
  const double regular = std::acos(1.0 / 3) * 180 / std::numbers::pi;  // 70.528779...
  EXPECT_NEAR(regular, 70.528779, 1e-6);
  const Tetrahedron t = positive({1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1});
  expect_angles_near(dihedral_angles_deg(t), {regular, regular, regular, regular, regular, regular});
  EXPECT_NEAR(radius_edge_ratio(t), std::sqrt(6.0) / 4, 1e-14);
}

TEST(TetMeshCheck, DihedralAnglesOfAKuhnTetrahedron) {
  const Tetrahedron t = canonical_tetrahedron({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1});
  expect_angles_near(sorted_angles(t), kKuhnAngles);
  // Edge by edge (v0v1, v0v2, v0v3, v1v2, v1v3, v2v3): the orthoscheme's three right angles
  // are at the edges off the path v0 v1 v2 v3, its 45s at the path's first and last steps.
  expect_angles_near(dihedral_angles_deg(t), {45, 90, 60, 90, 90, 45});
  EXPECT_NEAR(radius_edge_ratio(t), std::sqrt(3.0) / 2, 1e-14);  // half the diagonal over 1
  for (const Tetrahedron& k : kuhn({0, 0, 0}, {1, 1, 1})) expect_angles_near(sorted_angles(k), kKuhnAngles);
}

TEST(TetMeshCheck, DihedralAnglesAtExtremeScales) {
  // A frame scaled by a power of two: products of 2^1000 or 2^-1000 lengths would overflow
  // or underflow, yet the angles and ratios are the unit tetrahedron's.
  const Tetrahedron unit = canonical_tetrahedron({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1});
  for (const int e : {1000, -1000, 500, -1060}) {
    SCOPED_TRACE("scale 2^" + std::to_string(e));
    Tetrahedron t = unit;
    for (Point<3>& v : t.v)
      for (double& x : v) x = std::ldexp(x, e) + std::ldexp(3.0, e + 2);  // and off the origin
    EXPECT_EQ(dihedral_angles_deg(t), dihedral_angles_deg(unit));
    EXPECT_EQ(radius_edge_ratio(t), radius_edge_ratio(unit));
  }
}

TEST(TetMeshCheck, DegenerateTetrahedra) {
  const Tetrahedron flat = canonical_tetrahedron({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0});
  EXPECT_EQ(radius_edge_ratio(flat), std::numeric_limits<double>::infinity());
  for (const double a : dihedral_angles_deg(flat)) EXPECT_TRUE(a == 0 || a == 180) << a;
  // A sliver: four corners near the equator of a sphere, the dihedral angles near 0 and 180.
  const double h = 1e-6;
  const Tetrahedron sliver = positive({1, 0, h}, {-1, 0, h}, {0, 1, -h}, {0, -1, -h});
  const std::array<double, 6> a = sorted_angles(sliver);
  EXPECT_LT(a[0], 1e-3);
  EXPECT_GT(a[5], 180 - 1e-3);
  EXPECT_NEAR(radius_edge_ratio(sliver), 1 / std::sqrt(2.0), 1e-9);  // a sliver has a fine ratio
}

// ---- valid meshes pass -----------------------------------------------------------------------

TEST(TetMeshCheck, SmallValidMeshesPass) {
  const std::vector<Point<3>> corners = {{0, 0, 0}, {1, 1, 1}};
  TetMeshReport r = check_tet_mesh(kuhn_cube(), cube(0, 0, 0, 1), corners);
  EXPECT_TRUE(r.ok()) << r.summary();
  EXPECT_NEAR(r.min_dihedral_deg, 45, 1e-12);
  EXPECT_NEAR(r.max_dihedral_deg, 90, 1e-12);
  EXPECT_EQ(r.summary().rfind("tetrahedral mesh ok", 0), 0u) << r.summary();

  const std::vector<Point<3>> centre = {{0.5, 0.5, 0.5}};
  r = check_tet_mesh(make_tet_mesh(cone_cube()), cube(0, 0, 0, 1), centre);
  EXPECT_TRUE(r.ok()) << r.summary();

  EXPECT_TRUE(check_tet_mesh(kuhn_grid(3), cube(0, 0, 0, 3), {}, {44.9, 90.1}).ok());
  EXPECT_NO_THROW(require_valid_tet_mesh(kuhn_grid(3), cube(0, 0, 0, 3), {}));
}

TEST(TetMeshCheck, OffsetBoxWithInexactUpperSide) {
  // fl(0.1 + 0.7) = 0.7999999999999999: the box's upper faces are where the sum rounds.
  const Box<3> box = cube(0.1, 0.1, 0.1, 0.7);
  const double hi = 0.1 + 0.7;
  EXPECT_TRUE(check_tet_mesh(make_tet_mesh(kuhn({0.1, 0.1, 0.1}, {hi, hi, hi})), box, {}).ok());
  const TetMeshReport r = check_tet_mesh(make_tet_mesh(kuhn({0.1, 0.1, 0.1}, {0.8, 0.8, 0.8})), box, {});
  EXPECT_TRUE(r.has(TetMeshDefect::OutsideBox)) << r.summary();
  EXPECT_EQ(count(r, TetMeshDefect::MissingCorner), 7u) << r.summary();
}

TEST(TetMeshCheck, BoxesOfExtremeSizePass) {
  // The box's volume overflows at L = 2^600 and a tetrahedron's underflows at L = 2^-600,
  // yet the mesh is the plain Kuhn cube.
  for (const double side : {0x1p600, 0x1p-600, 3.1223605929922333e+307}) {
    SCOPED_TRACE(side);
    const Box<3> box = cube(-side / 2, 0, side, side);
    const Point<3> lo{-side / 2, 0, side}, hi{-side / 2 + side, side, side + side};
    const TetMeshReport r = check_tet_mesh(make_tet_mesh(kuhn(lo, hi)), box, {}, {44.9, 90.1});
    EXPECT_TRUE(r.ok()) << r.summary();
    EXPECT_NEAR(r.min_dihedral_deg, 45, 1e-12);
    EXPECT_NEAR(r.max_dihedral_deg, 90, 1e-12);
  }
}

TEST(TetMeshCheck, JitteredGridPasses) {
  const std::vector<Point<3>> inputs = {{0, 0, 0}, {6, 6, 6}, {0, 6, 3}};
  const TetMeshReport r = check_tet_mesh(kuhn_grid(6, 0.1, 7), cube(0, 0, 0, 6), inputs);
  EXPECT_TRUE(r.ok()) << r.summary();
  EXPECT_LT(r.min_dihedral_deg, 45);  // the jitter moved them
  EXPECT_GT(r.max_dihedral_deg, 90);
}

// ---- each corruption is reported -------------------------------------------------------------

TEST(TetMeshCheck, NegativelyOrientedTetrahedron) {
  TetMesh m = kuhn_grid(2);
  std::swap(m.tetrahedra[5][2], m.tetrahedra[5][3]);  // still in a canonical rotation...
  std::sort(m.tetrahedra.begin(), m.tetrahedra.end());  // ...and now in order again
  const TetMeshReport r = check_tet_mesh(m, cube(0, 0, 0, 2), {});
  EXPECT_EQ(count(r, TetMeshDefect::Orientation), 1u) << r.summary();
  EXPECT_TRUE(mentions(r, TetMeshDefect::Orientation));
  EXPECT_NE(r.summary().find("negatively oriented"), std::string::npos) << r.summary();
  EXPECT_FALSE(r.has(TetMeshDefect::Canonical)) << r.summary();
  EXPECT_TRUE(r.has(TetMeshDefect::Volume));  // counted negative: 2 volumes short

  // Four corners on one plane: degenerate, neither orientation.
  const std::vector<Tetrahedron> flat = {canonical_tetrahedron({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0})};
  const TetMeshReport f = check_tet_mesh(make_tet_mesh(flat), cube(0, 0, 0, 1), {});
  EXPECT_EQ(count(f, TetMeshDefect::Orientation), 1u) << f.summary();
  EXPECT_NE(f.summary().find("degenerate (coplanar corners)"), std::string::npos) << f.summary();
}

TEST(TetMeshCheck, DroppedTetrahedronIsAHole) {
  const TetMesh whole = kuhn_grid(2);
  for (std::size_t drop : {0u, 20u, 47u}) {  // a corner cube's, one at the centre vertex, the last
    TetMesh m = whole;
    m.tetrahedra.erase(m.tetrahedra.begin() + static_cast<std::ptrdiff_t>(drop));
    const TetMeshReport r = check_tet_mesh(m, cube(0, 0, 0, 2), {});
    EXPECT_TRUE(r.has(TetMeshDefect::OpenFace)) << drop << ": " << r.summary();
    EXPECT_TRUE(r.has(TetMeshDefect::Volume)) << r.summary();
    EXPECT_FALSE(r.has(TetMeshDefect::Orientation));
    EXPECT_FALSE(r.has(TetMeshDefect::FaceTwice));
    EXPECT_FALSE(r.has(TetMeshDefect::Canonical));
  }
}

TEST(TetMeshCheck, DuplicatedTetrahedron) {
  TetMesh m = kuhn_grid(2);
  m.tetrahedra.insert(m.tetrahedra.begin() + 9, m.tetrahedra[9]);
  const TetMeshReport r = check_tet_mesh(m, cube(0, 0, 0, 2), {});
  EXPECT_EQ(count(r, TetMeshDefect::FaceTwice), 4u) << r.summary();
  EXPECT_TRUE(mentions(r, TetMeshDefect::FaceTwice));
  EXPECT_TRUE(r.has(TetMeshDefect::Volume));
  EXPECT_FALSE(r.has(TetMeshDefect::Canonical));  // equal neighbours are still in order
  EXPECT_FALSE(r.has(TetMeshDefect::Orientation));
  EXPECT_FALSE(r.has(TetMeshDefect::OpenFace));
}

TEST(TetMeshCheck, CubeCoveredTwice) {
  // Two tilings of the cube that share no face: every face is matched or on the box, and only
  // the volume sees that each point is covered twice.
  std::vector<Tetrahedron> ts = kuhn({0, 0, 0}, {1, 1, 1});
  for (const Tetrahedron& t : cone_cube()) ts.push_back(t);
  const TetMeshReport r = check_tet_mesh(make_tet_mesh(ts), cube(0, 0, 0, 1), {});
  EXPECT_EQ(kinds(r), std::vector<TetMeshDefect>{TetMeshDefect::Volume}) << r.summary();
  EXPECT_TRUE(mentions(r, TetMeshDefect::Volume));
}

TEST(TetMeshCheck, VertexOffTheBox) {
  TetMesh m = kuhn_grid(2);
  const auto at = std::find(m.vertices.begin(), m.vertices.end(), Point<3>{1, 1, 0});
  ASSERT_NE(at, m.vertices.end());
  *at = {1, 1, -0.5};  // still between (1, 0, 2) and (1, 1, 1) in (x, y, z) order
  const TetMeshReport r = check_tet_mesh(m, cube(0, 0, 0, 2), {});
  EXPECT_EQ(count(r, TetMeshDefect::OutsideBox), 1u) << r.summary();
  EXPECT_TRUE(mentions(r, TetMeshDefect::OutsideBox));
  EXPECT_TRUE(r.has(TetMeshDefect::OpenFace));  // its faces on z = 0 left the plane
  EXPECT_FALSE(r.has(TetMeshDefect::Canonical));
}

TEST(TetMeshCheck, HangingVertexInsideTheBox) {
  // The cone cube with one tetrahedron split at the midpoint m of its edge from the centre to
  // the corner (0, 0, 0): the tetrahedra around that edge that are not split have m inside
  // an edge of theirs, and their faces there find no match.
  const Point<3> centre{0.5, 0.5, 0.5}, origin{0, 0, 0}, m{0.25, 0.25, 0.25};
  std::vector<Tetrahedron> ts = cone_cube();
  const auto around = std::find_if(ts.begin(), ts.end(), [&](const Tetrahedron& t) {
    return std::count(t.v.begin(), t.v.end(), origin) == 1 && std::count(t.v.begin(), t.v.end(), centre) == 1;
  });
  ASSERT_NE(around, ts.end());
  std::vector<Point<3>> rest;
  for (const Point<3>& v : around->v)
    if (v != origin && v != centre) rest.push_back(v);
  ASSERT_EQ(rest.size(), 2u);
  *around = positive(origin, m, rest[0], rest[1]);
  ts.push_back(positive(m, centre, rest[0], rest[1]));
  const TetMeshReport r = check_tet_mesh(make_tet_mesh(ts), cube(0, 0, 0, 1), {});
  EXPECT_TRUE(r.has(TetMeshDefect::OpenFace)) << r.summary();
  EXPECT_TRUE(mentions(r, TetMeshDefect::OpenFace));
  EXPECT_FALSE(r.has(TetMeshDefect::Volume)) << r.summary();  // the volume alone does not see it
  EXPECT_FALSE(r.has(TetMeshDefect::Orientation));
  EXPECT_FALSE(r.has(TetMeshDefect::FaceTwice));
}

TEST(TetMeshCheck, MissingInputPoint) {
  const std::vector<Point<3>> inputs = {{1, 1, 1}, {0.5, 0.5, 0.5}, {0, 0, 0}};
  const TetMeshReport r = check_tet_mesh(kuhn_cube(), cube(0, 0, 0, 1), inputs);
  EXPECT_EQ(kinds(r), std::vector<TetMeshDefect>{TetMeshDefect::MissingInput}) << r.summary();
  EXPECT_EQ(count(r, TetMeshDefect::MissingInput), 1u);
  EXPECT_NE(r.problems.at(0).find("input point 1"), std::string::npos) << r.problems[0];
}

TEST(TetMeshCheck, MissingCorner) {
  const TetMeshReport r = check_tet_mesh(kuhn_cube(), cube(0, 0, 0, 2), {});
  EXPECT_EQ(count(r, TetMeshDefect::MissingCorner), 7u) << r.summary();
  EXPECT_TRUE(mentions(r, TetMeshDefect::MissingCorner));
  EXPECT_TRUE(r.has(TetMeshDefect::OpenFace));  // the faces on x = 1, y = 1, z = 1
  EXPECT_TRUE(r.has(TetMeshDefect::Volume));
}

TEST(TetMeshCheck, IsolatedVertex) {
  const TetMesh m = with_vertex(kuhn_cube(), {0.5, 0.25, 0.75});
  const std::vector<Point<3>> inputs = {{0.5, 0.25, 0.75}};
  const TetMeshReport r = check_tet_mesh(m, cube(0, 0, 0, 1), inputs);
  EXPECT_EQ(kinds(r), std::vector<TetMeshDefect>{TetMeshDefect::IsolatedVertex}) << r.summary();
  EXPECT_TRUE(mentions(r, TetMeshDefect::IsolatedVertex));
}

TEST(TetMeshCheck, BadIndex) {
  for (const Tet bad : {Tet{1, 2, 3, 99}, Tet{7, 7, 7, 7}, Tet{2, 3, 2, 5}}) {
    TetMesh m = kuhn_cube();
    m.tetrahedra.push_back(bad);  // every Kuhn tetrahedron starts at 0: still in order
    const TetMeshReport r = check_tet_mesh(m, cube(0, 0, 0, 1), {});
    EXPECT_EQ(kinds(r), std::vector<TetMeshDefect>{TetMeshDefect::BadIndex}) << r.summary();
    EXPECT_TRUE(mentions(r, TetMeshDefect::BadIndex));
  }
}

TEST(TetMeshCheck, NonCanonicalForms) {
  TetMesh m = kuhn_cube();
  std::swap(m.tetrahedra[0], m.tetrahedra[1]);
  TetMeshReport r = check_tet_mesh(m, cube(0, 0, 0, 1), {});
  EXPECT_EQ(kinds(r), std::vector<TetMeshDefect>{TetMeshDefect::Canonical}) << r.summary();
  EXPECT_NE(r.summary().find("out of order"), std::string::npos);

  // An even permutation that is not the canonical rotation: same tetrahedron, same
  // orientation, wrong first corner; and one with the right first corner but the wrong second.
  m = kuhn_cube();
  const Tet t = m.tetrahedra[2];
  m.tetrahedra[2] = {t[1], t[0], t[3], t[2]};
  r = check_tet_mesh(m, cube(0, 0, 0, 1), {});
  EXPECT_EQ(kinds(r), std::vector<TetMeshDefect>{TetMeshDefect::Canonical}) << r.summary();
  EXPECT_NE(r.summary().find("canonical rotation"), std::string::npos);
  m = kuhn_cube();
  m.tetrahedra[2] = {t[0], t[2], t[3], t[1]};
  r = check_tet_mesh(m, cube(0, 0, 0, 1), {});
  EXPECT_EQ(kinds(r), std::vector<TetMeshDefect>{TetMeshDefect::Canonical}) << r.summary();

  // Vertices out of (x, y, z) order, renumbered consistently: the same tetrahedra.
  m = kuhn_cube();
  std::swap(m.vertices[1], m.vertices[2]);
  for (Tet& tet : m.tetrahedra)
    for (std::uint32_t& i : tet) i = i == 1 ? 2 : i == 2 ? 1 : i;
  r = check_tet_mesh(m, cube(0, 0, 0, 1), std::vector<Point<3>>{{0, 0, 1}, {0, 1, 0}});
  EXPECT_TRUE(r.has(TetMeshDefect::Canonical)) << r.summary();
  EXPECT_NE(r.summary().find("strictly increasing (x, y, z) order"), std::string::npos);
  EXPECT_FALSE(r.has(TetMeshDefect::MissingInput));
  EXPECT_FALSE(r.has(TetMeshDefect::MissingCorner));
  EXPECT_FALSE(r.has(TetMeshDefect::OpenFace));
  EXPECT_FALSE(r.has(TetMeshDefect::Orientation));
}

TEST(TetMeshCheck, DihedralAnglesOutsideTheBounds) {
  const TetMesh m = kuhn_grid(2);
  // The bounds are inclusive: Kuhn's 45 and 90 degrees pass bounds just beyond them.
  EXPECT_TRUE(check_tet_mesh(m, cube(0, 0, 0, 2), {}, {45 - 1e-9, 90 + 1e-9}).ok());

  TetMeshReport r = check_tet_mesh(m, cube(0, 0, 0, 2), {}, {45.000001, 180});
  EXPECT_EQ(kinds(r), std::vector<TetMeshDefect>{TetMeshDefect::SmallDihedral}) << r.summary();
  EXPECT_EQ(count(r, TetMeshDefect::SmallDihedral), 48u);  // reported once a tetrahedron
  EXPECT_NE(r.problems.at(0).find("degrees, below 45.0000"), std::string::npos) << r.problems[0];

  r = check_tet_mesh(m, cube(0, 0, 0, 2), {}, {0, 89.999999});
  EXPECT_EQ(kinds(r), std::vector<TetMeshDefect>{TetMeshDefect::LargeDihedral}) << r.summary();
  EXPECT_EQ(count(r, TetMeshDefect::LargeDihedral), 48u);
  EXPECT_TRUE(mentions(r, TetMeshDefect::LargeDihedral));

  // The cone cube with its apex moved almost onto the bottom face (still a tiling: any
  // interior apex of a convex box gives one), above a point inside one bottom triangle: the
  // two tetrahedra on the bottom are flat, with dihedral angles near 0 and near 180.
  std::vector<Tetrahedron> ts;
  for (const Tetrahedron& t : cone_cube()) {
    std::array<Point<3>, 4> v = t.v;
    for (Point<3>& p : v)
      if (p == Point<3>{0.5, 0.5, 0.5}) p = {0.3, 0.6, 1e-3};
    ts.push_back(positive(v[0], v[1], v[2], v[3]));
  }
  r = check_tet_mesh(make_tet_mesh(ts), cube(0, 0, 0, 1), {}, {5, 175});
  EXPECT_EQ(kinds(r), (std::vector<TetMeshDefect>{TetMeshDefect::SmallDihedral, TetMeshDefect::LargeDihedral}))
      << r.summary();
  EXPECT_LT(r.min_dihedral_deg, 1);
  EXPECT_GT(r.max_dihedral_deg, 179);
}

TEST(TetMeshCheck, ProblemsAreTruncatedButCounted) {
  TetMesh m = kuhn_grid(3);
  for (Tet& t : m.tetrahedra) std::swap(t[2], t[3]);
  TetMeshCheckOptions options;
  options.max_problems = 5;
  const TetMeshReport r = check_tet_mesh(m, cube(0, 0, 0, 3), {}, options);
  EXPECT_EQ(r.problems.size(), 5u);
  EXPECT_TRUE(r.truncated);
  EXPECT_EQ(count(r, TetMeshDefect::Orientation), 162u);
  EXPECT_NE(r.summary().find("more)"), std::string::npos);
  options.max_problems = 3;
  try {
    require_valid_tet_mesh(m, cube(0, 0, 0, 3), {}, options);
    ADD_FAILURE() << "no InvariantError";
  } catch (const InvariantError& e) {
    EXPECT_NE(std::string(e.what()).find("orientation"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("tetrahedral mesh invalid", 0), 0u) << e.what();
  }
}

TEST(TetMeshCheck, EmptyMesh) {
  const TetMeshReport r = check_tet_mesh(TetMesh{}, cube(0, 0, 0, 1), {});
  EXPECT_EQ(count(r, TetMeshDefect::MissingCorner), 8u);
  EXPECT_TRUE(r.has(TetMeshDefect::Volume));
  EXPECT_EQ(r.min_dihedral_deg, 0);
}

TEST(TetMeshCheck, LargeJitteredGrid) {
  // 6·20^3 = 48k tetrahedra, sized for sanitizer builds. The time is recorded, not asserted:
  // the machine is shared.
  const TetMesh m = kuhn_grid(20, 0.1, 3);
  const auto start = std::chrono::steady_clock::now();
  const TetMeshReport r = check_tet_mesh(m, cube(0, 0, 0, 20), {});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(r.ok()) << r.summary();
  RecordProperty("check_seconds", std::to_string(seconds));
}

}  // namespace
