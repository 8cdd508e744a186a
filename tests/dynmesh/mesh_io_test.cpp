// mesh_io_test.cpp — mesh_io.hpp: exact text of small meshes, .node/.ele round trips,
// VTK/MSH structure, the SVG picture, statistics and the change feed.
#include "dynmesh/mesh_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "dynmesh/errors.hpp"
#include "dynmesh/mesh.hpp"
#include "text_test_support.hpp"

namespace {

using namespace dynmesh;
using Kind = InputError::Kind;
using dynmesh_test::input_error_kind;
using dynmesh_test::lines_of;

Box<2> square(double o1, double o2, double side) { return Box<2>{{o1, o2}, side}; }

Mesh two_triangles() {
  const std::vector<Triangle> ts = {canonical_triangle({0, 0}, {1, 0}, {1, 1}),
                                    canonical_triangle({0, 0}, {1, 1}, {0, 1})};
  return make_mesh(ts);
}

Mesh grid(int n) {
  std::vector<Triangle> ts;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Point<2> a{double(i), double(j)}, b{double(i + 1), double(j)}, c{double(i + 1), double(j + 1)},
          d{double(i), double(j + 1)};
      ts.push_back(canonical_triangle(a, b, c));
      ts.push_back(canonical_triangle(a, c, d));
    }
  return make_mesh(ts);
}

std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

// ---- .node / .ele ----------------------------------------------------------------------------

TEST(MeshIo, NodeAndEleOfTheBoxSplitByADiagonal) {
  const Mesh m = two_triangles();
  EXPECT_EQ(format_node(m, square(0, 0, 1)), "4 2 0 1\n1 0 0 1\n2 0 1 1\n3 1 0 1\n4 1 1 1\n");
  EXPECT_EQ(format_ele(m), "2 3 0\n1 1 3 4\n2 1 4 2\n");
}

TEST(MeshIo, NodeMarksOnlyBoundaryVertices) {
  const Point<2> a{0, 0}, b{2, 0}, c{2, 2}, d{0, 2}, mid{1, 0.5}, e{1, 0};
  const std::vector<Triangle> ts = {canonical_triangle(a, e, mid), canonical_triangle(e, b, mid),
                                    canonical_triangle(b, c, mid), canonical_triangle(c, d, mid),
                                    canonical_triangle(d, a, mid)};
  const Mesh m = make_mesh(ts);
  EXPECT_EQ(format_node(m, square(0, 0, 2)), "6 2 0 1\n1 0 0 1\n2 0 2 1\n3 1 0 1\n4 1 0.5 0\n5 2 0 1\n6 2 2 1\n");
  EXPECT_EQ(format_ele(m), "5 3 0\n1 1 3 4\n2 1 4 2\n3 2 4 6\n4 3 5 4\n5 4 5 6\n");
}

TEST(MeshIo, UpperBoxSidesUseTheRoundedSum) {
  // fl(0.1 + 0.7) = 0.7999999999999999 is the upper side; 0.8 would be outside.
  const Box<2> box = square(0.1, 0.1, 0.7);
  const double hi = 0.1 + 0.7;
  const std::vector<Triangle> ts = {
      canonical_triangle({0.1, 0.1}, {hi, 0.1}, {0.45, 0.45}), canonical_triangle({hi, 0.1}, {hi, hi}, {0.45, 0.45}),
      canonical_triangle({hi, hi}, {0.1, hi}, {0.45, 0.45}), canonical_triangle({0.1, hi}, {0.1, 0.1}, {0.45, 0.45})};
  const std::vector<std::string> lines = lines_of(format_node(make_mesh(ts), box));
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_EQ(lines[3], "3 0.45000000000000001 0.45000000000000001 0");
  EXPECT_EQ(lines[5], "5 0.79999999999999993 0.79999999999999993 1");
}

TEST(MeshIo, NodeEleRoundTripIsBitExact) {
  // Awkward values: subnormal, huge, negative zero's neighbours, thirds and tenths.
  Mesh m;
  m.vertices = {{-2.5e-17, 123456789.123}, {5e-324, 1e300}, {0.1, 1.0 / 3}, {0.30000000000000004, -7e-310}};
  m.triangles = {{0, 2, 1}, {0, 3, 2}};
  const Mesh back = read_node_ele(format_node(m, square(0, 0, 1)), format_ele(m));
  ASSERT_EQ(back.vertices.size(), m.vertices.size());
  for (std::size_t i = 0; i < m.vertices.size(); ++i)
    for (int a = 0; a < 2; ++a)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(back.vertices[i][a]), std::bit_cast<std::uint64_t>(m.vertices[i][a]));
  EXPECT_EQ(back.triangles, m.triangles);

  const Mesh g = grid(4);
  EXPECT_EQ(read_node_ele(format_node(g, square(0, 0, 4)), format_ele(g)), g);
}

TEST(MeshIo, ReaderAcceptsTriangleConventions) {
  // Numbering from 0, comments, attributes and markers, blank lines.
  const std::string node = "# a comment\n3 2 1 1\n\n0 0 0 7 1\n1 1 0 7 1 # trailing\n2 0 1 7 1\n";
  const std::string ele = "1 3 0\n0  0 1 2\n";
  const Mesh m = read_node_ele(node, ele);
  EXPECT_EQ(m.vertices, (std::vector<Point<2>>{{0, 0}, {1, 0}, {0, 1}}));
  EXPECT_EQ(m.triangles, (std::vector<std::array<std::uint32_t, 3>>{{0, 1, 2}}));
}

TEST(MeshIo, ReaderErrorsNameFileAndKind) {
  const std::string ele = "1 3 0\n1 1 2 3\n";
  EXPECT_EQ(input_error_kind([&] { read_node_ele("3 2 0 0\n1 0 0\n2 1 0\n", ele); }), Kind::Count);
  EXPECT_EQ(input_error_kind([&] { read_node_ele("3 2 0 0\n1 0 0\n2 1 x\n3 0 1\n", ele); }), Kind::Malformed);
  EXPECT_EQ(input_error_kind([&] { read_node_ele("3 2 0 0\n1 0 0\n2 1 nan\n3 0 1\n", ele); }), Kind::NotFinite);
  EXPECT_EQ(input_error_kind([&] { read_node_ele("3 2 0 0\n1 0 0\n3 1 0\n3 0 1\n", ele); }), Kind::Malformed);
  EXPECT_EQ(input_error_kind([&] { read_node_ele("2 2 0 0\n1 0 0\n2 1 0\n3 0 1\n", ele); }), Kind::Count);
  const std::string node = "3 2 0 0\n1 0 0\n2 1 0\n3 0 1\n";
  EXPECT_EQ(input_error_kind([&] { read_node_ele(node, "1 3 0\n1 1 2 4\n"); }), Kind::Malformed);
  EXPECT_EQ(input_error_kind([&] { read_node_ele(node, "2 3 0\n1 1 2 3\n"); }), Kind::Count);
  try {
    read_node_ele(node, "1 3 0\n1 1 2 0\n");
    ADD_FAILURE() << "vertex 0 of a 1-based file accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "ele");
    EXPECT_EQ(e.line(), 2u);
  }
}

// ---- VTK and Gmsh ----------------------------------------------------------------------------

TEST(MeshIo, VtkOfTheBoxSplitByADiagonal) {
  EXPECT_EQ(format_vtk(two_triangles()),
            "# vtk DataFile Version 3.0\ndynmesh mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n"
            "POINTS 4 double\n0 0 0\n0 1 0\n1 0 0\n1 1 0\n"
            "CELLS 2 8\n3 0 2 3\n3 0 3 1\n"
            "CELL_TYPES 2\n5\n5\n");
}

TEST(MeshIo, VtkStructureCounts) {
  const Mesh m = grid(5);
  const std::vector<std::string> lines = lines_of(format_vtk(m));
  const std::size_t nv = m.num_vertices(), nt = m.num_triangles();
  ASSERT_EQ(lines.size(), 4 + 1 + nv + 1 + nt + 1 + nt);
  EXPECT_EQ(lines[4], "POINTS " + std::to_string(nv) + " double");
  EXPECT_EQ(lines[5 + nv], "CELLS " + std::to_string(nt) + " " + std::to_string(4 * nt));
  EXPECT_EQ(lines[6 + nv + nt], "CELL_TYPES " + std::to_string(nt));
  EXPECT_EQ(std::count(lines.begin(), lines.end(), "5"), static_cast<std::ptrdiff_t>(nt));
}

TEST(MeshIo, MshOfTheBoxSplitByADiagonal) {
  EXPECT_EQ(format_msh(two_triangles()),
            "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
            "$Nodes\n4\n1 0 0 0\n2 0 1 0\n3 1 0 0\n4 1 1 0\n$EndNodes\n"
            "$Elements\n2\n1 2 2 1 1 1 3 4\n2 2 2 1 1 1 4 2\n$EndElements\n");
}

TEST(MeshIo, MshStructureCounts) {
  const Mesh m = grid(5);
  const std::vector<std::string> lines = lines_of(format_msh(m));
  const std::size_t nv = m.num_vertices(), nt = m.num_triangles();
  ASSERT_EQ(lines.size(), 3 + 2 + nv + 1 + 2 + nt + 1);
  EXPECT_EQ(lines[4], std::to_string(nv));
  EXPECT_EQ(lines[5 + nv], "$EndNodes");
  EXPECT_EQ(lines[7 + nv], std::to_string(nt));
  EXPECT_EQ(lines.back(), "$EndElements");
  for (std::size_t t = 0; t < nt; ++t) EXPECT_EQ(lines[8 + nv + t].rfind(std::to_string(t + 1) + " 2 2 ", 0), 0u);
}

// ---- SVG -------------------------------------------------------------------------------------

// The concatenated d attributes of all <path> elements.
std::string path_data(const std::string& svg) {
  std::string d;
  for (std::size_t at = svg.find("<path d=\""); at != std::string::npos; at = svg.find("<path d=\"", at + 1)) {
    const std::size_t start = at + 9;
    d += svg.substr(start, svg.find('"', start) - start);
  }
  return d;
}

TEST(MeshIo, SvgDrawsEachEdgeOnceWithYUp) {
  SvgMeshOptions opt;
  opt.width_px = 100;
  opt.margin_px = 10;
  const std::vector<Point<2>> inputs = {{0.5, 0.5}, {0.25, 0.75}, {0.25, 0.75}};
  const std::string svg = format_svg(two_triangles(), square(0, 0, 1), inputs, opt);
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  EXPECT_EQ(occurrences(svg, "<path"), 1u);
  const std::string d = path_data(svg);
  EXPECT_EQ(std::count(d.begin(), d.end(), 'L'), 5);  // 4 sides and the diagonal
  // (0, 0) is the lower left corner: pixel (10, 110); (1, 1) the upper right: (110, 10).
  EXPECT_NE(d.find("10 110"), std::string::npos) << d;
  EXPECT_NE(d.find("110 10"), std::string::npos) << d;
  EXPECT_EQ(occurrences(svg, "<circle"), 2u);                     // the repeated input point is drawn once
  EXPECT_NE(svg.find("cx=\"35\" cy=\"35\""), std::string::npos);  // (0.25, 0.75)

  opt.max_marked_inputs = 2;
  EXPECT_EQ(occurrences(format_svg(two_triangles(), square(0, 0, 1), inputs, opt), "<circle"), 0u);
}

TEST(MeshIo, SvgOfALargeMeshIsCompact) {
  const int n = 100;
  const Mesh m = grid(n);  // 20000 triangles, 3n^2 + 2n edges
  const std::string svg = format_svg(m, square(0, 0, n), {}, {});
  EXPECT_LE(occurrences(svg, "<path"), 2u);
  const std::string d = path_data(svg);
  EXPECT_EQ(std::count(d.begin(), d.end(), 'L'), 3 * n * n + 2 * n);
  EXPECT_EQ(occurrences(svg, "<circle"), 0u);
  EXPECT_LT(svg.size(), std::size_t{40} * (3 * n * n + 2 * n));
  // The automatic stroke: a tenth of the mean edge on screen (about 11 pixels), at most 1.
  const std::size_t at = svg.find("stroke-width=\"");
  ASSERT_NE(at, std::string::npos);
  const double stroke = std::stod(svg.substr(at + 14));
  EXPECT_GE(stroke, 0.05);
  EXPECT_LE(stroke, 1.0);
}

// ---- statistics ------------------------------------------------------------------------------

TEST(MeshIo, StatsOfTheGrid) {
  const MeshStats s = mesh_stats(grid(4));
  EXPECT_EQ(s.vertices, 25u);
  EXPECT_EQ(s.triangles, 32u);
  EXPECT_EQ(s.min_angle_deg, 45);
  EXPECT_EQ(s.max_angle_deg, 90);
  EXPECT_EQ(s.shortest_edge, 1);
  EXPECT_EQ(s.longest_edge, std::sqrt(2.0));
  EXPECT_EQ(s.smallest_area, 0.5);
  EXPECT_EQ(s.largest_area, 0.5);
  std::array<std::size_t, 18> histogram{};
  histogram[4] = 64;  // two 45-degree angles per triangle
  histogram[9] = 32;  // one right angle
  EXPECT_EQ(s.angle_histogram, histogram);
}

/// The statistics of the grid scaled by a power of two are the grid's, scaled: a box of
/// side 3·10^291 once reported every edge and area as infinite (squares that overflowed),
/// and a tiny one would report 0.
TEST(MeshIo, StatsAtExtremeScales) {
  const Mesh unit = grid(4);
  const MeshStats base = mesh_stats(unit);
  for (const int e : {600, 960, -600, -960}) {
    SCOPED_TRACE("scale 2^" + std::to_string(e));
    std::vector<Triangle> ts;
    for (std::size_t t = 0; t < unit.num_triangles(); ++t) {
      Triangle tri = unit.triangle(t);
      for (Point<2>& v : tri.v) v = {std::ldexp(v[0], e), std::ldexp(v[1], e)};
      ts.push_back(tri);
    }
    const MeshStats s = mesh_stats(make_mesh(ts));
    EXPECT_EQ(s.shortest_edge, std::ldexp(base.shortest_edge, e));
    EXPECT_EQ(s.longest_edge, std::ldexp(base.longest_edge, e));
    // An area of 2^1919 is beyond the doubles, and one of 2^-1921 below them.
    const double area = std::abs(e) < 512 ? std::ldexp(0.5, 2 * e) : (e > 0 ? HUGE_VAL : 0.0);
    EXPECT_EQ(s.smallest_area, area);
    EXPECT_EQ(s.largest_area, area);
    EXPECT_EQ(s.min_angle_deg, base.min_angle_deg);
    EXPECT_EQ(s.max_angle_deg, base.max_angle_deg);
    EXPECT_EQ(s.angle_histogram, base.angle_histogram);
  }
}

TEST(MeshIo, StatsReport) {
  const std::string report = format_stats(mesh_stats(grid(4)));
  EXPECT_EQ(report,
            "Mesh quality statistics:\n"
            "\n"
            "  Vertices: 25    Triangles: 32\n"
            "\n"
            "  Smallest area:  0.5           |  Largest area:   0.5\n"
            "  Shortest edge:  1             |  Longest edge:   1.41421\n"
            "  Smallest angle: 45            |  Largest angle:  90\n"
            "\n"
            "  Angle histogram:\n"
            "        0 -  10 degrees:         0    |     90 - 100 degrees:        32\n"
            "       10 -  20 degrees:         0    |    100 - 110 degrees:         0\n"
            "       20 -  30 degrees:         0    |    110 - 120 degrees:         0\n"
            "       30 -  40 degrees:         0    |    120 - 130 degrees:         0\n"
            "       40 -  50 degrees:        64    |    130 - 140 degrees:         0\n"
            "       50 -  60 degrees:         0    |    140 - 150 degrees:         0\n"
            "       60 -  70 degrees:         0    |    150 - 160 degrees:         0\n"
            "       70 -  80 degrees:         0    |    160 - 170 degrees:         0\n"
            "       80 -  90 degrees:         0    |    170 - 180 degrees:         0\n")
      << report;
}

TEST(MeshIo, StatsOfAnEmptyMesh) {
  const MeshStats s = mesh_stats(Mesh{});
  EXPECT_EQ(s.triangles, 0u);
  EXPECT_EQ(s.min_angle_deg, 0);
  EXPECT_EQ(s.largest_area, 0);
  EXPECT_FALSE(format_stats(s).empty());
}

TEST(MeshIo, StatsOfASliver) {
  const Point<2> a{0, 0}, b{1, 0}, c{0.5, 1e-3};
  const std::vector<Triangle> ts = {canonical_triangle(a, b, c)};
  const MeshStats s = mesh_stats(make_mesh(ts));
  EXPECT_NEAR(s.min_angle_deg, std::atan(2e-3) * 180 / 3.14159265358979323846, 1e-12);
  EXPECT_EQ(s.angle_histogram[0], 2u);
  EXPECT_EQ(s.angle_histogram[17], 1u);
}

// ---- the change feed -------------------------------------------------------------------------

TEST(MeshIo, FeedText) {
  EXPECT_EQ(feed_header(), "# dynmesh feed v1\n");
  MeshChange change;
  change.removed = {canonical_triangle({0, 0}, {1, 0}, {1, 1}), canonical_triangle({0, 0}, {1, 1}, {0, 1})};
  change.added = {canonical_triangle({0, 0}, {1, 0}, {0, 1}), canonical_triangle({1, 0}, {1, 1}, {0, 1})};
  std::sort(change.removed.begin(), change.removed.end());
  std::sort(change.added.begin(), change.added.end());
  EXPECT_EQ(format_feed_update(3, change),
            "update 3 removed 2 added 2\n"
            "- 0 0 1 0 1 1\n"
            "- 0 0 1 1 0 1\n"
            "+ 0 0 1 0 0 1\n"
            "+ 0 1 1 0 1 1\n");
  EXPECT_EQ(format_feed_update(1, {}), "update 1 removed 0 added 0\n");
}

TEST(MeshIo, AppendedFeedUpdatesAreTheFormattedOnes) {
  // `dynmesh mesh --feed` streams the updates through one reused string: the bytes must be
  // those of format_feed_update, after whatever the string held.
  MeshChange change;
  change.removed = {canonical_triangle({0.1, 0.2}, {1.0 / 3, 0}, {1, 1})};
  change.added = {canonical_triangle({0, 0}, {1e-300, 0}, {0, 2.5e300})};
  std::string out = feed_header();
  append_feed_update(out, 1, change);
  append_feed_update(out, 2, {});
  EXPECT_EQ(out, feed_header() + format_feed_update(1, change) + format_feed_update(2, {}));
  out.clear();
  append_feed_update(out, 7, change);
  EXPECT_EQ(out, format_feed_update(7, change));
}

TEST(MeshIo, FeedNumbersRoundTrip) {
  const double third = 1.0 / 3, tenth = 0.1;
  MeshChange change;
  change.added = {canonical_triangle({tenth, third}, {1, third}, {0.5, 2 * third})};
  const std::string text = format_feed_update(12, change);
  EXPECT_EQ(text,
            "update 12 removed 0 added 1\n"
            "+ 0.10000000000000001 0.33333333333333331 1 0.33333333333333331 0.5 0.66666666666666663\n");
  std::istringstream in(text.substr(text.find('+') + 1));
  double x = 0;
  in >> x;
  EXPECT_EQ(x, tenth);
  in >> x;
  EXPECT_EQ(x, third);
}

}  // namespace
