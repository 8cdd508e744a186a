// mesh_check_test.cpp — mesh_check.hpp: valid meshes pass, and every kind of corruption is
// reported as its own defect.
#include "dynmesh/mesh_check.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "dynmesh/errors.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/predicates.hpp"

namespace {

using namespace dynmesh;
using Tri = std::array<std::uint32_t, 3>;

Box<2> square(double o1, double o2, double side) { return Box<2>{{o1, o2}, side}; }

// The n x n grid of unit squares on [0, n]^2, each split by its rising diagonal. `jitter`
// moves interior vertices by up to that much per axis (quads stay convex for jitter < 0.25).
Mesh grid(int n, double jitter = 0, unsigned seed = 1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> shift(-jitter, jitter);
  std::vector<Point<2>> at((n + 1) * (n + 1));
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      Point<2> p{double(i), double(j)};
      if (jitter > 0 && i > 0 && i < n && j > 0 && j < n) p = {p[0] + shift(rng), p[1] + shift(rng)};
      at[i * (n + 1) + j] = p;
    }
  std::vector<Triangle> ts;
  ts.reserve(2 * n * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Point<2>&a = at[i * (n + 1) + j], &b = at[(i + 1) * (n + 1) + j], &c = at[(i + 1) * (n + 1) + j + 1],
            &d = at[i * (n + 1) + j + 1];
      ts.push_back(canonical_triangle(a, b, c));
      ts.push_back(canonical_triangle(a, c, d));
    }
  return make_mesh(ts);
}

// The unit box split by its rising diagonal.
Mesh two_triangles() {
  const std::vector<Triangle> ts = {canonical_triangle({0, 0}, {1, 0}, {1, 1}),
                                    canonical_triangle({0, 0}, {1, 1}, {0, 1})};
  return make_mesh(ts);
}

// The box [0, s]^2 as a fan around an interior vertex c.
Mesh fan(Point<2> c, double s = 1) {
  const Point<2> a{0, 0}, b{s, 0}, d{s, s}, e{0, s};
  const std::vector<Triangle> ts = {canonical_triangle(a, b, c), canonical_triangle(b, d, c),
                                    canonical_triangle(d, e, c), canonical_triangle(e, a, c)};
  return make_mesh(ts);
}

std::size_t count(const MeshReport& r, MeshDefect d) { return r.counts[static_cast<std::size_t>(d)]; }

// The defects present, for messages and for "exactly these" assertions.
std::vector<MeshDefect> kinds(const MeshReport& r) {
  std::vector<MeshDefect> out;
  for (std::size_t k = 0; k < kMeshDefectKinds; ++k)
    if (r.counts[k] != 0) out.push_back(static_cast<MeshDefect>(k));
  return out;
}

bool mentions(const MeshReport& r, MeshDefect d) {
  const std::string prefix = std::string(defect_name(d)) + ": ";
  return std::any_of(r.problems.begin(), r.problems.end(),
                     [&](const std::string& p) { return p.rfind(prefix, 0) == 0; });
}

// ---- valid meshes pass -----------------------------------------------------------------------

TEST(MeshCheck, SmallValidMeshesPass) {
  const MeshCheckOptions delaunay{0, true};
  const std::vector<Point<2>> corners = {{0, 0}, {1, 1}};
  MeshReport r = check_mesh(two_triangles(), square(0, 0, 1), corners, delaunay);
  EXPECT_TRUE(r.ok()) << r.summary();
  EXPECT_DOUBLE_EQ(r.min_angle_deg, 45);
  EXPECT_DOUBLE_EQ(r.max_angle_deg, 90);

  const std::vector<Point<2>> centre = {{0.5, 0.5}};
  r = check_mesh(fan({0.5, 0.5}), square(0, 0, 1), centre, delaunay);
  EXPECT_TRUE(r.ok()) << r.summary();

  // Cocircular squares: either diagonal is Delaunay (nothing strictly inside).
  r = check_mesh(grid(4), square(0, 0, 4), {}, MeshCheckOptions{45, true});
  EXPECT_TRUE(r.ok()) << r.summary();
  EXPECT_EQ(r.summary().rfind("mesh ok", 0), 0u);
  EXPECT_NO_THROW(require_valid_mesh(grid(4), square(0, 0, 4), {}));
}

TEST(MeshCheck, OffsetBoxWithInexactUpperSide) {
  // fl(0.1 + 0.7) = 0.7999999999999999: the box's upper sides are where the sum rounds.
  const Box<2> box = square(0.1, 0.1, 0.7);
  const double hi = 0.1 + 0.7;
  const std::vector<Triangle> ts = {canonical_triangle({0.1, 0.1}, {hi, 0.1}, {hi, hi}),
                                    canonical_triangle({0.1, 0.1}, {hi, hi}, {0.1, hi})};
  EXPECT_TRUE(check_mesh(make_mesh(ts), box, {}).ok());
  const std::vector<Triangle> exact = {canonical_triangle({0.1, 0.1}, {0.8, 0.1}, {0.8, 0.8}),
                                       canonical_triangle({0.1, 0.1}, {0.8, 0.8}, {0.1, 0.8})};
  const MeshReport r = check_mesh(make_mesh(exact), box, {});
  EXPECT_TRUE(r.has(MeshDefect::OutsideBox)) << r.summary();
  EXPECT_TRUE(r.has(MeshDefect::MissingCorner)) << r.summary();
}

TEST(MeshCheck, BoxesOfExtremeSizePass) {
  // Areas and angles in double: the box's area overflows at L = 2^600 and a corner's cross
  // product underflows at L = 2^-600, yet the mesh is the plain two-triangle box (fuzzing).
  for (const double side : {0x1p600, 0x1p-600, 3.1223605929922333e+307}) {
    SCOPED_TRACE(side);
    const Box<2> box = square(-side / 2, 0, side);
    const double hi = -side / 2 + side;
    const std::vector<Triangle> ts = {canonical_triangle({-side / 2, 0}, {hi, 0}, {hi, side}),
                                      canonical_triangle({-side / 2, 0}, {hi, side}, {-side / 2, side})};
    const MeshReport r = check_mesh(make_mesh(ts), box, {}, MeshCheckOptions{44, false});
    EXPECT_TRUE(r.ok()) << r.summary();
    EXPECT_DOUBLE_EQ(r.min_angle_deg, 45);
    EXPECT_DOUBLE_EQ(r.max_angle_deg, 90);
  }
}

TEST(MeshCheck, JitteredGridPasses) {
  const std::vector<Point<2>> inputs = {{0, 0}, {30, 30}, {0, 30}};
  const MeshReport r = check_mesh(grid(30, 0.2, 7), square(0, 0, 30), inputs);
  EXPECT_TRUE(r.ok()) << r.summary();
  EXPECT_GT(r.min_angle_deg, 0);
  EXPECT_LT(r.max_angle_deg, 180);
}

TEST(MeshCheck, FanWithManyBoundaryVerticesPasses) {
  // Long edges from the centre to every boundary vertex: the vertex-in-edge search must
  // prune by the edge's line, not only its bounding box, to stay fast here.
  const int per_side = 2000;
  const Point<2> c{0.5, 0.5};
  std::vector<Point<2>> ring;
  for (int k = 0; k < per_side; ++k) ring.push_back({double(k) / per_side, 0});
  for (int k = 0; k < per_side; ++k) ring.push_back({1, double(k) / per_side});
  for (int k = 0; k < per_side; ++k) ring.push_back({1 - double(k) / per_side, 1});
  for (int k = 0; k < per_side; ++k) ring.push_back({0, 1 - double(k) / per_side});
  std::vector<Triangle> ts;
  for (std::size_t k = 0; k < ring.size(); ++k)
    ts.push_back(canonical_triangle(ring[k], ring[(k + 1) % ring.size()], c));
  const MeshReport r = check_mesh(make_mesh(ts), square(0, 0, 1), {});
  EXPECT_TRUE(r.ok()) << r.summary();
}

// ---- each corruption is reported -------------------------------------------------------------

TEST(MeshCheck, ClockwiseTriangle) {
  Mesh m = grid(4);
  std::swap(m.triangles[5][1], m.triangles[5][2]);  // still starts at its smallest index
  const MeshReport r = check_mesh(m, square(0, 0, 4), {});
  EXPECT_EQ(count(r, MeshDefect::Orientation), 1u) << r.summary();
  EXPECT_TRUE(mentions(r, MeshDefect::Orientation));
  EXPECT_NE(r.summary().find("clockwise"), std::string::npos);
}

TEST(MeshCheck, DroppedTriangleIsAHole) {
  for (std::size_t drop : {0u, 7u, 31u}) {  // a corner triangle, an inner one, the last
    Mesh m = grid(4);
    m.triangles.erase(m.triangles.begin() + drop);
    const MeshReport r = check_mesh(m, square(0, 0, 4), {});
    EXPECT_TRUE(r.has(MeshDefect::OpenEdge)) << drop << ": " << r.summary();
    EXPECT_TRUE(r.has(MeshDefect::Area)) << r.summary();
    EXPECT_FALSE(r.has(MeshDefect::Orientation));
    EXPECT_FALSE(r.has(MeshDefect::EdgeTwice));
  }
}

TEST(MeshCheck, DuplicatedTriangle) {
  Mesh m = grid(4);
  m.triangles.insert(m.triangles.begin() + 9, m.triangles[9]);
  const MeshReport r = check_mesh(m, square(0, 0, 4), {});
  EXPECT_EQ(count(r, MeshDefect::EdgeTwice), 3u) << r.summary();
  EXPECT_TRUE(r.has(MeshDefect::Area));
  EXPECT_FALSE(r.has(MeshDefect::Canonical));  // equal neighbours are still in order
  EXPECT_FALSE(r.has(MeshDefect::Orientation));
}

TEST(MeshCheck, VertexOffTheBox) {
  Mesh m = grid(4);
  ASSERT_EQ(m.vertices[10], (Point<2>{2, 0}));  // column x = 2 starts at index 2·5
  m.vertices[10] = {2, -0.5};
  const MeshReport r = check_mesh(m, square(0, 0, 4), {});
  EXPECT_EQ(count(r, MeshDefect::OutsideBox), 1u) << r.summary();
  EXPECT_TRUE(r.has(MeshDefect::OpenEdge));  // its boundary edges left the side line
  EXPECT_FALSE(r.has(MeshDefect::Canonical));
}

TEST(MeshCheck, TJunctionInsideTheBox) {
  // The vertex m sits exactly on the diagonal of the lower triangle, which is not split.
  const Point<2> a{0, 0}, b{1, 0}, c{1, 1}, d{0, 1}, mid{0.5, 0.5};
  const std::vector<Triangle> ts = {canonical_triangle(a, b, c), canonical_triangle(a, mid, d),
                                    canonical_triangle(mid, c, d)};
  const MeshReport r = check_mesh(make_mesh(ts), square(0, 0, 1), {});
  EXPECT_EQ(count(r, MeshDefect::VertexInEdge), 1u) << r.summary();
  EXPECT_TRUE(r.has(MeshDefect::OpenEdge));
  EXPECT_FALSE(r.has(MeshDefect::Area));  // the area alone does not see it
  EXPECT_FALSE(r.has(MeshDefect::Orientation));

  // One ulp off the diagonal is not inside the edge (the decision is exact).
  const Point<2> above{0.5, std::nextafter(0.5, 1.0)};
  const std::vector<Triangle> near = {canonical_triangle(a, b, c), canonical_triangle(a, above, d),
                                      canonical_triangle(above, c, d)};
  const MeshReport r2 = check_mesh(make_mesh(near), square(0, 0, 1), {});
  EXPECT_FALSE(r2.has(MeshDefect::VertexInEdge)) << r2.summary();
  EXPECT_TRUE(r2.has(MeshDefect::OpenEdge));
}

TEST(MeshCheck, VertexOnNonAxisEdgeIsDecidedExactly) {
  // A single triangle with one more vertex near or on its edge p -> q (other defects aside).
  // Dyadic coordinates are exactly collinear; the decimal midpoint of (0.1, 0.2) and (0.7, 0.5)
  // may not be, and the checker must agree with orient2d either way.
  struct Case {
    Point<2> p, q, mid;
  };
  for (const Case& k :
       {Case{{0.125, 0.25}, {0.875, 0.625}, {0.5, 0.4375}}, Case{{0.1, 0.2}, {0.7, 0.5}, {0.4, 0.35}}}) {
    Mesh m = make_mesh(std::vector<Triangle>{canonical_triangle(k.p, k.q, {0.875, 0.9})});
    ASSERT_EQ(m.vertices[0], k.p);
    m.vertices.insert(m.vertices.begin() + 1, k.mid);  // mid sorts between p and the rest
    for (auto& t : m.triangles)
      for (auto& i : t)
        if (i >= 1) ++i;
    const MeshReport r = check_mesh(m, square(0, 0, 1), {});
    EXPECT_FALSE(r.has(MeshDefect::Canonical)) << r.summary();
    EXPECT_TRUE(r.has(MeshDefect::IsolatedVertex));
    EXPECT_EQ(r.has(MeshDefect::VertexInEdge), orient2d(k.p, k.q, k.mid) == 0) << r.summary();
  }
  EXPECT_EQ(orient2d({0.125, 0.25}, {0.875, 0.625}, {0.5, 0.4375}), 0);
}

TEST(MeshCheck, TJunctionOnTheBoundary) {
  // A fan on [0, 2]^2, plus (1, 0) on the bottom side used by an extra triangle: it lies
  // inside the fan's bottom edge.
  std::vector<Triangle> ts = triangles_of(fan({1, 1}, 2));
  ts.push_back(canonical_triangle({0, 0}, {1, 0}, {1, 1}));
  const MeshReport r = check_mesh(make_mesh(ts), square(0, 0, 2), {});
  EXPECT_EQ(count(r, MeshDefect::VertexInEdge), 1u) << r.summary();
  EXPECT_TRUE(mentions(r, MeshDefect::VertexInEdge));
}

TEST(MeshCheck, LongEdgesThroughManyVertices) {
  // A big triangle laid over a 40 x 40 grid: its three edges run through the grid's
  // vertices on the left side, the top side and (unjittered) the diagonal. Long edges take
  // the tree search rather than the short scan.
  const int n = 40;
  for (const double jitter : {0.0, 0.2}) {
    std::vector<Triangle> ts = triangles_of(grid(n, jitter, 5));
    ts.push_back(canonical_triangle({0, 0}, {double(n), double(n)}, {0, double(n)}));
    const MeshReport r = check_mesh(make_mesh(ts), square(0, 0, n), {});
    const std::size_t sides = jitter == 0 ? 3 : 2;  // jitter moves the diagonal's vertices off it
    EXPECT_EQ(count(r, MeshDefect::VertexInEdge), sides * (n - 1)) << "jitter " << jitter;
    EXPECT_TRUE(r.has(MeshDefect::Area));
  }
}

TEST(MeshCheck, MissingInputPoint) {
  const std::vector<Point<2>> inputs = {{1, 1}, {0.5, 0.5}, {0, 0}};
  const MeshReport r = check_mesh(two_triangles(), square(0, 0, 1), inputs);
  EXPECT_EQ(kinds(r), std::vector<MeshDefect>{MeshDefect::MissingInput}) << r.summary();
  EXPECT_EQ(count(r, MeshDefect::MissingInput), 1u);
  EXPECT_NE(r.problems.at(0).find("input point 1"), std::string::npos) << r.problems[0];
}

TEST(MeshCheck, SliverBelowTheAngleBound) {
  const Mesh m = fan({0.5, 0.01});
  const MeshReport loose = check_mesh(m, square(0, 0, 1), {});
  EXPECT_TRUE(loose.ok()) << loose.summary();
  EXPECT_NEAR(loose.min_angle_deg, std::atan2(0.01, 0.5) * 180 / 3.14159265358979323846, 1e-9);

  const MeshReport strict = check_mesh(m, square(0, 0, 1), {}, MeshCheckOptions{20, false});
  EXPECT_EQ(kinds(strict), std::vector<MeshDefect>{MeshDefect::SmallAngle}) << strict.summary();
  EXPECT_EQ(count(strict, MeshDefect::SmallAngle), 1u);  // the bottom triangle
  // The bound is inclusive: exactly 45 degrees passes a 45-degree bound.
  EXPECT_TRUE(check_mesh(grid(4), square(0, 0, 4), {}, MeshCheckOptions{45, false}).ok());
  EXPECT_EQ(count(check_mesh(grid(4), square(0, 0, 4), {}, MeshCheckOptions{45.000001, false}), MeshDefect::SmallAngle),
            32u);
}

TEST(MeshCheck, NonDelaunayDiagonal) {
  // Corners and p = (0.3, 0.6), no four of the five cocircular except the corners. The fan
  // is the Delaunay triangulation; keeping the box diagonal instead puts p strictly inside
  // the circumcircle of the lower triangle.
  const Point<2> a{0, 0}, b{1, 0}, c{1, 1}, d{0, 1}, p{0.3, 0.6};
  const MeshReport good = check_mesh(fan(p), square(0, 0, 1), {}, MeshCheckOptions{0, true});
  EXPECT_TRUE(good.ok()) << good.summary();

  const std::vector<Triangle> ts = {canonical_triangle(a, b, c), canonical_triangle(a, c, p),
                                    canonical_triangle(c, d, p), canonical_triangle(d, a, p)};
  const Mesh flipped = make_mesh(ts);
  EXPECT_TRUE(check_mesh(flipped, square(0, 0, 1), {}).ok());  // a valid mesh...
  const MeshReport r = check_mesh(flipped, square(0, 0, 1), {}, MeshCheckOptions{0, true});
  EXPECT_EQ(kinds(r), std::vector<MeshDefect>{MeshDefect::NotDelaunay}) << r.summary();  // ...not Delaunay
  EXPECT_EQ(count(r, MeshDefect::NotDelaunay), 1u);
}

TEST(MeshCheck, MissingCorner) {
  const MeshReport r = check_mesh(two_triangles(), square(0, 0, 2), {});
  EXPECT_EQ(count(r, MeshDefect::MissingCorner), 3u) << r.summary();
  EXPECT_TRUE(r.has(MeshDefect::OpenEdge));
  EXPECT_TRUE(r.has(MeshDefect::Area));
}

TEST(MeshCheck, IsolatedVertex) {
  Mesh m = two_triangles();
  m.vertices.insert(m.vertices.begin() + 2, Point<2>{0.5, 0.25});
  for (auto& t : m.triangles)
    for (auto& i : t)
      if (i >= 2) ++i;
  const std::vector<Point<2>> inputs = {{0.5, 0.25}};
  const MeshReport r = check_mesh(m, square(0, 0, 1), inputs);
  EXPECT_EQ(kinds(r), std::vector<MeshDefect>{MeshDefect::IsolatedVertex}) << r.summary();
}

TEST(MeshCheck, BadIndexAndNonCanonicalForms) {
  Mesh m = two_triangles();
  m.triangles.push_back({1, 2, 99});
  MeshReport r = check_mesh(m, square(0, 0, 1), {});
  EXPECT_EQ(kinds(r), std::vector<MeshDefect>{MeshDefect::BadIndex}) << r.summary();

  m = two_triangles();
  std::swap(m.triangles[0], m.triangles[1]);
  r = check_mesh(m, square(0, 0, 1), {});
  EXPECT_EQ(kinds(r), std::vector<MeshDefect>{MeshDefect::Canonical}) << r.summary();

  m = two_triangles();
  m.triangles[1] = {3, 1, 0};  // a rotation of {0, 3, 1}: same triangle, wrong first corner
  r = check_mesh(m, square(0, 0, 1), {});
  EXPECT_EQ(kinds(r), std::vector<MeshDefect>{MeshDefect::Canonical}) << r.summary();

  m = two_triangles();
  std::swap(m.vertices[1], m.vertices[2]);  // renumber consistently: the mesh is the same
  for (auto& t : m.triangles)
    for (auto& i : t) i = i == 1 ? 2 : i == 2 ? 1 : i;
  r = check_mesh(m, square(0, 0, 1), std::vector<Point<2>>{{0, 1}});
  EXPECT_TRUE(r.has(MeshDefect::Canonical)) << r.summary();
  EXPECT_FALSE(r.has(MeshDefect::MissingInput));
  EXPECT_FALSE(r.has(MeshDefect::OpenEdge));
}

TEST(MeshCheck, ProblemsAreTruncatedButCounted) {
  Mesh m = grid(10);
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  const MeshReport r = check_mesh(m, square(0, 0, 10), {}, {}, 5);
  EXPECT_EQ(r.problems.size(), 5u);
  EXPECT_TRUE(r.truncated);
  EXPECT_EQ(count(r, MeshDefect::Orientation), 200u);
  EXPECT_NE(r.summary().find("more)"), std::string::npos);
  try {
    require_valid_mesh(m, square(0, 0, 10), {}, {}, 3);
    ADD_FAILURE() << "no InvariantError";
  } catch (const InvariantError& e) {
    EXPECT_NE(std::string(e.what()).find("orientation"), std::string::npos) << e.what();
  }
}

TEST(MeshCheck, EmptyMesh) {
  const MeshReport r = check_mesh(Mesh{}, square(0, 0, 1), {});
  EXPECT_EQ(count(r, MeshDefect::MissingCorner), 4u);
  EXPECT_TRUE(r.has(MeshDefect::Area));
}

TEST(MeshCheck, LargeJitteredGrid) {
  // 2·150^2 = 45k triangles, sized for sanitizer builds. The time is recorded, not asserted:
  // the machine is shared.
  const Mesh m = grid(150, 0.2, 3);
  const auto start = std::chrono::steady_clock::now();
  const MeshReport r = check_mesh(m, square(0, 0, 150), {});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(r.ok()) << r.summary();
  RecordProperty("check_seconds", std::to_string(seconds));
}

}  // namespace
