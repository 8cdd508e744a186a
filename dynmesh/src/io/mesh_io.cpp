// The text forms of a 2D mesh (see dynmesh/mesh_io.hpp for the formats).
#include "dynmesh/mesh_io.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>
#include <utility>
#include <vector>

#include "dynmesh/errors.hpp"
#include "dynmesh/mesh_check.hpp"
#include "geometry/powers_of_two.hpp"

namespace dynmesh {
namespace {

void append_line_end(std::string& out) { out += '\n'; }

void append_number(std::string& out, std::size_t n) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, n);
  out.append(buf, r.ptr);
}

void append_exact(std::string& out, double x) { out += format_exact(x); }

}  // namespace

// ---- Triangle's .node / .ele --------------------------------------------------------------

std::string format_node(const Mesh& mesh, const Box<2>& box) {
  const double x0 = box.origin[0], x1 = box.origin[0] + box.side;
  const double y0 = box.origin[1], y1 = box.origin[1] + box.side;
  std::string out;
  out.reserve(32 + mesh.num_vertices() * 48);
  append_number(out, mesh.num_vertices());
  out += " 2 0 1";
  append_line_end(out);
  for (std::size_t i = 0; i < mesh.num_vertices(); ++i) {
    const Point<2>& p = mesh.vertices[i];
    const bool boundary = p[0] == x0 || p[0] == x1 || p[1] == y0 || p[1] == y1;
    append_number(out, i + 1);
    out += ' ';
    append_exact(out, p[0]);
    out += ' ';
    append_exact(out, p[1]);
    out += boundary ? " 1" : " 0";
    append_line_end(out);
  }
  return out;
}

std::string format_ele(const Mesh& mesh) {
  std::string out;
  out.reserve(32 + mesh.num_triangles() * 32);
  append_number(out, mesh.num_triangles());
  out += " 3 0";
  append_line_end(out);
  for (std::size_t t = 0; t < mesh.num_triangles(); ++t) {
    append_number(out, t + 1);
    for (std::uint32_t v : mesh.triangles[t]) {
      out += ' ';
      append_number(out, std::size_t{v} + 1);
    }
    append_line_end(out);
  }
  return out;
}

// ---- VTK and Gmsh -------------------------------------------------------------------------

std::string format_vtk(const Mesh& mesh) {
  const std::size_t nv = mesh.num_vertices(), nt = mesh.num_triangles();
  std::string out;
  out.reserve(160 + nv * 44 + nt * 30);
  out += "# vtk DataFile Version 3.0\ndynmesh mesh\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS ";
  append_number(out, nv);
  out += " double\n";
  for (const Point<2>& p : mesh.vertices) {
    append_exact(out, p[0]);
    out += ' ';
    append_exact(out, p[1]);
    out += " 0\n";
  }
  out += "CELLS ";
  append_number(out, nt);
  out += ' ';
  append_number(out, 4 * nt);  // each cell: its point count, then three 0-based point ids
  append_line_end(out);
  for (const auto& tri : mesh.triangles) {
    out += '3';
    for (std::uint32_t v : tri) {
      out += ' ';
      append_number(out, v);
    }
    append_line_end(out);
  }
  out += "CELL_TYPES ";
  append_number(out, nt);
  append_line_end(out);
  for (std::size_t t = 0; t < nt; ++t) out += "5\n";  // VTK_TRIANGLE
  return out;
}

std::string format_msh(const Mesh& mesh) {
  const std::size_t nv = mesh.num_vertices(), nt = mesh.num_triangles();
  std::string out;
  out.reserve(160 + nv * 50 + nt * 40);
  out += "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n";
  append_number(out, nv);
  append_line_end(out);
  for (std::size_t i = 0; i < nv; ++i) {
    append_number(out, i + 1);
    out += ' ';
    append_exact(out, mesh.vertices[i][0]);
    out += ' ';
    append_exact(out, mesh.vertices[i][1]);
    out += " 0\n";
  }
  out += "$EndNodes\n$Elements\n";
  append_number(out, nt);
  append_line_end(out);
  for (std::size_t t = 0; t < nt; ++t) {
    append_number(out, t + 1);
    // Type 2 (3-node triangle), two tags: physical group 1 and elementary entity 1. Readers
    // that keep only physical groups (dolfin-convert, some meshio paths) then keep them all.
    out += " 2 2 1 1";
    for (std::uint32_t v : mesh.triangles[t]) {
      out += ' ';
      append_number(out, std::size_t{v} + 1);
    }
    append_line_end(out);
  }
  out += "$EndElements\n";
  return out;
}

// ---- reading .node / .ele back ------------------------------------------------------------

namespace {

// The non-comment fields of one line at a time, with the line number for messages.
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

}  // namespace

Mesh read_node_ele(const std::string& node_text, const std::string& ele_text) {
  Mesh mesh;
  std::vector<std::string_view> fields;

  FieldReader node(node_text, "node");
  if (!node.next(fields)) node.fail(InputError::Kind::Malformed, "missing the header line");
  const std::size_t nv = node.integer(fields[0]);
  if (fields.size() > 1 && node.integer(fields[1]) != 2) node.fail(InputError::Kind::Malformed, "dimension must be 2");
  std::size_t base = 0;
  mesh.vertices.reserve(std::min(nv, node_text.size() / 4));  // a bogus count must not allocate
  for (std::size_t i = 0; i < nv; ++i) {
    if (!node.next(fields))
      node.fail(InputError::Kind::Count, "expected " + std::to_string(nv) + " vertices, found " + std::to_string(i));
    if (fields.size() < 3) node.fail(InputError::Kind::Count, "a vertex line needs a number and two coordinates");
    const std::size_t number = node.integer(fields[0]);
    if (i == 0) {
      if (number > 1) node.fail(InputError::Kind::Malformed, "vertex numbering must start at 0 or 1");
      base = number;
    } else if (number != base + i) {
      node.fail(InputError::Kind::Malformed,
                "vertex number " + std::to_string(number) + ", expected " + std::to_string(base + i));
    }
    mesh.vertices.push_back({node.number(fields[1]), node.number(fields[2])});
  }
  if (node.next(fields)) node.fail(InputError::Kind::Count, "more vertices than the header's " + std::to_string(nv));

  FieldReader ele(ele_text, "ele");
  if (!ele.next(fields)) ele.fail(InputError::Kind::Malformed, "missing the header line");
  const std::size_t nt = ele.integer(fields[0]);
  if (fields.size() > 1 && ele.integer(fields[1]) != 3)
    ele.fail(InputError::Kind::Malformed, "only 3-node triangles are supported");
  mesh.triangles.reserve(std::min(nt, ele_text.size() / 6));
  for (std::size_t t = 0; t < nt; ++t) {
    if (!ele.next(fields))
      ele.fail(InputError::Kind::Count, "expected " + std::to_string(nt) + " triangles, found " + std::to_string(t));
    if (fields.size() < 4) ele.fail(InputError::Kind::Count, "a triangle line needs a number and three vertices");
    std::array<std::uint32_t, 3> tri{};
    for (std::size_t k = 0; k < 3; ++k) {
      const std::size_t v = ele.integer(fields[k + 1]);
      if (v < base || v - base >= nv)
        ele.fail(InputError::Kind::Malformed, "vertex " + std::to_string(v) + " does not exist");
      tri[k] = static_cast<std::uint32_t>(v - base);
    }
    mesh.triangles.push_back(tri);
  }
  if (ele.next(fields)) ele.fail(InputError::Kind::Count, "more triangles than the header's " + std::to_string(nt));
  return mesh;
}

// ---- SVG ----------------------------------------------------------------------------------

namespace {

// Picture coordinates are kept in hundredths of a pixel: the printed precision, and the
// grid on which edges that look the same (or have no length) are merged.
using Centi = std::int64_t;
struct PixelPoint {
  Centi x, y;
  friend auto operator<=>(const PixelPoint&, const PixelPoint&) = default;
};

void append_centi(std::string& out, Centi c) {
  if (c < 0) {
    out += '-';
    c = -c;
  }
  append_number(out, static_cast<std::size_t>(c / 100));
  const Centi frac = c % 100;
  if (frac != 0) {
    out += '.';
    out += static_cast<char>('0' + frac / 10);
    if (frac % 10 != 0) out += static_cast<char>('0' + frac % 10);
  }
}

std::string pixels(double v) {
  std::string s;
  append_centi(s, std::llround(v * 100));
  return s;
}

// Segments per <path>: one element holds many edges, but no attribute grows past about a
// megabyte (XML parsers such as libxml2 limit attribute size).
constexpr std::size_t kSegmentsPerPath = 40000;

}  // namespace

std::string format_svg(const Mesh& mesh, const Box<2>& box, std::span<const Point<2>> inputs,
                       const SvgMeshOptions& opt) {
  const double size = opt.width_px, margin = opt.margin_px, total = size + 2 * margin;
  const double per_unit = size / box.side;
  // y up: the box's lower side is at the bottom of the picture. Far-off points (a broken
  // mesh) are clamped so that the numbers stay printable.
  auto to_pixels = [&](const Point<2>& p) {
    auto clamp = [](double v) { return std::isfinite(v) ? std::clamp(v, -1e9, 1e9) : 0.0; };
    const double x = clamp(margin + (p[0] - box.origin[0]) * per_unit);
    const double y = clamp(margin + size - (p[1] - box.origin[1]) * per_unit);
    return PixelPoint{std::llround(x * 100), std::llround(y * 100)};
  };

  // Every edge once: the index pairs of all triangle sides, then the same on the pixel grid,
  // where a dense cluster collapses into few distinct segments.
  std::vector<std::uint64_t> pairs;
  pairs.reserve(3 * mesh.num_triangles());
  for (const auto& tri : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = tri[k], b = tri[(k + 1) % 3];
      pairs.push_back(a < b ? (a << 32 | b) : (b << 32 | a));
    }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  std::vector<PixelPoint> at(mesh.num_vertices());
  for (std::size_t i = 0; i < mesh.num_vertices(); ++i) at[i] = to_pixels(mesh.vertices[i]);
  std::vector<std::pair<PixelPoint, PixelPoint>> segments;
  segments.reserve(pairs.size());
  double length_sum = 0;
  for (std::uint64_t pair : pairs) {
    const std::size_t a = pair >> 32, b = pair & 0xffffffffu;
    if (a >= at.size() || b >= at.size()) continue;  // a broken mesh: draw what exists
    PixelPoint p = at[a], q = at[b];
    if (p == q) continue;
    if (q < p) std::swap(p, q);
    segments.emplace_back(p, q);
    length_sum += std::hypot(static_cast<double>(q.x - p.x), static_cast<double>(q.y - p.y)) / 100;
  }
  std::sort(segments.begin(), segments.end());
  segments.erase(std::unique(segments.begin(), segments.end()), segments.end());

  // A stroke a tenth of the mean edge on screen, within [0.05, 1] pixel: thin enough that
  // 10^5 triangles stay apart, thick enough that a coarse mesh is visible.
  double stroke = opt.stroke_px;
  if (!(stroke > 0)) {
    const double mean = segments.empty() ? size : length_sum / static_cast<double>(pairs.size());
    stroke = std::clamp(mean / 10, 0.05, 1.0);
  }

  std::string out;
  out.reserve(512 + segments.size() * 30 + std::min(inputs.size(), opt.max_marked_inputs) * 48);
  out +=
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"";
  out += pixels(total) + "\" height=\"" + pixels(total) + "\" viewBox=\"0 0 " + pixels(total) + ' ' + pixels(total) +
         "\">\n";
  out += "<title>dynmesh mesh: " + std::to_string(mesh.num_vertices()) + " vertices, " +
         std::to_string(mesh.num_triangles()) + " triangles, " + std::to_string(inputs.size()) +
         " input points</title>\n";
  out += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";

  const std::string path_end = "\" fill=\"none\" stroke=\"#404040\" stroke-width=\"" + pixels(stroke) +
                               "\" stroke-linecap=\"round\" stroke-linejoin=\"round\"/>\n";
  std::size_t in_path = 0;
  PixelPoint pen{std::numeric_limits<Centi>::min(), 0};
  for (const auto& [p, q] : segments) {
    if (in_path == 0) out += "<path d=\"";
    // Consecutive segments often start where the last one started; "M" is needed only when
    // the pen is elsewhere.
    if (!(pen == p)) {
      out += 'M';
      append_centi(out, p.x);
      out += ' ';
      append_centi(out, p.y);
    }
    out += 'L';
    append_centi(out, q.x);
    out += ' ';
    append_centi(out, q.y);
    pen = q;
    if (++in_path == kSegmentsPerPath) {
      out += path_end;
      in_path = 0;
      pen = PixelPoint{std::numeric_limits<Centi>::min(), 0};
    }
  }
  if (in_path != 0) out += path_end;

  // Input points as dots, each distinct quarter-pixel position once.
  if (!inputs.empty() && inputs.size() <= opt.max_marked_inputs) {
    std::vector<PixelPoint> dots;
    dots.reserve(inputs.size());
    for (const Point<2>& p : inputs) {
      const PixelPoint c = to_pixels(p);
      dots.push_back({(c.x + 12) / 25 * 25, (c.y + 12) / 25 * 25});  // snap to 0.25 px
    }
    std::sort(dots.begin(), dots.end());
    dots.erase(std::unique(dots.begin(), dots.end()), dots.end());
    out += "<g fill=\"#c0392b\">\n";
    const std::string radius = pixels(opt.point_radius_px);
    for (const PixelPoint& d : dots) {
      out += "<circle cx=\"";
      append_centi(out, d.x);
      out += "\" cy=\"";
      append_centi(out, d.y);
      out += "\" r=\"" + radius + "\"/>\n";
    }
    out += "</g>\n";
  }
  out += "</svg>\n";
  return out;
}

// ---- statistics ---------------------------------------------------------------------------

MeshStats mesh_stats(const Mesh& mesh) {
  MeshStats stats;
  stats.vertices = mesh.num_vertices();
  stats.triangles = mesh.num_triangles();
  if (mesh.triangles.empty()) return stats;
  constexpr double inf = std::numeric_limits<double>::infinity();
  stats.min_angle_deg = stats.shortest_edge = stats.smallest_area = inf;
  stats.max_angle_deg = stats.longest_edge = stats.largest_area = -inf;
  for (std::size_t t = 0; t < mesh.num_triangles(); ++t) {
    const Triangle tri = mesh.triangle(t);
    const auto& [a, b, c] = tri.v;
    // In a frame scaled by a power of two (exact), so that the products neither overflow in
    // a box near 1e300 nor underflow in one near 1e-300: the area is infinite or 0 only when
    // it is beyond the doubles' range itself.
    double ux = b[0] - a[0], uy = b[1] - a[1], vx = c[0] - a[0], vy = c[1] - a[1];
    const int e = detail::to_unit_frame(ux, uy, vx, vy);
    const double area = std::ldexp((ux * vy - uy * vx) / 2, 2 * e);
    stats.smallest_area = std::min(stats.smallest_area, area);
    stats.largest_area = std::max(stats.largest_area, area);
    for (int k = 0; k < 3; ++k) {
      const Point<2>& p = tri.v[k];
      const Point<2>& q = tri.v[(k + 1) % 3];
      const Point<2>& r = tri.v[(k + 2) % 3];
      const double edge = std::hypot(q[0] - p[0], q[1] - p[1]);  // no overflow or underflow
      stats.shortest_edge = std::min(stats.shortest_edge, edge);
      stats.longest_edge = std::max(stats.longest_edge, edge);
      const double angle = corner_angle_deg(p, q, r);
      stats.min_angle_deg = std::min(stats.min_angle_deg, angle);
      stats.max_angle_deg = std::max(stats.max_angle_deg, angle);
      const auto bin = static_cast<std::size_t>(std::clamp(angle / 10, 0.0, 17.0));
      ++stats.angle_histogram[bin];
    }
  }
  return stats;
}

namespace {

std::string readable(double x) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general, 6);
  return std::string(buf, r.ptr);
}

std::string pad_right(std::string s, std::size_t width) {
  if (s.size() < width) s.append(width - s.size(), ' ');
  return s;
}

std::string pad_left(std::string s, std::size_t width) {
  if (s.size() < width) s.insert(0, width - s.size(), ' ');
  return s;
}

}  // namespace

std::string format_stats(const MeshStats& s) {
  std::string out = "Mesh quality statistics:\n\n";
  out += "  Vertices: " + std::to_string(s.vertices) + "    Triangles: " + std::to_string(s.triangles) + "\n\n";
  auto row = [&](const char* left, double l, const char* right, double r) {
    out += "  " + pad_right(left, 16) + pad_right(readable(l), 14) + "|  " + pad_right(right, 16) + readable(r) + '\n';
  };
  row("Smallest area:", s.smallest_area, "Largest area:", s.largest_area);
  row("Shortest edge:", s.shortest_edge, "Longest edge:", s.longest_edge);
  row("Smallest angle:", s.min_angle_deg, "Largest angle:", s.max_angle_deg);
  out += "\n  Angle histogram:\n";
  auto bin = [&](std::size_t k) {
    return pad_left(std::to_string(10 * k), 7) + " - " + pad_left(std::to_string(10 * k + 10), 3) +
           " degrees: " + pad_left(std::to_string(s.angle_histogram[k]), 9);
  };
  for (std::size_t k = 0; k < 9; ++k) out += "  " + bin(k) + "    |" + bin(k + 9) + '\n';
  return out;
}

// ---- the change feed ----------------------------------------------------------------------

std::string feed_header() { return "# dynmesh feed v1\n"; }

std::string format_feed_update(std::size_t k, const MeshChange& change) {
  std::string out = "update ";
  append_number(out, k);
  out += " removed ";
  append_number(out, change.removed.size());
  out += " added ";
  append_number(out, change.added.size());
  append_line_end(out);
  auto triangle_line = [&](char sign, const Triangle& t) {
    out += sign;
    for (const Point<2>& p : t.v) {
      out += ' ';
      append_exact(out, p[0]);
      out += ' ';
      append_exact(out, p[1]);
    }
    append_line_end(out);
  };
  for (const Triangle& t : change.removed) triangle_line('-', t);
  for (const Triangle& t : change.added) triangle_line('+', t);
  return out;
}

}  // namespace dynmesh
