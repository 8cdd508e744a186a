// dynmesh/svg.hpp — a picture of a 2D quadtree and its points as SVG.
//
// Purpose: `dynmesh quadtree --svg` and `dynmesh demo` draw the leaves of the final tree
// (thin outlines) and the input points (dots), so that a person can see the grading and the
// refinement around clusters. The box [o, o+L]^2 maps onto a square viewport of
// `size_px` pixels plus a margin, with the y axis pointing up (mathematical orientation, as
// in the input coordinates).
//
// Drawing, kept small for large trees:
//   * Outlines: each leaf draws only its left and top edges, as one path segment
//     "M x,bottom V top H right", and the box outline is drawn once. Leaves tile the box, so
//     every right or bottom edge of a leaf is covered by the left or top edges of the
//     leaves beyond it (or lies on the box outline): the union is the full set of outlines.
//   * Cells narrower than `min_cell_px` cannot be told apart on screen; such a leaf is drawn
//     as its ancestor at the finest level whose width is still ≥ min_cell_px, filled grey
//     (each such block once), so a deep cluster costs a bounded number of elements.
//   * Points snap to a quarter-pixel grid and coinciding dots are drawn once. On dense inputs
//     the dots shrink (default_point_radius_px: a tenth of the spacing of evenly spread
//     points, 1 px down to 0.25 px), and above `max_points` points none are drawn: a solid
//     cloud of dots would hide the tree it is meant to explain.
// Numbers are printed with std::to_chars (locale-independent), two decimals.
//
// Invariants: the output is a complete, well-formed SVG 1.1 document (starting with
// "<?xml"); it depends only on its arguments (leaf and point order do not matter).
// Complexity: O(|leaves| lg |leaves| + |points| lg |points|) (sorting makes the output
// independent of input order and does the dedup); output size
// O(min(|leaves|, (size_px / min_cell_px)^2) + min(|points|, (4·size_px)^2, max_points)).
// Paper: none (a drawing aid for the quadtree of Acar & Hudson, Section 2).
#pragma once

#include <cstddef>
#include <iosfwd>
#include <span>
#include <string>

#include "dynmesh/box.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace dynmesh {

/// More points than this are not drawn by default (the `dynmesh` command's --svg-max-points).
inline constexpr std::size_t kSvgMaxPoints = 20000;

struct SvgOptions {
  double size_px = 1000.0;        // side of the square drawing of the box, in pixels
  double margin_px = 10.0;        // blank border around it
  double min_cell_px = 0.5;       // finer leaves are merged into filled blocks of this size
  double point_radius_px = 0.0;   // dot radius; 0: default_point_radius_px(|points|, size_px, 1)
  double stroke_px = 0.4;         // outline width
  std::size_t max_points = kSvgMaxPoints;  // more points than this: no dots at all
};

/// The dot radius in pixels for `points` dots in a drawing `size_px` wide: a tenth of the
/// spacing of as many points spread evenly (size_px / sqrt(points)), so that dots stay apart
/// where the points do, within [0.25, largest_px] (0.25: the grid the dots snap to). For
/// 1000 px: 1 px up to 10^4 points (largest_px 1), 0.32 px at 10^5, 0.25 px from 1.6·10^5.
double default_point_radius_px(std::size_t points, double size_px, double largest_px);

/// Writes the SVG document for the leaves (any order) and points of a 2D tree in `box`.
/// Points outside the box are drawn where they fall (they are not clipped).
void write_svg(std::ostream& out, const Box<2>& box, std::span<const Leaf<2>> leaves,
               std::span<const Point<2>> points, const SvgOptions& options = {});

/// write_svg to `path`; InputError(Io) when the file cannot be written.
void write_svg_file(const std::string& path, const Box<2>& box, std::span<const Leaf<2>> leaves,
                    std::span<const Point<2>> points, const SvgOptions& options = {});

}  // namespace dynmesh
