// io_test.cpp — point files, edit scripts, `.cells`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/io.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace {

using namespace dynmesh;
using Kind = InputError::Kind;

template <std::size_t d>
PointFile<d> node(const std::string& text, const std::string& name = "in.node") {
  std::istringstream in(text);
  return read_node<d>(in, name);
}

template <std::size_t d>
PointFile<d> plain(const std::string& text, const std::string& name = "in.xyz") {
  std::istringstream in(text);
  return read_plain<d>(in, name);
}

template <std::size_t d>
EditScript<d> edits(const std::string& text, const std::string& name = "edits.txt") {
  std::istringstream in(text);
  return read_edits<d>(in, name);
}

/// Runs f, expects an InputError of `kind` naming `file` and `line` (0: no line) in both its
/// fields and its message.
template <class F>
void expect_error(F&& f, Kind kind, const std::string& file, std::size_t line, const std::string& fragment = {}) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one at " << file << ":" << line;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.kind(), kind) << what;
    EXPECT_EQ(e.file(), file) << what;
    EXPECT_EQ(e.line(), line) << what;
    const std::string prefix = line ? file + ":" + std::to_string(line) + ": " : file + ": ";
    EXPECT_EQ(what.rfind(prefix, 0), 0u) << what;
    if (!fragment.empty()) {
      EXPECT_NE(what.find(fragment), std::string::npos) << what;
    }
  }
}

// --- .node ---------------------------------------------------------------------------------

TEST(ReadNode, TriangleFileNumberedFromOne) {
  const auto f = node<2>(
      "# a comment line\n"
      "4 2 1 1   # header: 4 vertices, 2D, one attribute, markers\n"
      "\n"
      "1 0.0 0.0 7.5 1\n"
      "2 1.0 0.0 7.5 1 # trailing comment\n"
      "   # an indented comment\n"
      "3 1.0 1.0 7.5 0\n"
      "4 -2.5e-1 +1e0 3 1\n");
  ASSERT_EQ(f.points.size(), 4u);
  EXPECT_EQ(f.points[0], (Point<2>{0.0, 0.0}));
  EXPECT_EQ(f.points[3], (Point<2>{-0.25, 1.0}));
  EXPECT_EQ(f.lines, (std::vector<std::size_t>{4, 5, 7, 8}));
  EXPECT_EQ(f.name, "in.node");
}

TEST(ReadNode, TetGenFileNumberedFromZeroWithCrLf) {
  const auto f = node<3>("3 3 0 0\r\n0 1 2 3\r\n1 4 5 6\r\n2 0.5 0.25 0.125\r\n");
  ASSERT_EQ(f.points.size(), 3u);
  EXPECT_EQ(f.points[2], (Point<3>{0.5, 0.25, 0.125}));
}

TEST(ReadNode, ShortHeaderAndExtraFields) {
  // Triangle allows trailing header fields to be omitted; fields beyond the announced
  // attributes and marker are ignored.
  const auto f = node<2>("2\n1 0 0 whatever\n2 1 1\n");
  ASSERT_EQ(f.points.size(), 2u);
  const auto g = node<2>("0 2 0 0\n");
  EXPECT_TRUE(g.points.empty());
}

TEST(ReadNode, Errors) {
  const std::string n = "bad.node";
  expect_error([&] { node<2>("", n); }, Kind::Malformed, n, 0, "header");
  expect_error([&] { node<2>("# only a comment\n", n); }, Kind::Malformed, n, 1, "header");
  expect_error([&] { node<2>("two 2 0 0\n", n); }, Kind::Malformed, n, 1, "'two'");
  expect_error([&] { node<2>("2 4 0 0\n", n); }, Kind::Malformed, n, 1, "dimension");
  expect_error([&] { node<2>("1 3 0 0\n1 0 0 0\n", n); }, Kind::Malformed, n, 1, "dimension 3");
  expect_error([&] { node<2>("1 2 0 2\n1 0 0\n", n); }, Kind::Malformed, n, 1, "markers");
  expect_error([&] { node<2>("1 2 0 0 9\n", n); }, Kind::Malformed, n, 1);
  expect_error([&] { node<2>("-1 2 0 0\n", n); }, Kind::Malformed, n, 1);
  // A malformed number.
  expect_error([&] { node<2>("2 2 0 0\n1 0 0\n\n2 0.5x 1\n", n); }, Kind::Malformed, n, 4, "'0.5x'");
  expect_error([&] { node<2>("1 2 0 0\n1 0x1p3 1\n", n); }, Kind::Malformed, n, 2, "'0x1p3'");
  expect_error([&] { node<2>("1 2 0 0\n1 ++1 1\n", n); }, Kind::Malformed, n, 2);
  expect_error([&] { node<2>("1 2 0 0\n1 +-1 1\n", n); }, Kind::Malformed, n, 2);
  expect_error([&] { node<2>("1 2 0 0\n1 1e 1\n", n); }, Kind::Malformed, n, 2);
  expect_error([&] { node<2>("1 2 1 0\n1 0 0 attr\n", n); }, Kind::Malformed, n, 2, "'attr'");
  expect_error([&] { node<2>("1 2 0 1\n1 0 0 1.5\n", n); }, Kind::Malformed, n, 2, "'1.5'");
  // NaN and infinity, including a decimal overflow.
  expect_error([&] { node<2>("2 2 0 0\n1 0 0\n2 nan 1\n", n); }, Kind::NotFinite, n, 3, "'nan'");
  expect_error([&] { node<2>("1 2 0 0\n1 0 -inf\n", n); }, Kind::NotFinite, n, 2, "'-inf'");
  expect_error([&] { node<2>("1 2 0 0\n1 0 Infinity\n", n); }, Kind::NotFinite, n, 2);
  expect_error([&] { node<2>("1 2 0 0\n1 1e999 0\n", n); }, Kind::NotFinite, n, 2, "'1e999'");
  expect_error([&] { node<2>("1 2 0 0\n1 -123.4e307 0\n", n); }, Kind::NotFinite, n, 2);
  // Wrong counts: too few fields, more or fewer vertices than announced.
  expect_error([&] { node<2>("2 2 0 0\n1 0 0\n2 5\n", n); }, Kind::Count, n, 3, "field");
  expect_error([&] { node<3>("1 3 0 0\n1 0 0\n", n); }, Kind::Count, n, 2);
  expect_error([&] { node<2>("1 2 0 0\n1 0 0\n2 1 1\n", n); }, Kind::Count, n, 3, "more vertices");
  expect_error([&] { node<2>("# c\n3 2 0 0\n1 0 0\n2 1 1\n", n); }, Kind::Count, n, 2, "announces 3");
  // Numbering.
  expect_error([&] { node<2>("2 2 0 0\n2 0 0\n3 1 1\n", n); }, Kind::Malformed, n, 2, "start at 0 or 1");
  expect_error([&] { node<2>("3 2 0 0\n0 0 0\n1 1 1\n3 2 2\n", n); }, Kind::Malformed, n, 4, "out of sequence");
  expect_error([&] { node<2>("2 2 0 0\n1 0 0\n1.0 1 1\n", n); }, Kind::Malformed, n, 3);
}

TEST(ReadNode, ByteOrderMarkIsSkippedButCommasAreNotSeparators) {
  const auto f = node<2>("\xEF\xBB\xBF# exported on Windows\r\n2 2 0 0\r\n1 0 0\r\n2 1 1\r\n");
  ASSERT_EQ(f.points.size(), 2u);
  EXPECT_EQ(f.points[1], (Point<2>{1, 1}));
  const auto g = node<2>("\xEF\xBB\xBF" "1 2 0 0\n1 0.5 0.25\n");
  EXPECT_EQ(g.points[0], (Point<2>{0.5, 0.25}));
  // Triangle's format has whitespace-separated fields only.
  expect_error([] { node<2>("1 2 0 0\n1 0.5,0.25\n", "c.node"); }, Kind::Count, "c.node", 2);
  // A byte order mark anywhere but at the start is not skipped.
  expect_error([] { node<2>("1 2 0 0\n\xEF\xBB\xBF" "1 0 0\n", "m.node"); }, Kind::Malformed, "m.node", 2);
}

TEST(ReadNode, UnderflowIsTheRoundedZero) {
  const auto f = node<2>("1 2 0 0\n1 1e-999 -1e-400\n");
  EXPECT_EQ(f.points[0][0], 0.0);
  EXPECT_EQ(f.points[0][1], 0.0);
  EXPECT_TRUE(std::signbit(f.points[0][1]));
  const auto g = node<2>("1 2 0 0\n1 4.9e-324 0.000001e-320\n");
  EXPECT_EQ(g.points[0][0], std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(g.points[0][1], 0.0);
}

// --- plain text ------------------------------------------------------------------------------

TEST(ReadPlain, FirstDimNumbersAndIgnoredColumns) {
  const auto f = plain<3>("1 2 3 0.1 0.2 0.3 red\n\n# comment\n  4\t5 6\n7 8 9 # note\n");
  ASSERT_EQ(f.points.size(), 3u);
  EXPECT_EQ(f.points[1], (Point<3>{4, 5, 6}));
  EXPECT_EQ(f.lines, (std::vector<std::size_t>{1, 4, 5}));
  const auto g = plain<2>("1 2 3\n4 5 6\n");
  EXPECT_EQ(g.points[1], (Point<2>{4, 5}));
}

TEST(ReadPlain, ByteOrderMark) {
  const auto f = plain<2>("\xEF\xBB\xBF" "0.5 0.25\n1 2\n");
  ASSERT_EQ(f.points.size(), 2u);
  EXPECT_EQ(f.points[0], (Point<2>{0.5, 0.25}));
  const auto g = plain<2>("\xEF\xBB\xBF# header comment\n3 4\n");
  EXPECT_EQ(g.lines, (std::vector<std::size_t>{2}));
}

TEST(ReadPlain, CommasAndSemicolonsSeparateFields) {
  const auto f = plain<2>("0.5,0.25\n0.5; 0.25\n1 , 2\n-3;+4;extra,columns\n5,6 # comment, with commas\n7;8;\t9\n");
  ASSERT_EQ(f.points.size(), 6u);
  EXPECT_EQ(f.points[0], (Point<2>{0.5, 0.25}));
  EXPECT_EQ(f.points[1], (Point<2>{0.5, 0.25}));
  EXPECT_EQ(f.points[2], (Point<2>{1, 2}));
  EXPECT_EQ(f.points[3], (Point<2>{-3, 4}));
  EXPECT_EQ(f.points[4], (Point<2>{5, 6}));
  EXPECT_EQ(f.points[5], (Point<2>{7, 8}));
  const auto g = plain<3>("1,2,3,0.1,0.2,0.3\n4;5;6\n");
  EXPECT_EQ(g.points[0], (Point<3>{1, 2, 3}));
  EXPECT_EQ(g.points[1], (Point<3>{4, 5, 6}));
  // Whitespace between the coordinates and commas among the ignored columns is fine.
  EXPECT_EQ(plain<2>("1 2 r,g,b\n").points[0], (Point<2>{1, 2}));
}

TEST(ReadPlain, CommaErrors) {
  const std::string n = "c.csv";
  // A decimal comma: the separators up to the last coordinate mix ',' and whitespace.
  expect_error([&] { plain<2>("1 2,5\n", n); }, Kind::Malformed, n, 1, "'2,5'");
  expect_error([&] { plain<2>("1,5 2,5\n", n); }, Kind::Malformed, n, 1, "decimal comma");
  expect_error([&] { plain<3>("1,2 3\n", n); }, Kind::Malformed, n, 1, "'1,2'");
  // Empty fields.
  expect_error([&] { plain<2>("0.5,,0.25\n", n); }, Kind::Malformed, n, 1, "empty field");
  expect_error([&] { plain<2>(",0.5,0.25\n", n); }, Kind::Malformed, n, 1, "empty field");
  expect_error([&] { plain<2>("1 2\n0.5,0.25,\n", n); }, Kind::Malformed, n, 2, "empty field");
  // The number rules are unchanged.
  expect_error([&] { plain<2>("1,nan\n", n); }, Kind::NotFinite, n, 1, "'nan'");
  expect_error([&] { plain<2>("1;-inf\n", n); }, Kind::NotFinite, n, 1);
  expect_error([&] { plain<2>("1,1e999\n", n); }, Kind::NotFinite, n, 1);
  expect_error([&] { plain<2>("1,x\n", n); }, Kind::Malformed, n, 1, "'x'");
  expect_error([&] { plain<2>("0.5\n", n); }, Kind::Count, n, 1, "expected 2 coordinates, found 1");
  expect_error([&] { plain<3>("1,2\n", n); }, Kind::Count, n, 1);
}

TEST(ReadPlain, Errors) {
  const std::string n = "pts.xyz";
  expect_error([&] { plain<2>("1 2\n3\n", n); }, Kind::Count, n, 2, "expected 2 coordinates, found 1");
  expect_error([&] { plain<3>("1 2 3\n\n1 2\n", n); }, Kind::Count, n, 3);
  expect_error([&] { plain<2>("1 2\n1,5 2\n", n); }, Kind::Malformed, n, 2, "'1,5'");
  expect_error([&] { plain<2>("1 2\nx y\n", n); }, Kind::Malformed, n, 2);  // a header only comes first
  expect_error([&] { plain<2>("x 1\n", n); }, Kind::Malformed, n, 1);      // a number: not a header
  expect_error([&] { plain<2>("1 2\n3 4\nNaN 1\n", n); }, Kind::NotFinite, n, 3);
  expect_error([&] { plain<2>("1 inf\n", n); }, Kind::NotFinite, n, 1);
}

TEST(ReadPlain, AFirstLineWithoutNumbersIsAHeader) {
  const auto f = plain<2>("# exported\n\nx, y\n0.5, 0.25\n1, 2\n", "h.csv");
  EXPECT_EQ(f.header_line, 3u);
  EXPECT_EQ(f.header, "x, y");
  EXPECT_EQ(f.points, (std::vector<Point<2>>{{0.5, 0.25}, {1, 2}}));
  EXPECT_EQ(f.lines, (std::vector<std::size_t>{4, 5}));
  EXPECT_EQ(plain<2>("1 2\n").header_line, 0u);
  EXPECT_EQ(plain<2>("easting\tnorthing\x01\n1 2\n").header, "easting\\x09northing\\x01");
}

TEST(ReadPlain, TriangleNumberedRowsAreRefusedByName) {
  const std::string n = "rows.txt";
  // A .node under another name: a header of whole numbers, then numbered vertices.
  expect_error([&] { plain<2>("3 2 0 0\n1 0 0\n2 1 0\n3 0.5 1\n", n); }, Kind::Unsupported, n, 1,
               "Triangle's .node format");
  expect_error([&] { plain<2>("# c\n3 2\n0 0 0\n1 1 0\n2 0.5 1\n", n); }, Kind::Unsupported, n, 2, ".node");
  // Triangles: every field a vertex number.
  expect_error([&] { plain<2>("2 3 0\n1 1 2 3\n2 2 3 4\n", n); }, Kind::Unsupported, n, 1,
               "Triangle's .ele format");
  // A .poly: its segment list fails to read as points, and the file is named for what it is.
  expect_error([&] { plain<2>("3 2 0 0\n1 0 0\n2 1 0\n3 0.5 1\n3 0\n1 1 2\n", n); }, Kind::Unsupported, n, 1,
               ".node format");
  // Plain points that merely start with whole numbers stay points; one numbered row is not
  // enough to tell (here a decimal comma is the error).
  expect_error([&] { plain<2>("1 2\n1,5 2\n", n); }, Kind::Malformed, n, 2, "'1,5'");
  EXPECT_EQ(plain<2>("3 2\n1 0\n2 0\n").points.size(), 3u);                // two fields per row
  EXPECT_EQ(plain<2>("3 2 0 0\n5 0 0\n6 1 0\n7 0.5 1\n").points.size(), 4u);  // not numbered from 0/1
  EXPECT_EQ(plain<2>("3 5 0 0\n1 0 0\n2 1 0\n3 0.5 1\n").points.size(), 4u);  // no dimension 5
}

TEST(ReadPoly, VerticesWithoutSegmentsOrHoles) {
  std::istringstream in("# p\n3 2 1 1\n1 0 0 7 1\n2 1 0 7 1\n3 0.5 1 7 0\n0 0\n0\n");
  const auto f = read_poly<2>(in, "p.poly");
  EXPECT_EQ(f.points, (std::vector<Point<2>>{{0, 0}, {1, 0}, {0.5, 1}}));
  EXPECT_EQ(f.lines, (std::vector<std::size_t>{3, 4, 5}));
  std::istringstream regions("3 2\n0 0 0\n1 1 0\n2 0.5 1\n0\n0\n0\n");
  EXPECT_EQ(read_poly<2>(regions, "r.poly").points.size(), 3u);
}

TEST(ReadPoly, SegmentsHolesAndMissingListsAreRefused) {
  const std::string n = "a.poly";
  auto poly = [&](const std::string& text) {
    std::istringstream in(text);
    return read_poly<2>(in, n);
  };
  const std::string vertices = "3 2 0 0\n1 0 0\n2 1 0\n3 0.5 1\n";
  expect_error([&] { poly(vertices + "3 0\n1 1 2\n2 2 3\n3 3 1\n0\n"); }, Kind::Unsupported, n, 5,
               "3 segments: segments and holes are not supported yet");
  expect_error([&] { poly(vertices + "0 0\n1\n1 0.5 0.5\n"); }, Kind::Unsupported, n, 6, "1 holes");
  expect_error([&] { poly(vertices + "0 0\n0\n1\n1 0.5 0.5 1 0\n"); }, Kind::Unsupported, n, 7, "regional");
  expect_error([&] { poly(vertices); }, Kind::Malformed, n, 4, "ends before its number of segments");
  expect_error([&] { poly(vertices + "0\n"); }, Kind::Malformed, n, 5, "holes");
  expect_error([&] { poly("0 2 0 1\n0 0\n0\n"); }, Kind::Unsupported, n, 1, "lists no vertices");
  expect_error([&] { poly("3 3 0 0\n"); }, Kind::Malformed, n, 1, "dimension 3");
}

TEST(ReadPoints, EleIsRefusedAndFormatsGoByName) {
  EXPECT_EQ(format_for_path("x.POLY"), PointFormat::Poly);
  EXPECT_EQ(format_for_path("x.ele"), PointFormat::Ele);
  EXPECT_EQ(format_for_path("x.elements"), PointFormat::Plain);
  std::istringstream ele("1 3 0\n1 1 2 3\n");
  expect_error([&] { (void)read_points<2>(ele, "m.ele"); }, Kind::Unsupported, "m.ele", 0, "holds triangles");
  std::istringstream poly("1 2\n1 0.5 0.5\n0 0\n0\n");
  EXPECT_EQ(read_points<2>(poly, "m.poly").points.size(), 1u);
}

TEST(EscapeControlBytes, EveryControlByteAndOnlyThose) {
  EXPECT_EQ(escape_control_bytes("a\tb\r\x1b[31m\x7f\xc3\xa9"), "a\\x09b\\x0d\\x1b[31m\\x7f\xc3\xa9");
  std::istringstream junk("1 2\n\x01\x02 3\n");
  expect_error([&] { (void)read_plain<2>(junk, "j.txt"); }, Kind::Malformed, "j.txt", 2, "'\\x01\\x02'");
}

// --- files, boxes and duplicates -------------------------------------------------------------

// A fresh directory of its own per test (mkdtemp): not a name derived from the test and the
// clock (gtest's random_seed() is the time in ms when no seed is given), which two processes
// running the same test at once, such as two build trees' ctest runs on one machine, could
// share, one removing the other's files.
class TempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::string name = (std::filesystem::temp_directory_path() / ("dynmesh_io_test_" + test + "_XXXXXX")).string();
    ASSERT_NE(::mkdtemp(name.data()), nullptr) << "mkdtemp " << name << ": " << std::strerror(errno);
    dir_ = name;
  }
  void TearDown() override {
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }
  std::string write(const std::string& name, const std::string& text) {
    const auto p = (dir_ / name).string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  std::filesystem::path dir_;
};

TEST_F(TempDir, ReadPointsFileChoosesTheFormatByExtension) {
  const auto a = write("a.node", "2 2 0 0\n1 0 0\n2 1 1\n");
  const auto b = write("b.NODE", "1 2\n");
  const auto c = write("c.xyz", "2 2 0 0\n");
  EXPECT_EQ(read_points_file<2>(a).points.size(), 2u);
  EXPECT_EQ(format_for_path(b), PointFormat::Node);
  EXPECT_EQ(read_points_file<2>(c).points.size(), 1u);  // plain: "2 2 0 0" is the point (2, 2)
  EXPECT_EQ(read_points_file<2>(c).points[0], (Point<2>{2, 2}));
  // A .node file read as plain text is refused: its vertex numbers would become coordinates.
  expect_error([&] { read_points_file<2>(a, PointFormat::Plain); }, Kind::Unsupported, a, 1, ".node format");
  EXPECT_EQ(node_file_dimension(a), 2);
  EXPECT_EQ(node_file_dimension(write("d.node", "5\n")), 0);
  expect_error([&] { read_points_file<2>(write("e.node", "1 2 0 0\n1 0 nan\n")); }, Kind::NotFinite,
               (dir_ / "e.node").string(), 2);
  const std::string missing = (dir_ / "missing.node").string();
  expect_error([&] { read_points_file<2>(missing); }, Kind::Io, missing, 0, "cannot open");
  expect_error([&] { read_points_file<2>(missing); }, Kind::Io, missing, 0, "No such file or directory");
}

TEST_F(TempDir, ADirectoryIsNamedAsSuch) {
  const std::string dir = dir_.string();
  expect_error([&] { read_points_file<2>(dir); }, Kind::Io, dir, 0, "is a directory");
  expect_error([&] { read_edits_file<2>(dir); }, Kind::Io, dir, 0, "is a directory");
  expect_error([&] { node_file_dimension(dir); }, Kind::Io, dir, 0, "is a directory");
}

TEST(LocatePoints, EqualPositionsAreDuplicatesOrASpreadBeyondTheResolution) {
  // 0 and 1e-20 differ as doubles but have the same located q in the box o = −1, L = 3
  // (x − o rounds to 1 for both): not a duplicate but a spread L/s = 3e20 the grid cannot
  // resolve.
  const auto f = plain<2>("0 0\n1 1\n# c\n0.5 0.5\n1e-20 0\n", "dup.txt");
  const Box<2> box = derive_box<2>(f.points);
  try {
    (void)locate_points(f, box);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), Kind::Resolution);
    EXPECT_EQ(e.file(), "dup.txt");
    EXPECT_EQ(e.line(), 5u);
    const std::string what = e.what();
    EXPECT_NE(what.find("line 1"), std::string::npos) << what;
    EXPECT_NE(what.find("spread L/s = 3e+20 (log2 68.0)"), std::string::npos) << what;
    EXPECT_NE(what.find("exceeds the resolution"), std::string::npos) << what;
    EXPECT_EQ(e.point_indices(), (std::vector<std::size_t>{0, 3}));
  }
  // Exact repeats too; the first repeat in file order is reported.
  const auto g = plain<2>("0 0\n5 5\n1 1\n1 1\n5 5\n", "dup2.txt");
  expect_error([&] { (void)locate_points(g, derive_box<2>(g.points)); }, Kind::Duplicate, "dup2.txt", 4);
  const auto ok = plain<2>("0 0\n1 1\n");
  EXPECT_EQ(locate_points(ok, derive_box<2>(ok.points)).size(), 2u);
}

TEST(LocatePoints, ManyCopiesOfOnePointAreFoundInOneSortedPass) {
  // 200,000 copies: the first repeat is reported, in O(n log n) (a walk back over the equal
  // positions for each copy took minutes at 3 million).
  PointFile<2> f;
  f.name = "copies.txt";
  f.points.assign(200000, Point<2>{0.5, 0.5});
  f.points.push_back({0.25, 0.75});
  for (std::size_t i = 0; i < f.points.size(); ++i) f.lines.push_back(i + 1);
  expect_error([&] { (void)locate_points(f, derive_box<2>(f.points)); }, Kind::Duplicate, "copies.txt", 2,
               "the point on line 1");
  // The earliest repeat in file order wins, whichever group it is in.
  const auto g = plain<2>("1 1\n2 2\n3 3\n2 2\n1 1\n2 2\n", "g.txt");
  expect_error([&] { (void)locate_points(g, derive_box<2>(g.points)); }, Kind::Duplicate, "g.txt", 4,
               "the point on line 2");
}

TEST(LocatePoints, DropDuplicatePointsKeepsTheFirstCopy) {
  auto f = plain<2>("0 0\n5 5\n1 1\n1.0 1e0\n# c\n5 5\n-0 0\n2 2\n");
  EXPECT_EQ(drop_duplicate_points(f), 3u);
  EXPECT_EQ(f.points, (std::vector<Point<2>>{{0, 0}, {5, 5}, {1, 1}, {2, 2}}));
  EXPECT_EQ(f.lines, (std::vector<std::size_t>{1, 2, 3, 8}));
  EXPECT_EQ(locate_points(f, derive_box<2>(f.points)).size(), 4u);
  EXPECT_EQ(drop_duplicate_points(f), 0u);
  // Different points with one located position stay: that is not a duplicate.
  auto g = plain<2>("0 0\n1 1\n1e-20 0\n");
  EXPECT_EQ(drop_duplicate_points(g), 0u);
  expect_error([&] { (void)locate_points(g, derive_box<2>(g.points)); }, Kind::Resolution, "in.xyz", 3);
}

TEST(SpreadMessages, StretchingPointAndSpreadText) {
  // Terrain coordinates with one stray far-out point: it alone stretches the derived box.
  const std::vector<Point<2>> terrain = {
      {500000, 4100000}, {500012.5, 4100003}, {1e17, 4100000}, {500050, 4100050}};
  const auto stretch = stretching_point<2>(terrain);
  ASSERT_TRUE(stretch);
  EXPECT_EQ(stretch->index, 2u);
  EXPECT_EQ(stretch->side_without, 150.0);  // 3 · 50
  const std::vector<Point<3>> low = {{0, 0, -1e9}, {1, 1, 1}, {0.5, 0.5, 0.5}};
  EXPECT_EQ(stretching_point<3>(low)->index, 0u);
  EXPECT_EQ(stretching_point<3>(low)->side_without, 1.5);  // 3 · 0.5
  EXPECT_FALSE(stretching_point<2>(std::vector<Point<2>>{{0, 0}, {1, 1}}));
  const Box<2> box{{-1, -1}, 3};
  EXPECT_EQ(spread_text<2>(box, {0, 0}, {0, 1e-20}), "spread L/s = 3e+20 (log2 68.0) with L = 3 and s = 1e-20");
  EXPECT_EQ(spread_text<2>(box, {0, 0}, {3e-300, 4e-300}),
            "spread L/s = 6e+299 (log2 995.8) with L = 3 and s = 5e-300");
}

TEST(LocatePoints, OutsideTheGivenBox) {
  const auto f = plain<3>("0 0 0\n0.5 0.5 0.5\n1 0.5 0.5\n", "box.txt");
  const Box<3> box{{0, 0, 0}, 1};
  expect_error([&] { (void)locate_points(f, box); }, Kind::OutsideBox, "box.txt", 3, "outside the domain box");
}

// --- edit scripts ----------------------------------------------------------------------------

TEST(ReadEdits, Basic) {
  const auto script = edits<2>("# script\n+ 0.5 0.25\n\n- 1 2 # delete\n  +\t3 4\n");
  const auto& e = script.edits;
  ASSERT_EQ(e.size(), 3u);
  ASSERT_EQ(script.lines, (std::vector<std::size_t>{2, 4, 5}));
  EXPECT_EQ(e[0].op, EditOp::Insert);
  EXPECT_EQ(e[0].point, (Point<2>{0.5, 0.25}));
  EXPECT_EQ(e[1].op, EditOp::Delete);
  EXPECT_EQ(e[2].point, (Point<2>{3, 4}));
  const auto e3 = edits<3>("- 1 2 3\n");
  EXPECT_EQ(e3.edits[0].point, (Point<3>{1, 2, 3}));
}

TEST(ReadEdits, ByteOrderMarkCommasAndSemicolons) {
  const auto script = edits<2>("\xEF\xBB\xBF+ 0.5,0.25\n- 0.5; 0.25\n+,1,2\n-\t3 ;4\n");
  const auto& e = script.edits;
  ASSERT_EQ(e.size(), 4u);
  EXPECT_EQ(e[0].op, EditOp::Insert);
  EXPECT_EQ(e[0].point, (Point<2>{0.5, 0.25}));
  EXPECT_EQ(e[1].op, EditOp::Delete);
  EXPECT_EQ(e[1].point, (Point<2>{0.5, 0.25}));
  EXPECT_EQ(e[2].point, (Point<2>{1, 2}));
  EXPECT_EQ(e[3].point, (Point<2>{3, 4}));
  EXPECT_EQ(edits<3>("+ 1,2,3\n").edits[0].point, (Point<3>{1, 2, 3}));
  const std::string n = "ed.csv";
  expect_error([&] { edits<2>("+ 1,5 2\n", n); }, Kind::Malformed, n, 1, "'1,5'");
  expect_error([&] { edits<2>("+ 1,,2\n", n); }, Kind::Malformed, n, 1, "empty field");
  expect_error([&] { edits<2>("+ 1,2,3\n", n); }, Kind::Count, n, 1, "exactly 2");
  expect_error([&] { edits<2>("+1,2\n", n); }, Kind::Malformed, n, 1, "'+1'");
  expect_error([&] { edits<2>("- 1;nan\n", n); }, Kind::NotFinite, n, 1);
}

TEST(ReadEdits, Errors) {
  const std::string n = "ed.txt";
  expect_error([&] { edits<2>("+ 1 2\n* 1 2\n", n); }, Kind::Malformed, n, 2, "'*'");
  expect_error([&] { edits<2>("+1 2\n", n); }, Kind::Malformed, n, 1);
  expect_error([&] { edits<2>("+ 1\n", n); }, Kind::Count, n, 1, "exactly 2");
  expect_error([&] { edits<2>("\n\n- 1 2 3\n", n); }, Kind::Count, n, 3);
  expect_error([&] { edits<3>("+ 1 2\n", n); }, Kind::Count, n, 1);
  expect_error([&] { edits<2>("+ 1 two\n", n); }, Kind::Malformed, n, 1, "'two'");
  expect_error([&] { edits<2>("- nan 2\n", n); }, Kind::NotFinite, n, 1);
}

// --- .cells ----------------------------------------------------------------------------------

TEST(Cells, WriterIsByteExact) {
  // Two points two level-1 cells apart (the grading cascade with m = 1), box derived from
  // three points with ugly coordinates (%.17g must print all digits).
  const std::vector<Point<2>> pts = {{0.1, 0.2}, {0.4, 0.8}, {0.35, 0.75}};
  const Box<2> box = derive_box<2>(pts);
  const std::vector<Position<2>> q = {{0, 0}, {std::uint64_t{1} << 51, 0}};
  const StaticQuadtree<2> tree(q);
  std::vector<Leaf<2>> leaves(tree.leaves().begin(), tree.leaves().end());
  std::reverse(leaves.begin(), leaves.end());  // the writer sorts
  std::ostringstream out;
  write_cells<2>(out, box, leaves);
  EXPECT_EQ(out.str(),
            "# dynmesh cells v1\n"
            "# dim 2\n"
            "# box -0.65000000000000013 -0.40000000000000013 1.8000000000000003\n"
            "1 0 1 0\n"
            "1 1 1 0\n"
            "2 0 0 1\n"
            "2 0 1 0\n"
            "2 1 0 0\n"
            "2 1 1 0\n"
            "2 2 0 1\n"
            "2 2 1 0\n"
            "2 3 0 0\n"
            "2 3 1 0\n");
}

TEST(Cells, WriterThreeDAndNumberFormats) {
  const Box<3> box{{-1, 1e-300, -0.0}, 123456789012345680000.0};
  const std::vector<Leaf<3>> leaves = {{{1, {1, 0, 0}}, 0}, {{0, {0, 0, 0}}, 3}, {{1, {0, 1, 1}}, 1}};
  EXPECT_EQ(format_cells<3>(box, leaves),
            "# dynmesh cells v1\n"
            "# dim 3\n"
            "# box -1 1e-300 -0 1.2345678901234568e+20\n"
            "0 0 0 0 3\n"
            "1 0 1 1 1\n"
            "1 1 0 0 0\n");
}

TEST_F(TempDir, CellsRoundTrip) {
  const auto pts = generate<3>(Distribution::Clusters, 300, 5);
  const Box<3> box = derive_box<3>(pts);
  const auto tree = StaticQuadtree<3>::from_points(box, pts);
  const std::string path = (dir_ / "t.cells").string();
  write_cells_file<3>(path, box, tree.leaves());
  const CellsFile<3> back = read_cells_file<3>(path);
  EXPECT_EQ(back.box, box);
  EXPECT_TRUE(std::equal(back.leaves.begin(), back.leaves.end(), tree.leaves().begin(), tree.leaves().end()));
  std::vector<Position<3>> q;
  for (const auto& p : pts) q.push_back(locate(box, p));
  EXPECT_TRUE(check_tree<3>(q, back.leaves).ok());
}

TEST(Cells, ReaderErrors) {
  const std::string n = "x.cells";
  auto rd = [&](const std::string& text) {
    std::istringstream in(text);
    return read_cells<2>(in, n);
  };
  const std::string head = "# dynmesh cells v1\n# dim 2\n# box 0 0 1\n";
  EXPECT_EQ(rd(head + "0 0 0 0\n").leaves.size(), 1u);
  expect_error([&] { rd("# dynmesh cells v2\n"); }, Kind::Malformed, n, 1);
  expect_error([&] { rd("# dynmesh cells v1\n# dim 3\n"); }, Kind::Malformed, n, 2);
  expect_error([&] { rd("# dynmesh cells v1\n# dim 2\n# box 0 0\n"); }, Kind::Malformed, n, 3);
  expect_error([&] { rd("# dynmesh cells v1\n# dim 2\n# box 0 0 -1\n"); }, Kind::OutsideBox, n, 3);
  expect_error([&] { rd(head + "1 0 0 0\n1 0 1 0 7\n"); }, Kind::Count, n, 5);
  expect_error([&] { rd(head + "1 2 0 0\n"); }, Kind::Malformed, n, 4, "index");
  expect_error([&] { rd(head + "53 0 0 0\n"); }, Kind::Malformed, n, 4, "level");
  expect_error([&] { rd(head + "1 1 0 0\n1 0 1 0\n"); }, Kind::Malformed, n, 5, "sorted");
  expect_error([&] { rd(head + "1 0 0 0\n\n"); }, Kind::Count, n, 5);
}

}  // namespace
