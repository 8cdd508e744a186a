// tet_mesh_io_test.cpp — tet_mesh_io.hpp: exact text of a small tetrahedral mesh, .node/.ele
// round trips, VTK/MSH structure, statistics and the change feed in 3D.
#include "dynmesh/tet_mesh_io.hpp"

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
#include "dynmesh/predicates.hpp"
#include "dynmesh/tet_mesh.hpp"
#include "kuhn_meshes.hpp"
#include "text_test_support.hpp"

namespace {

using namespace dynmesh;
using dynmesh_test::cube;
using dynmesh_test::kuhn;
using dynmesh_test::kuhn_cube;
using dynmesh_test::kuhn_grid;
using Kind = InputError::Kind;
using dynmesh_test::input_error_kind;
using dynmesh_test::lines_of;
using Tet = std::array<std::uint32_t, 4>;

// ---- .node / .ele ----------------------------------------------------------------------------

TEST(TetMeshIo, NodeAndEleOfTheKuhnCube) {
  const TetMesh m = kuhn_cube();
  EXPECT_EQ(format_node(m, cube(0, 0, 0, 1)),
            "8 3 0 1\n1 0 0 0 1\n2 0 0 1 1\n3 0 1 0 1\n4 0 1 1 1\n5 1 0 0 1\n6 1 0 1 1\n7 1 1 0 1\n8 1 1 1 1\n");
  // Every tetrahedron holds the diagonal 1-8; each starts at vertex 1, the smallest, and
  // continues at the smallest of the other three, in positive orientation.
  EXPECT_EQ(format_ele(m), "6 4 0\n1 1 2 6 8\n2 1 2 8 4\n3 1 3 4 8\n4 1 3 8 7\n5 1 5 7 8\n6 1 5 8 6\n");
  for (std::size_t t = 0; t < m.num_tetrahedra(); ++t) {
    const Tetrahedron tet = m.tetrahedron(t);
    EXPECT_EQ(orient3d(tet.v[0], tet.v[1], tet.v[2], tet.v[3]), 1) << t;
  }
}

TEST(TetMeshIo, NodeMarksOnlyBoundaryVertices) {
  const std::vector<std::string> lines = lines_of(format_node(kuhn_grid(2), cube(0, 0, 0, 2)));
  ASSERT_EQ(lines.size(), 28u);
  EXPECT_EQ(lines[0], "27 3 0 1");
  std::vector<std::string> interior;
  for (std::size_t i = 1; i < lines.size(); ++i)
    if (lines[i].back() == '0') interior.push_back(lines[i]);
  EXPECT_EQ(interior, std::vector<std::string>{"14 1 1 1 0"});  // the centre, 14th of 27
}

TEST(TetMeshIo, UpperBoxFacesUseTheRoundedSum) {
  // fl(0.1 + 0.7) = 0.7999999999999999 is the upper face on each axis; 0.8 would be outside.
  const Box<3> box = cube(0.1, 0.1, 0.1, 0.7);
  const double hi = 0.1 + 0.7;
  TetMesh m = make_tet_mesh(kuhn({0.1, 0.1, 0.1}, {hi, hi, hi}));
  std::vector<std::string> lines = lines_of(format_node(m, box));
  ASSERT_EQ(lines.size(), 9u);
  EXPECT_EQ(lines[8], "8 0.79999999999999993 0.79999999999999993 0.79999999999999993 1");
  m.vertices.back() = {0.8, 0.45, 0.8};  // not a mesh any more, but a marker question
  lines = lines_of(format_node(m, box));
  EXPECT_EQ(lines[8], "8 0.80000000000000004 0.45000000000000001 0.80000000000000004 0");
}

TEST(TetMeshIo, NodeEleRoundTripIsBitExact) {
  // Awkward values: subnormal, huge, thirds and tenths, negative zero's neighbours.
  TetMesh m;
  m.vertices = {{-2.5e-17, 123456789.123, 0.1},
                {5e-324, 1e300, -1e-300},
                {0.1, 1.0 / 3, 2.0 / 3},
                {0.30000000000000004, -7e-310, 1e15 + 1},
                {1, 2, 3}};
  m.tetrahedra = {{0, 1, 2, 3}, {0, 4, 3, 2}};
  const TetMesh back = read_tet_node_ele(format_node(m, cube(0, 0, 0, 1)), format_ele(m));
  ASSERT_EQ(back.vertices.size(), m.vertices.size());
  for (std::size_t i = 0; i < m.vertices.size(); ++i)
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(back.vertices[i][a]), std::bit_cast<std::uint64_t>(m.vertices[i][a]));
  EXPECT_EQ(back.tetrahedra, m.tetrahedra);

  const TetMesh g = kuhn_grid(3);
  EXPECT_EQ(read_tet_node_ele(format_node(g, cube(0, 0, 0, 3)), format_ele(g)), g);
}

TEST(TetMeshIo, ReaderAcceptsTetGenConventions) {
  // Numbering from 0, comments, attributes and markers, blank lines.
  const std::string node = "# a comment\n4 3 1 1\n\n0 0 0 0 7 1\n1 1 0 0 7 1 # trailing\n2 0 1 0 7 1\n3 0 0 1 7 0\n";
  const std::string ele = "1 4 1\n0  0 1 2 3 5.5\n";
  const TetMesh m = read_tet_node_ele(node, ele);
  EXPECT_EQ(m.vertices, (std::vector<Point<3>>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}));
  EXPECT_EQ(m.tetrahedra, (std::vector<Tet>{{0, 1, 2, 3}}));
}

TEST(TetMeshIo, ReaderErrorsNameFileAndKind) {
  const std::string node = "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
  const std::string ele = "1 4 0\n1 1 2 3 4\n";
  EXPECT_EQ(input_error_kind([&] { read_tet_node_ele("4 2 0 0\n1 0 0\n2 1 0\n3 0 1\n4 1 1\n", ele); }),
            Kind::Malformed);  // a 2D file
  EXPECT_EQ(input_error_kind([&] { read_tet_node_ele(node, "1 10 0\n1 1 2 3 4 1 1 1 1 1 1\n"); }),
            Kind::Malformed);  // 10-node tetrahedra
  EXPECT_EQ(input_error_kind([&] { read_tet_node_ele("4 3 0 0\n1 0 0 0\n2 1 0\n3 0 1 0\n4 0 0 1\n", ele); }),
            Kind::Count);  // a coordinate short
  EXPECT_EQ(input_error_kind([&] { read_tet_node_ele("4 3 0 0\n1 0 0 0\n2 1 0 nan\n3 0 1 0\n4 0 0 1\n", ele); }),
            Kind::NotFinite);
  EXPECT_EQ(input_error_kind([&] { read_tet_node_ele(node, "1 4 0\n1 1 2 3\n"); }), Kind::Count);
  EXPECT_EQ(input_error_kind([&] { read_tet_node_ele(node, "1 4 0\n1 1 2 3 5\n"); }), Kind::Malformed);
  EXPECT_EQ(input_error_kind([&] { read_tet_node_ele(node, "2 4 0\n1 1 2 3 4\n"); }), Kind::Count);
  try {
    read_tet_node_ele(node, "1 4 0\n1 1 2 3 0\n");
    ADD_FAILURE() << "vertex 0 of a 1-based file accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "ele");
    EXPECT_EQ(e.line(), 2u);
  }
  try {
    read_tet_node_ele(node, "1 4 0\n1 1 2 3\n");
    ADD_FAILURE() << "a short tetrahedron line accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.text(), "a tetrahedron line needs a number and four vertices");
  }
}

// ---- VTK and Gmsh ----------------------------------------------------------------------------

TEST(TetMeshIo, VtkOfTheKuhnCube) {
  EXPECT_EQ(format_vtk(kuhn_cube()),
            "# vtk DataFile Version 3.0\ndynmesh mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n"
            "POINTS 8 double\n0 0 0\n0 0 1\n0 1 0\n0 1 1\n1 0 0\n1 0 1\n1 1 0\n1 1 1\n"
            "CELLS 6 30\n4 0 1 5 7\n4 0 1 7 3\n4 0 2 3 7\n4 0 2 7 6\n4 0 4 6 7\n4 0 4 7 5\n"
            "CELL_TYPES 6\n10\n10\n10\n10\n10\n10\n");
}

TEST(TetMeshIo, VtkStructureCounts) {
  const TetMesh m = kuhn_grid(3);
  const std::vector<std::string> lines = lines_of(format_vtk(m));
  const std::size_t nv = m.num_vertices(), nt = m.num_tetrahedra();
  ASSERT_EQ(lines.size(), 4 + 1 + nv + 1 + nt + 1 + nt);
  EXPECT_EQ(lines[4], "POINTS " + std::to_string(nv) + " double");
  EXPECT_EQ(lines[5 + nv], "CELLS " + std::to_string(nt) + " " + std::to_string(5 * nt));
  EXPECT_EQ(lines[6 + nv + nt], "CELL_TYPES " + std::to_string(nt));
  EXPECT_EQ(std::count(lines.begin(), lines.end(), "10"), static_cast<std::ptrdiff_t>(nt));
}

TEST(TetMeshIo, MshOfTheKuhnCube) {
  EXPECT_EQ(format_msh(kuhn_cube()),
            "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
            "$Nodes\n8\n1 0 0 0\n2 0 0 1\n3 0 1 0\n4 0 1 1\n5 1 0 0\n6 1 0 1\n7 1 1 0\n8 1 1 1\n$EndNodes\n"
            "$Elements\n6\n1 4 2 1 1 1 2 6 8\n2 4 2 1 1 1 2 8 4\n3 4 2 1 1 1 3 4 8\n4 4 2 1 1 1 3 8 7\n"
            "5 4 2 1 1 1 5 7 8\n6 4 2 1 1 1 5 8 6\n$EndElements\n");
}

TEST(TetMeshIo, MshStructureCounts) {
  const TetMesh m = kuhn_grid(3);
  const std::vector<std::string> lines = lines_of(format_msh(m));
  const std::size_t nv = m.num_vertices(), nt = m.num_tetrahedra();
  ASSERT_EQ(lines.size(), 3 + 2 + nv + 1 + 2 + nt + 1);
  EXPECT_EQ(lines[4], std::to_string(nv));
  EXPECT_EQ(lines[5 + nv], "$EndNodes");
  EXPECT_EQ(lines[7 + nv], std::to_string(nt));
  EXPECT_EQ(lines.back(), "$EndElements");
  for (std::size_t t = 0; t < nt; ++t) EXPECT_EQ(lines[8 + nv + t].rfind(std::to_string(t + 1) + " 4 2 1 1 ", 0), 0u);
}

// ---- statistics ------------------------------------------------------------------------------

TEST(TetMeshIo, StatsOfTheGrid) {
  const TetMeshStats s = tet_mesh_stats(kuhn_grid(2));
  EXPECT_EQ(s.vertices, 27u);
  EXPECT_EQ(s.tetrahedra, 48u);
  EXPECT_NEAR(s.min_dihedral_deg, 45, 1e-12);
  EXPECT_NEAR(s.max_dihedral_deg, 90, 1e-12);
  EXPECT_NEAR(s.max_radius_edge_ratio, std::sqrt(3.0) / 2, 1e-14);
  EXPECT_EQ(s.shortest_edge, 1);
  EXPECT_EQ(s.longest_edge, std::sqrt(3.0));
  EXPECT_EQ(s.smallest_volume, 1.0 / 6);
  EXPECT_EQ(s.largest_volume, 1.0 / 6);
  std::array<std::size_t, 18> histogram{};
  histogram[4] = 2 * 48;  // 45 degrees (at the path's first and last edge)
  histogram[6] = 48;      // 60
  histogram[9] = 3 * 48;  // 90: in [90, 100)
  EXPECT_EQ(s.dihedral_histogram, histogram);
}

/// The statistics of the grid scaled by a power of two are the grid's, scaled: volumes and
/// edges neither overflow nor underflow before they must.
TEST(TetMeshIo, StatsAtExtremeScales) {
  const TetMesh unit = kuhn_grid(2);
  const TetMeshStats base = tet_mesh_stats(unit);
  for (const int e : {300, 960, -300, -960}) {
    SCOPED_TRACE("scale 2^" + std::to_string(e));
    TetMesh m = unit;
    for (Point<3>& v : m.vertices)
      for (double& x : v) x = std::ldexp(x, e);
    const TetMeshStats s = tet_mesh_stats(m);
    EXPECT_EQ(s.shortest_edge, std::ldexp(base.shortest_edge, e));
    EXPECT_EQ(s.longest_edge, std::ldexp(base.longest_edge, e));
    // A volume of 2^2877 is beyond the doubles, and one of 2^-2883 below them.
    const double volume = std::abs(e) < 340 ? std::ldexp(base.largest_volume, 3 * e) : (e > 0 ? HUGE_VAL : 0.0);
    EXPECT_EQ(s.smallest_volume, volume);
    EXPECT_EQ(s.largest_volume, volume);
    EXPECT_EQ(s.min_dihedral_deg, base.min_dihedral_deg);
    EXPECT_EQ(s.max_dihedral_deg, base.max_dihedral_deg);
    EXPECT_EQ(s.max_radius_edge_ratio, base.max_radius_edge_ratio);
    EXPECT_EQ(s.dihedral_histogram, base.dihedral_histogram);
  }
}

TEST(TetMeshIo, StatsReport) {
  const std::string report = format_stats(tet_mesh_stats(kuhn_grid(2)), 4);
  EXPECT_EQ(report,
            "Mesh quality statistics:\n"
            "\n"
            "  Vertices: 27    Tetrahedra: 48\n"
            "  Input points: 4    Tetrahedra per input point: 12\n"
            "\n"
            "  Smallest volume:   0.166667      |  Largest volume:    0.166667\n"
            "  Shortest edge:     1             |  Longest edge:      1.73205\n"
            "  Smallest dihedral: 45            |  Largest dihedral:  90\n"
            "  Largest radius-edge ratio: 0.866025\n"
            "\n"
            "  Dihedral angle histogram:\n"
            "        0 -  10 degrees:         0    |     90 - 100 degrees:       144\n"
            "       10 -  20 degrees:         0    |    100 - 110 degrees:         0\n"
            "       20 -  30 degrees:         0    |    110 - 120 degrees:         0\n"
            "       30 -  40 degrees:         0    |    120 - 130 degrees:         0\n"
            "       40 -  50 degrees:        96    |    130 - 140 degrees:         0\n"
            "       50 -  60 degrees:         0    |    140 - 150 degrees:         0\n"
            "       60 -  70 degrees:        48    |    150 - 160 degrees:         0\n"
            "       70 -  80 degrees:         0    |    160 - 170 degrees:         0\n"
            "       80 -  90 degrees:         0    |    170 - 180 degrees:         0\n")
      << report;
  EXPECT_NE(format_stats(tet_mesh_stats(kuhn_grid(2)), 0).find("  Input points: 0\n"), std::string::npos);
}

TEST(TetMeshIo, StatsOfAnEmptyMesh) {
  const TetMeshStats s = tet_mesh_stats(TetMesh{});
  EXPECT_EQ(s.tetrahedra, 0u);
  EXPECT_EQ(s.min_dihedral_deg, 0);
  EXPECT_EQ(s.largest_volume, 0);
  EXPECT_EQ(s.max_radius_edge_ratio, 0);
  EXPECT_FALSE(format_stats(s, 0).empty());
}

// ---- the change feed -------------------------------------------------------------------------

TEST(TetMeshIo, FeedText) {
  EXPECT_EQ(feed_header(), "# dynmesh feed v1\n");
  // The unit tetrahedron given from another corner: canonical_tetrahedron puts the smallest
  // corner first, then the smallest of the rest, keeping the orientation.
  const Tetrahedron unit = canonical_tetrahedron({0, 1, 0}, {0, 0, 1}, {0, 0, 0}, {1, 0, 0});
  EXPECT_EQ(unit.v, (std::array<Point<3>, 4>{{{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}}}));
  EXPECT_EQ(orient3d(unit.v[0], unit.v[1], unit.v[2], unit.v[3]), 1);
  TetMeshChange change;
  change.removed = {unit};
  change.added = kuhn({0, 0, 0}, {1, 1, 1});
  change.added.resize(2);
  std::sort(change.added.begin(), change.added.end());
  EXPECT_EQ(format_feed_update(3, change),
            "update 3 removed 1 added 2\n"
            "- 0 0 0 0 0 1 1 0 0 0 1 0\n"
            "+ 0 0 0 0 1 0 0 1 1 1 1 1\n"
            "+ 0 0 0 1 0 0 1 1 0 1 1 1\n");
  EXPECT_EQ(format_feed_update(1, TetMeshChange{}), "update 1 removed 0 added 0\n");
}

TEST(TetMeshIo, AppendedFeedUpdatesAreTheFormattedOnes) {
  TetMeshChange change;
  change.removed = {canonical_tetrahedron({0, 1, 0}, {0, 0, 1}, {0, 0, 0}, {1, 0, 0})};
  change.added = kuhn({1e-300, 0.2, 0.3}, {1.0 / 3, 1, 2.5e300});
  std::sort(change.added.begin(), change.added.end());
  std::string out = feed_header();
  append_feed_update(out, 4, change);
  append_feed_update(out, 5, TetMeshChange{});
  EXPECT_EQ(out, feed_header() + format_feed_update(4, change) + format_feed_update(5, TetMeshChange{}));
}

TEST(TetMeshIo, FeedLinesHoldTwelveExactNumbers) {
  const double third = 1.0 / 3, tenth = 0.1;
  TetMeshChange change;
  change.added = {canonical_tetrahedron({tenth, third, 0}, {1, third, 0}, {0.5, 2 * third, 0}, {0.5, 0.5, tenth})};
  const std::string text = format_feed_update(12, change);
  const std::vector<std::string> lines = lines_of(text);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "update 12 removed 0 added 1");
  EXPECT_EQ(lines[1],
            "+ 0.10000000000000001 0.33333333333333331 0 0.5 0.5 0.10000000000000001 "
            "1 0.33333333333333331 0 0.5 0.66666666666666663 0");
  std::istringstream in(lines[1].substr(1));
  std::vector<double> numbers;
  for (double x = 0; in >> x;) numbers.push_back(x);
  ASSERT_EQ(numbers.size(), 12u);
  for (std::size_t c = 0; c < 4; ++c)
    for (std::size_t a = 0; a < 3; ++a) EXPECT_EQ(numbers[3 * c + a], change.added[0].v[c][a]);
}

}  // namespace
