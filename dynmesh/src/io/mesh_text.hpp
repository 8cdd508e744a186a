// mesh_text.hpp (private) — the text forms of a simplicial mesh in d dimensions: one template
// for the 2D writers (mesh_io.cpp) and the 3D ones (tet_mesh_io.cpp).
//
// Purpose: a triangle mesh and a tetrahedral mesh are written and read alike: a vertex list
// and a list of k-vertex cells, numbered from 1 in the .node/.ele, .msh files and from 0 in
// .vtk; a feed line per simplex; the -V style statistics' rows and histogram. Writing them
// once keeps the two dimensions' files identical in form (docs/FORMATS.md, "`dynmesh mesh` (2D)"
// and "`dynmesh mesh` in 3D") and their number formatting the same (%.17g, C locale).
// Invariants: every line ends in '\n'; coordinates are format_exact's text, so they
// round-trip; read_node_ele_text(node_text(v, box), ele_text(c)) gives back v and c.
// Complexity: linear in the vertices and cells, and in the text for the reader.
// Paper: none (Triangle's and TetGen's .node/.ele; VTK's legacy format; Gmsh's MSH 2.2).
#pragma once

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"
#include "io/number_text.hpp"

namespace dynmesh::detail {

inline void append_line_end(std::string& out) { out += '\n'; }


/// A one-digit constant as a character (append_number on a constant trips GCC 12's
/// -Wrestrict false positive, its bug 105651).
template <std::size_t n>
constexpr char digit() noexcept {
  static_assert(n < 10);
  return static_cast<char>('0' + n);
}

/// The coordinates, separated by spaces, with z = 0 for a 2D point where the format is 3D.
template <std::size_t d>
void append_coordinates(std::string& out, const Point<d>& p, bool pad_to_3d) {
  for (std::size_t a = 0; a < d; ++a) {
    if (a) out += ' ';
    append_exact(out, p[a]);
  }
  if (pad_to_3d && d == 2) out += " 0";
}

// ---- Triangle's and TetGen's .node / .ele ---------------------------------------------------

/// `<#vertices> d 0 1`.
template <std::size_t d>
void append_node_header(std::string& out, std::size_t vertices) {
  append_number(out, vertices);
  out += ' ';
  out += digit<d>();
  out += " 0 1";
  append_line_end(out);
}

/// `<i> <coordinates> <marker>` for each vertex, i from first + 1; the marker is 1 on a side
/// of the closed box (a coordinate equal to o or fl(o + L)), else 0.
template <std::size_t d>
void append_node_lines(std::string& out, std::size_t first, std::span<const Point<d>> vertices, const Box<d>& box) {
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const Point<d>& p = vertices[i];
    bool boundary = false;
    for (std::size_t a = 0; a < d; ++a)
      boundary = boundary || p[a] == box.origin[a] || p[a] == box.origin[a] + box.side;
    append_number(out, first + i + 1);
    out += ' ';
    append_coordinates(out, p, false);
    out += boundary ? " 1" : " 0";
    append_line_end(out);
  }
}

template <std::size_t d>
std::string node_text(std::span<const Point<d>> vertices, const Box<d>& box) {
  std::string out;
  out.reserve(32 + vertices.size() * (8 + 24 * d));
  append_node_header<d>(out, vertices.size());
  append_node_lines<d>(out, 0, vertices, box);
  return out;
}

/// `<#cells> k 0`.
template <std::size_t k>
void append_ele_header(std::string& out, std::size_t cells) {
  append_number(out, cells);
  out += ' ';
  out += digit<k>();
  out += " 0";
  append_line_end(out);
}

/// `<i> <v1> ... <vk>` for each cell, i from first + 1, of 0-based vertex numbers written
/// from 1.
template <std::size_t k, class Index>
void append_ele_lines(std::string& out, std::size_t first, std::span<const std::array<Index, k>> cells) {
  for (std::size_t t = 0; t < cells.size(); ++t) {
    append_number(out, first + t + 1);
    for (const Index v : cells[t]) {
      out += ' ';
      append_number(out, static_cast<std::size_t>(v) + 1);
    }
    append_line_end(out);
  }
}

template <std::size_t k>
std::string ele_text(std::span<const std::array<std::uint32_t, k>> cells) {
  std::string out;
  out.reserve(32 + cells.size() * 8 * (k + 1));
  append_ele_header<k>(out, cells.size());
  append_ele_lines<k, std::uint32_t>(out, 0, cells);
  return out;
}

// ---- VTK and Gmsh ---------------------------------------------------------------------------

/// Legacy VTK (version 3.0) ASCII unstructured grid: 3D points (z = 0 in 2D), 0-based cells,
/// one VTK cell type for all. In parts: the header and `POINTS`, the point lines, `CELLS`,
/// the cell lines, then `CELL_TYPES` and its lines.
inline void append_vtk_points_head(std::string& out, std::size_t nv) {
  out += "# vtk DataFile Version 3.0\ndynmesh mesh\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS ";
  append_number(out, nv);
  out += " double\n";
}
template <std::size_t d>
void append_vtk_point_lines(std::string& out, std::span<const Point<d>> vertices) {
  for (const Point<d>& p : vertices) {
    append_coordinates(out, p, true);
    append_line_end(out);
  }
}
template <std::size_t k>
void append_vtk_cells_head(std::string& out, std::size_t nt) {
  out += "CELLS ";
  append_number(out, nt);
  out += ' ';
  append_number(out, (k + 1) * nt);  // each cell: its point count, then its 0-based point ids
  append_line_end(out);
}
template <std::size_t k, class Index>
void append_vtk_cell_lines(std::string& out, std::span<const std::array<Index, k>> cells) {
  for (const auto& cell : cells) {
    out += digit<k>();
    for (const Index v : cell) {
      out += ' ';
      append_number(out, static_cast<std::size_t>(v));
    }
    append_line_end(out);
  }
}
inline void append_vtk_cell_types(std::string& out, std::size_t nt, int cell_type) {
  out += "CELL_TYPES ";
  append_number(out, nt);
  append_line_end(out);
  const std::string type_line = std::to_string(cell_type) + '\n';
  for (std::size_t t = 0; t < nt; ++t) out += type_line;
}

template <std::size_t d, std::size_t k>
std::string vtk_text(std::span<const Point<d>> vertices, std::span<const std::array<std::uint32_t, k>> cells,
                     int cell_type) {
  const std::size_t nv = vertices.size(), nt = cells.size();
  std::string out;
  out.reserve(160 + nv * 66 + nt * 8 * (k + 1));
  append_vtk_points_head(out, nv);
  append_vtk_point_lines<d>(out, vertices);
  append_vtk_cells_head<k>(out, nt);
  append_vtk_cell_lines<k, std::uint32_t>(out, cells);
  append_vtk_cell_types(out, nt, cell_type);
  return out;
}

/// Gmsh MSH 2.2 ASCII: 3D nodes (z = 0 in 2D) and 1-based elements of one type. In parts:
/// the head with the node count, the node lines, the element head (`$EndNodes` and the
/// element count), the element lines, `$EndElements`.
inline void append_msh_nodes_head(std::string& out, std::size_t nv) {
  out += "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n";
  append_number(out, nv);
  append_line_end(out);
}
template <std::size_t d>
void append_msh_node_lines(std::string& out, std::size_t first, std::span<const Point<d>> vertices) {
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    append_number(out, first + i + 1);
    out += ' ';
    append_coordinates(out, vertices[i], true);
    append_line_end(out);
  }
}
inline void append_msh_elements_head(std::string& out, std::size_t nt) {
  out += "$EndNodes\n$Elements\n";
  append_number(out, nt);
  append_line_end(out);
}
template <std::size_t k, class Index>
void append_msh_element_lines(std::string& out, std::size_t first, std::span<const std::array<Index, k>> cells,
                              int element_type) {
  // Two tags per element: physical group 1 and elementary entity 1. Readers that keep only
  // physical groups (dolfin-convert, some meshio paths) then keep them all.
  const std::string type_and_tags = ' ' + std::to_string(element_type) + " 2 1 1";
  for (std::size_t t = 0; t < cells.size(); ++t) {
    append_number(out, first + t + 1);
    out += type_and_tags;
    for (const Index v : cells[t]) {
      out += ' ';
      append_number(out, static_cast<std::size_t>(v) + 1);
    }
    append_line_end(out);
  }
}
inline void append_msh_end(std::string& out) { out += "$EndElements\n"; }

template <std::size_t d, std::size_t k>
std::string msh_text(std::span<const Point<d>> vertices, std::span<const std::array<std::uint32_t, k>> cells,
                     int element_type) {
  const std::size_t nv = vertices.size(), nt = cells.size();
  std::string out;
  out.reserve(160 + nv * 72 + nt * 8 * (k + 5));
  append_msh_nodes_head(out, nv);
  append_msh_node_lines<d>(out, 0, vertices);
  append_msh_elements_head(out, nt);
  append_msh_element_lines<k, std::uint32_t>(out, 0, cells, element_type);
  append_msh_end(out);
  return out;
}

// ---- reading .node / .ele back --------------------------------------------------------------

/// The non-comment fields of one line at a time, with the line number for messages.
class FieldReader {
 public:
  FieldReader(std::string_view text, std::string name) : text_(text), name_(std::move(name)) {}

  /// The next line with at least one field; false at the end of the text.
  bool next(std::vector<std::string_view>& fields) {
    while (pos_ < text_.size()) {
      const std::size_t end = std::min(text_.find('\n', pos_), text_.size());
      std::string_view line = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_;
      if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      fields.clear();
      std::size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && is_space(line[i])) ++i;
        const std::size_t start = i;
        while (i < line.size() && !is_space(line[i])) ++i;
        if (i > start) fields.push_back(line.substr(start, i - start));
      }
      if (!fields.empty()) return true;
    }
    return false;
  }

  [[noreturn]] void fail(InputError::Kind kind, const std::string& what) const {
    throw InputError(kind, what, name_, line_);
  }

  std::size_t integer(std::string_view field) const {
    std::size_t value = 0;
    const auto r = std::from_chars(field.data(), field.data() + field.size(), value);
    if (r.ec != std::errc() || r.ptr != field.data() + field.size())
      fail(InputError::Kind::Malformed, "expected a non-negative integer, got '" + std::string(field) + "'");
    return value;
  }

  double number(std::string_view field) const {
    std::string_view digits = field;
    if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);  // from_chars rejects '+'
    double value = 0;
    const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (r.ec == std::errc::result_out_of_range)
      fail(InputError::Kind::NotFinite, "number '" + std::string(field) + "' is out of the range of double");
    if (r.ec != std::errc() || r.ptr != digits.data() + digits.size() ||
        (digits.size() < field.size() && !digits.empty() && digits.front() == '-'))
      fail(InputError::Kind::Malformed, "expected a number, got '" + std::string(field) + "'");
    if (!std::isfinite(value))
      fail(InputError::Kind::NotFinite, "NaN or infinite coordinate '" + std::string(field) + "'");
    return value;
  }

 private:
  static bool is_space(char c) noexcept { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

  std::string_view text_;
  std::string name_;
  std::size_t pos_ = 0;
  std::size_t line_ = 0;
};

/// What the reader calls a cell in its messages ("triangle", "triangles").
struct CellWords {
  const char* one;
  const char* many;
};

/// Parses .node and .ele text (numbering from 0 or 1, `#` comments, attributes and markers
/// ignored) into vertices and k-vertex cells, in file order. InputError (Malformed, Count,
/// NotFinite) naming "node" or "ele" and the line otherwise.
template <std::size_t d, std::size_t k>
void read_node_ele_text(const std::string& node_text, const std::string& ele_text, CellWords cell,
                        std::vector<Point<d>>& vertices, std::vector<std::array<std::uint32_t, k>>& cells) {
  static constexpr std::array<const char*, 5> kCount{"zero", "one", "two", "three", "four"};
  static_assert(k < kCount.size());
  std::vector<std::string_view> fields;

  FieldReader node(node_text, "node");
  if (!node.next(fields)) node.fail(InputError::Kind::Malformed, "missing the header line");
  const std::size_t nv = node.integer(fields[0]);
  if (fields.size() > 1 && node.integer(fields[1]) != d)
    node.fail(InputError::Kind::Malformed, "dimension must be " + std::to_string(d));
  std::size_t base = 0;
  vertices.reserve(std::min(nv, node_text.size() / (2 * d)));  // a bogus count must not allocate
  for (std::size_t i = 0; i < nv; ++i) {
    if (!node.next(fields))
      node.fail(InputError::Kind::Count, "expected " + std::to_string(nv) + " vertices, found " + std::to_string(i));
    if (fields.size() < d + 1)
      node.fail(InputError::Kind::Count, std::string("a vertex line needs a number and ") + kCount[d] + " coordinates");
    const std::size_t number = node.integer(fields[0]);
    if (i == 0) {
      if (number > 1) node.fail(InputError::Kind::Malformed, "vertex numbering must start at 0 or 1");
      base = number;
    } else if (number != base + i) {
      node.fail(InputError::Kind::Malformed,
                "vertex number " + std::to_string(number) + ", expected " + std::to_string(base + i));
    }
    Point<d> p;
    for (std::size_t a = 0; a < d; ++a) p[a] = node.number(fields[a + 1]);
    vertices.push_back(p);
  }
  if (node.next(fields)) node.fail(InputError::Kind::Count, "more vertices than the header's " + std::to_string(nv));

  FieldReader ele(ele_text, "ele");
  if (!ele.next(fields)) ele.fail(InputError::Kind::Malformed, "missing the header line");
  const std::size_t nt = ele.integer(fields[0]);
  if (fields.size() > 1 && ele.integer(fields[1]) != k)
    ele.fail(InputError::Kind::Malformed, "only " + std::to_string(k) + "-node " + cell.many + " are supported");
  cells.reserve(std::min(nt, ele_text.size() / (2 * k)));
  for (std::size_t t = 0; t < nt; ++t) {
    if (!ele.next(fields))
      ele.fail(InputError::Kind::Count,
               "expected " + std::to_string(nt) + " " + cell.many + ", found " + std::to_string(t));
    if (fields.size() < k + 1)
      ele.fail(InputError::Kind::Count,
               std::string("a ") + cell.one + " line needs a number and " + kCount[k] + " vertices");
    std::array<std::uint32_t, k> ids{};
    for (std::size_t c = 0; c < k; ++c) {
      const std::size_t v = ele.integer(fields[c + 1]);
      if (v < base || v - base >= nv)
        ele.fail(InputError::Kind::Malformed, "vertex " + std::to_string(v) + " does not exist");
      ids[c] = static_cast<std::uint32_t>(v - base);
    }
    cells.push_back(ids);
  }
  if (ele.next(fields))
    ele.fail(InputError::Kind::Count, std::string("more ") + cell.many + " than the header's " + std::to_string(nt));
}

// ---- the change feed ------------------------------------------------------------------------

/// `update <k> removed <r> added <a>`.
inline void append_feed_head(std::string& out, std::size_t k, std::size_t removed, std::size_t added) {
  out += "update ";
  append_number(out, k);
  out += " removed ";
  append_number(out, removed);
  out += " added ";
  append_number(out, added);
  append_line_end(out);
}

/// A `sign ...` line per simplex: its corners' coordinates in its (canonical) order.
template <class Simplex>
void append_simplex_lines(std::string& out, char sign, std::span<const Simplex> simplices) {
  for (const Simplex& s : simplices) {
    out += sign;
    for (const auto& p : s.v) {
      out += ' ';
      append_coordinates(out, p, false);
    }
    append_line_end(out);
  }
}

/// The head, then a `- ...` line per removed simplex and a `+ ...` line per added one.
/// Appended to `out`, so that a caller streaming the feed can reuse one string.
template <class Simplex>
void append_feed_update_text(std::string& out, std::size_t k, std::span<const Simplex> removed,
                             std::span<const Simplex> added) {
  append_feed_head(out, k, removed.size(), added.size());
  append_simplex_lines<Simplex>(out, '-', removed);
  append_simplex_lines<Simplex>(out, '+', added);
}

// ---- the statistics report ------------------------------------------------------------------

inline std::string pad_right(std::string s, std::size_t width) {
  if (s.size() < width) s.append(width - s.size(), ' ');
  return s;
}

inline std::string pad_left(std::string s, std::size_t width) {
  if (s.size() < width) s.insert(0, width - s.size(), ' ');
  return s;
}

/// `  <left> <l> |  <right> <r>` in aligned columns (labels padded to label_width), numbers
/// to 6 significant digits.
inline void append_stats_row(std::string& out, const char* left, double l, const char* right, double r,
                             std::size_t label_width = 16) {
  out += "  " + pad_right(left, label_width) + pad_right(format_brief(l), 14) + "|  " + pad_right(right, label_width) +
         format_brief(r) + '\n';
}

/// An angle histogram of 10-degree bins over [0, 180] in two columns of nine.
inline void append_angle_histogram(std::string& out, const std::array<std::size_t, 18>& histogram) {
  auto bin = [&](std::size_t k) {
    return pad_left(std::to_string(10 * k), 7) + " - " + pad_left(std::to_string(10 * k + 10), 3) +
           " degrees: " + pad_left(std::to_string(histogram[k]), 9);
  };
  for (std::size_t k = 0; k < 9; ++k) out += "  " + bin(k) + "    |" + bin(k + 9) + '\n';
}

/// The histogram bin of an angle in degrees: [10k − snap, 10k + 10 − snap), with 180 in the
/// last bin. A snap of the angles' accuracy keeps an exact angle on a bin's lower end in that
/// bin when it is computed a few ulps below (Kuhn's 60° dihedral comes out 59.999999999999993).
inline std::size_t angle_bin(double angle_deg, double snap = 0) noexcept {
  return static_cast<std::size_t>(std::clamp((angle_deg + snap) / 10, 0.0, 17.0));
}

}  // namespace dynmesh::detail
