// dynmesh/mesh_text_parts.hpp — the files of a mesh written in parts, for writers that stream.
//
// Purpose: a writer that never holds the whole mesh (dynmesh-mpi's rank 0, merging the
// ranks' sorted parts) writes `.node`, `.ele`, VTK, MSH and the change feed piece by piece,
// with exactly the bytes of mesh_io.hpp's and tet_mesh_io.hpp's format_* and
// append_feed_update, which are built from the same pieces. Each mesh file is five parts in
// order: the vertices' head, the vertex lines, the cells' head, the cell lines, the tail
// (parts a format does not have append nothing: `.ele` lists no vertices, `.node` no cells).
// Vertices come in the canonical order (numbered from 0 here), cells as canonical index
// tuples in sorted order; `first` is the number of vertices or cells written before the run.
// Invariants: for a canonical mesh m, the five parts over any split of m's vertices and cells
// into consecutive runs give format_node(m, box), format_ele(m), format_vtk(m) and
// format_msh(m); the feed head followed by the '-' and then the '+' runs of a change gives
// append_feed_update.
// Complexity: linear in what is appended.
// Paper: none (Triangle's and TetGen's .node/.ele; VTK's legacy format; Gmsh's MSH 2.2; the
// feed of docs/FORMATS.md).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "dynmesh/box.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/tet_mesh.hpp"

namespace dynmesh {

enum class MeshFile { Node, Ele, Vtk, Msh };

/// The vertices' head (`.node`: `<#vertices> d 0 1`).
void append_vertices_head(std::string& out, MeshFile file, std::size_t vertices, std::size_t dim);
/// A line per vertex (`.node`: `<i> <coordinates> <marker>`, marker 1 on the box's boundary).
void append_vertex_lines(std::string& out, MeshFile file, std::size_t first, std::span<const Point<2>> vertices,
                         const Box<2>& box);
void append_vertex_lines(std::string& out, MeshFile file, std::size_t first, std::span<const Point<3>> vertices,
                         const Box<3>& box);
/// The cells' head (`.ele`: `<#cells> k 0`; k = `corners`, 3 or 4).
void append_cells_head(std::string& out, MeshFile file, std::size_t cells, std::size_t corners);
/// A line per cell (`.ele`: `<i> <v1> ... <vk>` from 1).
void append_cell_lines(std::string& out, MeshFile file, std::size_t first,
                       std::span<const std::array<std::uint64_t, 3>> cells);
void append_cell_lines(std::string& out, MeshFile file, std::size_t first,
                       std::span<const std::array<std::uint64_t, 4>> cells);
/// What follows the cells (VTK: the cell types; MSH: `$EndElements`).
void append_file_tail(std::string& out, MeshFile file, std::size_t cells, std::size_t corners);

/// `update <k> removed <r> added <a>`.
void append_feed_head(std::string& out, std::size_t k, std::size_t removed, std::size_t added);
/// One `sign ...` line per simplex, its corners' coordinates in its canonical order (sign:
/// '-' removed, '+' added).
void append_feed_lines(std::string& out, char sign, std::span<const Triangle> simplices);
void append_feed_lines(std::string& out, char sign, std::span<const Tetrahedron> simplices);

}  // namespace dynmesh
