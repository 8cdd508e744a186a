// dynmesh/mesh_io.hpp — the text forms of a 2D mesh: files, feed, picture and statistics.
//
// Purpose: everything `dynmesh mesh` writes (docs/FORMATS.md, "`dynmesh mesh` (2D)"), as pure
// functions from values to strings (the feed's updates also appended to a caller's string, so
// that a stream of them reuses one); the caller writes files (aside, then renamed).
//   .node / .ele  Triangle's formats, numbered from 1 in the canonical order of a Mesh;
//                 coordinates %.17g (they round-trip exactly); node marker 1 on the box
//                 boundary (x == o1, x == fl(o1+L), y == o2 or y == fl(o2+L)), else 0.
//   .vtk          legacy VTK ASCII, UNSTRUCTURED_GRID, POINTS double with z = 0, cell type 5.
//   .msh          Gmsh 2.2 ASCII: $MeshFormat 2.2 0 8, $Nodes (z = 0), $Elements of type 2
//                 with two tags (physical group 1, elementary entity 1).
//   .svg          a picture that stays readable at 10^5 triangles: y up, each edge drawn once,
//                 edges batched into a few <path> elements, strokes sized to the picture.
//   feed          "# dynmesh feed v1", then per update "update k removed r added a" and the
//                 "- ..." then "+ ..." lines of six %.17g corner coordinates.
//   stats         Triangle's -V style quality report: counts, angle, edge and area extremes,
//                 an angle histogram in 10-degree bins.
// Every line ends in '\n'; numbers that must round-trip use format_exact (%.17g, C locale).
//
// Invariants: each format_* depends only on its arguments; append_feed_update(out, k, c)
// appends exactly format_feed_update(k, c); read_node_ele(format_node(m, b), format_ele(m)) == m
// for every Mesh m.
// Complexity: linear in the mesh for the text formats; format_svg O(t log t) (edges are
// sorted to draw each once); read_node_ele linear in the text.
// Paper: none (Triangle's .node/.ele and -V report; VTK's legacy format; Gmsh's MSH 2.2).
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string>

#include "dynmesh/box.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh {

/// `<#vertices> 2 0 1`, then `<i> <x> <y> <marker>` for i from 1.
std::string format_node(const Mesh& mesh, const Box<2>& box);
/// `<#triangles> 3 0`, then `<i> <a> <b> <c>`: 1-based vertex numbers, counter-clockwise.
std::string format_ele(const Mesh& mesh);
/// Legacy VTK (version 3.0) ASCII unstructured grid of triangles (cell type 5).
std::string format_vtk(const Mesh& mesh);
/// Gmsh MSH 2.2 ASCII with 3-node triangles (element type 2).
std::string format_msh(const Mesh& mesh);

/// Parses the output of format_node and format_ele (and Triangle's own files: numbering from
/// 0 or 1, `#` comments, attributes and markers ignored) back into a Mesh, in file order,
/// not re-canonicalized. InputError (Malformed, Count, NotFinite: also a number beyond the
/// range of double) naming "node" or "ele" and the line otherwise.
Mesh read_node_ele(const std::string& node_text, const std::string& ele_text);

struct SvgMeshOptions {
  double width_px = 1000.0;  // side of the square drawing of the box, in pixels
  double margin_px = 10.0;   // blank border around it
  double stroke_px = 0.0;    // edge width; 0 picks one from the mean edge length on screen
  double point_radius_px = 1.5;
  std::size_t max_marked_inputs = 20000;  // more input points than this: none are marked
};

/// The SVG document of the mesh in `box` with `inputs` marked as dots.
std::string format_svg(const Mesh& mesh, const Box<2>& box, std::span<const Point<2>> inputs,
                       const SvgMeshOptions& options = {});

/// Quality figures over all triangles; angles as corner_angle_deg (mesh_check.hpp) computes
/// them. All zero for an empty mesh.
struct MeshStats {
  std::size_t vertices = 0;
  std::size_t triangles = 0;
  double min_angle_deg = 0, max_angle_deg = 0;
  double shortest_edge = 0, longest_edge = 0;
  double smallest_area = 0, largest_area = 0;
  /// Every angle of every triangle: bin k counts angles in [10k, 10k + 10) degrees, and
  /// 180 degrees falls in bin 17.
  std::array<std::size_t, 18> angle_histogram{};
};

MeshStats mesh_stats(const Mesh& mesh);
/// A readable multi-line report of the statistics (numbers to 6 significant digits).
std::string format_stats(const MeshStats& stats);

/// "# dynmesh feed v1\n".
std::string feed_header();
/// `update <k> removed <r> added <a>`, then one `- x1 y1 x2 y2 x3 y3` line per removed
/// triangle and one `+ ...` line per added one, in the change's (sorted) order.
std::string format_feed_update(std::size_t k, const MeshChange& change);
/// format_feed_update's text appended to `out`: a caller that streams the feed reuses one
/// string for every update instead of allocating one per update.
void append_feed_update(std::string& out, std::size_t k, const MeshChange& change);

}  // namespace dynmesh
