// dynmesh/mesh_text_parts.hpp — the files of a mesh written in parts: headers, runs of lines.
//
// Purpose: a writer that streams a mesh it never holds whole (dynmesh-mpi's rank 0, merging
// the ranks' sorted parts) writes `.node`, `.ele` and the change feed piece by piece, with
// exactly the bytes of mesh_io.hpp's and tet_mesh_io.hpp's format_node, format_ele and
// append_feed_update, which are built from these same pieces.
// Invariants: for a canonical mesh m, append_node_header(n) followed by append_node_lines
// over consecutive runs of m's vertices (first = the run's offset) is format_node(m, box);
// likewise for .ele and for one feed update (head, then the '-' runs, then the '+' runs).
// Complexity: linear in what is appended.
// Paper: none (Triangle's and TetGen's .node/.ele; the feed of docs/FORMATS.md).
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

/// `<#vertices> d 0 1`.
void append_node_header(std::string& out, std::size_t vertices, std::size_t dim);
/// `<i> <coordinates> <marker>` for each vertex, i from first + 1 (marker 1 on the box's
/// boundary).
void append_node_lines(std::string& out, std::size_t first, std::span<const Point<2>> vertices, const Box<2>& box);
void append_node_lines(std::string& out, std::size_t first, std::span<const Point<3>> vertices, const Box<3>& box);

/// `<#cells> k 0` (k = 3: triangles, 4: tetrahedra).
void append_ele_header(std::string& out, std::size_t cells, std::size_t corners);
/// `<i> <v1> ... <vk>` for each cell, i from first + 1; the vertex numbers are 0-based here
/// and written from 1.
void append_ele_lines(std::string& out, std::size_t first, std::span<const std::array<std::uint64_t, 3>> cells);
void append_ele_lines(std::string& out, std::size_t first, std::span<const std::array<std::uint64_t, 4>> cells);

/// `update <k> removed <r> added <a>`.
void append_feed_head(std::string& out, std::size_t k, std::size_t removed, std::size_t added);
/// One `sign ...` line per simplex, its corners' coordinates in its canonical order (sign:
/// '-' removed, '+' added).
void append_feed_lines(std::string& out, char sign, std::span<const Triangle> simplices);
void append_feed_lines(std::string& out, char sign, std::span<const Tetrahedron> simplices);

}  // namespace dynmesh
