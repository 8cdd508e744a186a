// The text forms of a 2D mesh (see dynmesh/mesh_io.hpp for the formats).
#include "dynmesh/mesh_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "dynmesh/mesh_check.hpp"
#include "geometry/powers_of_two.hpp"
#include "io/mesh_text.hpp"

namespace dynmesh {

// ---- Triangle's .node / .ele --------------------------------------------------------------

std::string format_node(const Mesh& mesh, const Box<2>& box) {
  return detail::node_text<2>(mesh.vertices, box);
}

std::string format_ele(const Mesh& mesh) { return detail::ele_text<3>(mesh.triangles); }

// ---- VTK and Gmsh -------------------------------------------------------------------------

std::string format_vtk(const Mesh& mesh) {
  return detail::vtk_text<2, 3>(mesh.vertices, mesh.triangles, 5);  // VTK_TRIANGLE
}

std::string format_msh(const Mesh& mesh) {
  return detail::msh_text<2, 3>(mesh.vertices, mesh.triangles, 2);  // 3-node triangle
}

// ---- reading .node / .ele back ------------------------------------------------------------

Mesh read_node_ele(const std::string& node_text, const std::string& ele_text) {
  Mesh mesh;
  detail::read_node_ele_text<2, 3>(node_text, ele_text, {"triangle", "triangles"}, mesh.vertices, mesh.triangles);
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
  detail::append_number(out, static_cast<std::size_t>(c / 100));
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
      ++stats.angle_histogram[detail::angle_bin(angle)];
    }
  }
  return stats;
}

std::string format_stats(const MeshStats& s) {
  std::string out = "Mesh quality statistics:\n\n";
  out += "  Vertices: " + std::to_string(s.vertices) + "    Triangles: " + std::to_string(s.triangles) + "\n\n";
  detail::append_stats_row(out, "Smallest area:", s.smallest_area, "Largest area:", s.largest_area);
  detail::append_stats_row(out, "Shortest edge:", s.shortest_edge, "Longest edge:", s.longest_edge);
  detail::append_stats_row(out, "Smallest angle:", s.min_angle_deg, "Largest angle:", s.max_angle_deg);
  out += "\n  Angle histogram:\n";
  detail::append_angle_histogram(out, s.angle_histogram);
  return out;
}

// ---- the change feed ----------------------------------------------------------------------

std::string feed_header() { return "# dynmesh feed v1\n"; }

std::string format_feed_update(std::size_t k, const MeshChange& change) {
  std::string out;
  append_feed_update(out, k, change);
  return out;
}

void append_feed_update(std::string& out, std::size_t k, const MeshChange& change) {
  detail::append_feed_update_text<Triangle>(out, k, change.removed, change.added);
}

}  // namespace dynmesh
