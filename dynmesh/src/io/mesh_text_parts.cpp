// mesh_text_parts.cpp — the parts of the mesh files and the feed (dynmesh/mesh_text_parts.hpp),
// over the templates that format_node, format_ele, format_vtk, format_msh and
// append_feed_update use (mesh_text.hpp).
#include "dynmesh/mesh_text_parts.hpp"

#include <stdexcept>

#include "io/mesh_text.hpp"

namespace dynmesh {
namespace {

/// VTK's and MSH's type numbers: triangles 5 and 2, tetrahedra 10 and 4.
int vtk_type(std::size_t corners) { return corners == 3 ? 5 : 10; }
int msh_type(std::size_t corners) { return corners == 3 ? 2 : 4; }

template <std::size_t d>
void vertex_lines(std::string& out, MeshFile file, std::size_t first, std::span<const Point<d>> v, const Box<d>& box) {
  switch (file) {
    case MeshFile::Node: return detail::append_node_lines<d>(out, first, v, box);
    case MeshFile::Vtk: return detail::append_vtk_point_lines<d>(out, v);
    case MeshFile::Msh: return detail::append_msh_node_lines<d>(out, first, v);
    case MeshFile::Ele: return;
  }
}

template <std::size_t k>
void cell_lines(std::string& out, MeshFile file, std::size_t first, std::span<const std::array<std::uint64_t, k>> c) {
  switch (file) {
    case MeshFile::Ele: return detail::append_ele_lines<k, std::uint64_t>(out, first, c);
    case MeshFile::Vtk: return detail::append_vtk_cell_lines<k, std::uint64_t>(out, c);
    case MeshFile::Msh: return detail::append_msh_element_lines<k, std::uint64_t>(out, first, c, msh_type(k));
    case MeshFile::Node: return;
  }
}

}  // namespace

void append_vertices_head(std::string& out, MeshFile file, std::size_t vertices, std::size_t dim) {
  if (dim != 2 && dim != 3) throw std::invalid_argument("dynmesh: append_vertices_head: dimension 2 or 3");
  switch (file) {
    case MeshFile::Node:
      return dim == 2 ? detail::append_node_header<2>(out, vertices) : detail::append_node_header<3>(out, vertices);
    case MeshFile::Vtk: return detail::append_vtk_points_head(out, vertices);
    case MeshFile::Msh: return detail::append_msh_nodes_head(out, vertices);
    case MeshFile::Ele: return;
  }
}

void append_vertex_lines(std::string& out, MeshFile file, std::size_t first, std::span<const Point<2>> vertices,
                         const Box<2>& box) {
  vertex_lines<2>(out, file, first, vertices, box);
}
void append_vertex_lines(std::string& out, MeshFile file, std::size_t first, std::span<const Point<3>> vertices,
                         const Box<3>& box) {
  vertex_lines<3>(out, file, first, vertices, box);
}

void append_cells_head(std::string& out, MeshFile file, std::size_t cells, std::size_t corners) {
  if (corners != 3 && corners != 4) throw std::invalid_argument("dynmesh: append_cells_head: 3 or 4 corners");
  switch (file) {
    case MeshFile::Ele:
      return corners == 3 ? detail::append_ele_header<3>(out, cells) : detail::append_ele_header<4>(out, cells);
    case MeshFile::Vtk:
      return corners == 3 ? detail::append_vtk_cells_head<3>(out, cells) : detail::append_vtk_cells_head<4>(out, cells);
    case MeshFile::Msh: return detail::append_msh_elements_head(out, cells);
    case MeshFile::Node: return;
  }
}

void append_cell_lines(std::string& out, MeshFile file, std::size_t first,
                       std::span<const std::array<std::uint64_t, 3>> cells) {
  cell_lines<3>(out, file, first, cells);
}
void append_cell_lines(std::string& out, MeshFile file, std::size_t first,
                       std::span<const std::array<std::uint64_t, 4>> cells) {
  cell_lines<4>(out, file, first, cells);
}

void append_file_tail(std::string& out, MeshFile file, std::size_t cells, std::size_t corners) {
  if (file == MeshFile::Vtk) detail::append_vtk_cell_types(out, cells, vtk_type(corners));
  if (file == MeshFile::Msh) detail::append_msh_end(out);
}

void append_feed_head(std::string& out, std::size_t k, std::size_t removed, std::size_t added) {
  detail::append_feed_head(out, k, removed, added);
}
void append_feed_lines(std::string& out, char sign, std::span<const Triangle> simplices) {
  detail::append_simplex_lines<Triangle>(out, sign, simplices);
}
void append_feed_lines(std::string& out, char sign, std::span<const Tetrahedron> simplices) {
  detail::append_simplex_lines<Tetrahedron>(out, sign, simplices);
}

}  // namespace dynmesh
