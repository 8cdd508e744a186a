// fuzz_point_readers — libFuzzer target of the point-file readers (dynmesh/io.hpp):
// read_node, read_poly and read_plain in 2D and 3D, and what the commands do next with a file they read
// (drop_duplicate_points, derive_box, locate_points, the static tree on small files).
//
// Input: the first byte picks the reader (bit 0: `.node` or plain text; bit 2 set: `.poly`)
// and the dimension (bit 1: 2 or 3); the rest is the file's text.
// Properties: a read either succeeds or throws InputError (Malformed, NotFinite, Count, or
// Unsupported for plain text shaped like Triangle's numbered rows or a .poly with segments)
// naming the file and an existing line in a one-line message; a successful read has one
// strictly increasing line number per point and finite coordinates only, and the points
// written back (%.17g) read back bit for bit, as plain text and as `.node`; dropping
// duplicates keeps the first copy of each point in order and leaves no two equal;
// derive_box and locate_points succeed or throw InputError, and located positions are
// distinct; a small file's static tree passes its checker.
// Complexity: linear in the input, plus O(n log n) for the located points.
#include "fuzz_support.hpp"

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "dynmesh/io.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace {

using namespace dynmesh_fuzz;

template <std::size_t d>
void check_round_trip(const PointFile<d>& file) {
  std::string plain, node = std::to_string(file.points.size()) + " " + std::to_string(d) + " 0 0\n";
  for (std::size_t i = 0; i < file.points.size(); ++i) {
    node += std::to_string(i + 1);
    for (std::size_t a = 0; a < d; ++a) {
      plain += (a ? " " : "") + format_exact(file.points[i][a]);
      node += " " + format_exact(file.points[i][a]);
    }
    plain += '\n';
    node += '\n';
  }
  std::istringstream plain_in(plain), node_in(node);
  const PointFile<d> again = read_plain<d>(plain_in, "again.txt");
  const PointFile<d> again_node = read_node<d>(node_in, "again.node");
  check(again.points.size() == file.points.size() && again_node.points.size() == file.points.size(),
        "points written back read back as a different number of points");
  for (std::size_t i = 0; i < file.points.size(); ++i)
    check(same_bits<d>(again.points[i], file.points[i]) && same_bits<d>(again_node.points[i], file.points[i]),
          "a point written back (%.17g) reads back as a different double");
}

template <std::size_t d>
void check_duplicates_dropped(const PointFile<d>& file) {
  PointFile<d> kept = file;
  const std::size_t dropped = drop_duplicate_points<d>(kept);
  check(kept.points.size() + dropped == file.points.size(), "drop_duplicate_points miscounts");
  check(kept.lines.size() == kept.points.size(), "drop_duplicate_points: lines and points disagree");
  // The kept points are the first copies, in file order (quadratic: files here are small).
  std::size_t k = 0;
  for (std::size_t i = 0; i < file.points.size(); ++i) {
    bool earlier = false;
    for (std::size_t j = 0; j < i && !earlier; ++j) earlier = file.points[j] == file.points[i];
    if (earlier) continue;
    check(k < kept.points.size() && same_bits<d>(kept.points[k], file.points[i]) && kept.lines[k] == file.lines[i],
          "drop_duplicate_points did not keep the first copy of a point, in order");
    ++k;
  }
  check(k == kept.points.size(), "drop_duplicate_points kept a later copy");
}

template <std::size_t d>
void check_located(const PointFile<d>& file) {
  Box<d> box;
  try {
    box = derive_box<d>(file.points);
  } catch (const InputError&) {
    return;  // empty, or coordinates too large for a usable box
  }
  std::vector<Position<d>> q;
  try {
    q = locate_points<d>(file, box);
  } catch (const InputError& e) {
    using Kind = InputError::Kind;
    // The derived box holds every point in its middle third: only collisions can fail.
    check(e.kind() == Kind::Duplicate || e.kind() == Kind::Resolution,
          "locate_points on the derived box threw other than Duplicate or Resolution");
    check(e.line() != 0 && e.file() == file.name, "locate_points: the error names no line");
    return;
  }
  check(q.size() == file.points.size(), "locate_points: one position per point");
  if (q.size() > 32) return;  // keep each run fast
  try {
    const StaticQuadtree<d> tree(q);
    tree.check_invariants();
  } catch (const InputError& e) {
    // Distinct positions that a level-52 cell cannot separate.
    check(e.kind() == InputError::Kind::Resolution, "the static tree refused distinct positions other than for resolution");
  }
}

enum class Reader { Plain, Node, Poly };

template <std::size_t d>
void fuzz(Reader reader, std::string_view text) {
  const std::string name = reader == Reader::Poly ? "fuzz.poly" : reader == Reader::Node ? "fuzz.node" : "fuzz.txt";
  std::istringstream in{std::string(text)};
  PointFile<d> file;
  try {
    file = reader == Reader::Poly   ? read_poly<d>(in, name)
           : reader == Reader::Node ? read_node<d>(in, name)
                                    : read_plain<d>(in, name);
  } catch (const InputError& e) {
    check_reader_error(e, name, text);
    return;
  }
  check(file.name == name, "the file keeps its name");
  check_lines(file.lines, file.points.size(), text);
  for (const Point<d>& p : file.points) check(finite<d>(p), "a successful read returned a NaN or infinity");
  check_round_trip<d>(file);
  if (file.points.size() <= 256) check_duplicates_dropped<d>(file);
  check_located<d>(file);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t selector = data[0];
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  const Reader reader = (selector & 4) ? Reader::Poly : (selector & 1) ? Reader::Node : Reader::Plain;
  if (selector & 2)
    fuzz<3>(reader, text);
  else
    fuzz<2>(reader, text);
  return 0;
}
