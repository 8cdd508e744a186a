// SVG drawing of a 2D quadtree (see dynmesh/svg.hpp for the drawing rules).
#include "dynmesh/svg.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "dynmesh/cell.hpp"
#include "dynmesh/errors.hpp"

namespace dynmesh {
namespace {

// A pixel coordinate with two decimals and no trailing zeros ("12.5", "3", "0.25").
std::string px(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, 2);
  std::string s(buf, r.ptr);
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

// The finest level whose cells are at least min_px wide (0 when even the root is narrower).
int finest_visible_level(double size_px, double min_px) {
  int level = 0;
  while (level < kMaxLevel && size_px / static_cast<double>(cells_per_axis(level + 1)) >= min_px) ++level;
  return level;
}

// Path segments per <path> element: keeps each attribute a manageable size for viewers.
constexpr std::size_t kSegmentsPerPath = 8192;

}  // namespace

double default_point_radius_px(std::size_t points, double size_px, double largest_px) {
  const double floor_px = std::min(0.25, largest_px);
  if (points == 0) return largest_px;
  return std::clamp(0.1 * size_px / std::sqrt(static_cast<double>(points)), floor_px, largest_px);
}

void write_svg(std::ostream& out, const Box<2>& box, std::span<const Leaf<2>> leaves,
               std::span<const Point<2>> points, const SvgOptions& opt) {
  const double size = opt.size_px, margin = opt.margin_px;
  const double total = size + 2 * margin;
  const int visible = finest_visible_level(size, opt.min_cell_px);
  const bool draw_points = points.size() <= opt.max_points;

  // Tiles: leaves at visible levels, and the level-`visible` ancestors of finer leaves
  // (blocks). Together they still tile the box. Sorted so the output ignores input order.
  std::vector<CellId<2>> tiles, blocks;
  tiles.reserve(leaves.size());
  for (const Leaf<2>& leaf : leaves) {
    if (leaf.cell.level <= visible)
      tiles.push_back(leaf.cell);
    else
      blocks.push_back(ancestor(leaf.cell, visible));
  }
  std::sort(blocks.begin(), blocks.end());
  blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
  tiles.insert(tiles.end(), blocks.begin(), blocks.end());
  std::sort(tiles.begin(), tiles.end());
  tiles.erase(std::unique(tiles.begin(), tiles.end()), tiles.end());

  // Cell (l, i, j) in pixels: x from margin + i·w, y (pointing down) from the top of row j.
  auto cell_x = [&](const CellId<2>& c, std::uint64_t i) {
    return margin + static_cast<double>(i) * (size / static_cast<double>(cells_per_axis(c.level)));
  };
  auto cell_y = [&](const CellId<2>& c, std::uint64_t j) {
    return margin + size - static_cast<double>(j) * (size / static_cast<double>(cells_per_axis(c.level)));
  };

  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" << px(total) << "\" height=\""
      << px(total) << "\" viewBox=\"0 0 " << px(total) << ' ' << px(total) << "\">\n"
      << "<title>dynmesh quadtree: " << leaves.size() << " leaves, " << points.size() << " points"
      << (draw_points ? "" : " (not drawn: more than " + std::to_string(opt.max_points) + ")") << "</title>\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";

  if (!blocks.empty()) {
    out << "<g fill=\"#c8c8c8\">\n";
    for (const CellId<2>& b : blocks) {
      const double x0 = cell_x(b, b.index[0]), x1 = cell_x(b, b.index[0] + 1);
      const double ytop = cell_y(b, b.index[1] + 1), ybot = cell_y(b, b.index[1]);
      out << "<rect x=\"" << px(x0) << "\" y=\"" << px(ytop) << "\" width=\"" << px(x1 - x0) << "\" height=\""
          << px(ybot - ytop) << "\"/>\n";
    }
    out << "</g>\n";
  }

  // Left and top edge of every tile; the box outline closes the right and bottom sides.
  std::size_t in_path = 0;
  const std::string path_attrs = "\" fill=\"none\" stroke=\"#404040\" stroke-width=\"" + px(opt.stroke_px) + "\"/>\n";
  for (const CellId<2>& c : tiles) {
    if (c.level == 0) continue;  // the root's edges are the box outline
    if (in_path == 0) out << "<path d=\"";
    const double x0 = cell_x(c, c.index[0]), x1 = cell_x(c, c.index[0] + 1);
    const double ytop = cell_y(c, c.index[1] + 1), ybot = cell_y(c, c.index[1]);
    out << 'M' << px(x0) << ' ' << px(ybot) << 'V' << px(ytop) << 'H' << px(x1);
    if (++in_path == kSegmentsPerPath) {
      out << path_attrs;
      in_path = 0;
    }
  }
  if (in_path != 0) out << path_attrs;
  out << "<rect x=\"" << px(margin) << "\" y=\"" << px(margin) << "\" width=\"" << px(size) << "\" height=\""
      << px(size) << "\" fill=\"none\" stroke=\"#404040\" stroke-width=\"" << px(2 * opt.stroke_px) << "\"/>\n";

  // Points on a quarter-pixel grid, each distinct dot once; none above max_points.
  std::vector<std::pair<std::int64_t, std::int64_t>> dots;
  if (draw_points) dots.reserve(points.size());
  const double per_unit = size / box.side;
  for (const Point<2>& p : draw_points ? points : std::span<const Point<2>>{}) {
    const double x = margin + (p[0] - box.origin[0]) * per_unit;
    const double y = margin + size - (p[1] - box.origin[1]) * per_unit;
    if (!std::isfinite(x) || !std::isfinite(y) || std::abs(x) > 1e9 || std::abs(y) > 1e9) continue;
    dots.emplace_back(std::llround(x * 4), std::llround(y * 4));
  }
  std::sort(dots.begin(), dots.end());
  dots.erase(std::unique(dots.begin(), dots.end()), dots.end());
  if (!dots.empty()) {
    out << "<g fill=\"#c0392b\">\n";
    const double radius =
        opt.point_radius_px > 0 ? opt.point_radius_px : default_point_radius_px(points.size(), size, 1.0);
    const std::string r = px(radius);
    for (const auto& [x4, y4] : dots)
      out << "<circle cx=\"" << px(static_cast<double>(x4) / 4) << "\" cy=\"" << px(static_cast<double>(y4) / 4)
          << "\" r=\"" << r << "\"/>\n";
    out << "</g>\n";
  }
  out << "</svg>\n";
}

void write_svg_file(const std::string& path, const Box<2>& box, std::span<const Leaf<2>> leaves,
                    std::span<const Point<2>> points, const SvgOptions& options) {
  std::ofstream out(path, std::ios::binary);
  if (!out)
    throw InputError(InputError::Kind::Io, std::string("cannot open file for writing: ") + std::strerror(errno),
                     path);
  write_svg(out, box, leaves, points, options);
  out.flush();
  if (!out) throw InputError(InputError::Kind::Io, "write error", path);
}

}  // namespace dynmesh
