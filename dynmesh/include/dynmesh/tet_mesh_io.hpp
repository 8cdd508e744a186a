// dynmesh/tet_mesh_io.hpp — the text forms of a 3D (tetrahedral) mesh: files, feed and
// statistics.
//
// Purpose: everything `dynmesh mesh` writes in 3D (docs/FORMATS.md, "`dynmesh mesh` in 3D"), as
// pure functions from values to strings, overloads of mesh_io.hpp's 2D writers; the caller
// writes files (aside, then renamed).
//   .node / .ele  TetGen's formats, numbered from 1 in the canonical order of a TetMesh;
//                 coordinates %.17g (they round-trip exactly); node marker 1 on the box
//                 boundary (a coordinate equal to o_a or fl(o_a + L) on some axis a), else 0;
//                 tetrahedra positively oriented, in tet_mesh.hpp's canonical rotation.
//   .vtk          legacy VTK ASCII, UNSTRUCTURED_GRID, POINTS double, cell type 10 (VTK_TETRA).
//   .msh          Gmsh 2.2 ASCII: $MeshFormat 2.2 0 8, $Nodes, $Elements of type 4 (4-node
//                 tetrahedron) with two tags (physical group 1, elementary entity 1).
//   feed          after feed_header() (mesh_io.hpp), per update "update k removed r added a"
//                 and the "- ..." then "+ ..." lines of twelve %.17g corner coordinates, the
//                 corners in the canonical rotation.
//   stats         a -V style quality report: counts, tetrahedra per input point, dihedral
//                 angle, radius-edge, edge and volume extremes, a dihedral angle histogram
//                 in 10-degree bins.
// Every line ends in '\n'; the 2D and 3D forms come from one template each, so they agree in
// layout and number formatting.
//
// Invariants: each format_* depends only on its arguments; read_tet_node_ele(format_node(m,
// b), format_ele(m)) == m for every TetMesh m.
// Complexity: linear in the mesh for every function; read_tet_node_ele linear in the text.
// Paper: none (TetGen's .node/.ele; VTK's legacy format; Gmsh's MSH 2.2).
#pragma once

#include <array>
#include <cstddef>
#include <string>

#include "dynmesh/box.hpp"
#include "dynmesh/mesh_io.hpp"
#include "dynmesh/tet_mesh.hpp"

namespace dynmesh {

/// `<#vertices> 3 0 1`, then `<i> <x> <y> <z> <marker>` for i from 1.
std::string format_node(const TetMesh& mesh, const Box<3>& box);
/// `<#tetrahedra> 4 0`, then `<i> <a> <b> <c> <d>`: 1-based vertex numbers, positively
/// oriented (det(b − a, c − a, d − a) > 0).
std::string format_ele(const TetMesh& mesh);
/// Legacy VTK (version 3.0) ASCII unstructured grid of tetrahedra (cell type 10).
std::string format_vtk(const TetMesh& mesh);
/// Gmsh MSH 2.2 ASCII with 4-node tetrahedra (element type 4).
std::string format_msh(const TetMesh& mesh);

/// Parses the output of the 3D format_node and format_ele (and TetGen's own files: numbering
/// from 0 or 1, `#` comments, attributes and markers ignored) back into a TetMesh, in file
/// order, not re-canonicalized. InputError (Malformed, Count, NotFinite: also a number beyond
/// the range of double) naming "node" or "ele" and the line otherwise; a file of dimension
/// other than 3, or of 10-node tetrahedra, is Malformed.
TetMesh read_tet_node_ele(const std::string& node_text, const std::string& ele_text);

/// Quality figures over all tetrahedra; dihedral angles and radius-edge ratios as
/// tet_mesh_check.hpp computes them. All zero for an empty mesh.
struct TetMeshStats {
  std::size_t vertices = 0;
  std::size_t tetrahedra = 0;
  double min_dihedral_deg = 0, max_dihedral_deg = 0;
  double max_radius_edge_ratio = 0;  // +infinity when a tetrahedron is flat
  double shortest_edge = 0, longest_edge = 0;
  double smallest_volume = 0, largest_volume = 0;  // signed: negative for an inverted one
  /// Every dihedral angle of every tetrahedron (six each): bin k counts angles in
  /// [10k, 10k + 10) degrees, and 180 degrees falls in bin 17. An angle computed within
  /// 1e-9 degrees below 10k counts as 10k (an exact 60 may come out an ulp short of it).
  std::array<std::size_t, 18> dihedral_histogram{};
};

TetMeshStats tet_mesh_stats(const TetMesh& mesh);
/// A readable multi-line report of the statistics (numbers to 6 significant digits), with
/// the tetrahedra per input point for `num_inputs` input points (left out when 0).
std::string format_stats(const TetMeshStats& stats, std::size_t num_inputs);

/// `update <k> removed <r> added <a>`, then one `- x1 y1 z1 x2 y2 z2 x3 y3 z3 x4 y4 z4` line
/// per removed tetrahedron and one `+ ...` line per added one, in the change's (sorted) order,
/// each tetrahedron's corners in its canonical rotation.
std::string format_feed_update(std::size_t k, const TetMeshChange& change);
/// format_feed_update's text appended to `out` (mesh_io.hpp's 2D twin says why).
void append_feed_update(std::string& out, std::size_t k, const TetMeshChange& change);

}  // namespace dynmesh
