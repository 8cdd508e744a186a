// mesh_text_parts.cpp — the pieces of .node, .ele and the feed (dynmesh/mesh_text_parts.hpp),
// over the templates that format_node, format_ele and append_feed_update use (mesh_text.hpp).
#include "dynmesh/mesh_text_parts.hpp"

#include <stdexcept>

#include "io/mesh_text.hpp"

namespace dynmesh {

void append_node_header(std::string& out, std::size_t vertices, std::size_t dim) {
  if (dim == 2) return detail::append_node_header<2>(out, vertices);
  if (dim == 3) return detail::append_node_header<3>(out, vertices);
  throw std::invalid_argument("dynmesh: append_node_header: dimension 2 or 3");
}

void append_node_lines(std::string& out, std::size_t first, std::span<const Point<2>> vertices, const Box<2>& box) {
  detail::append_node_lines<2>(out, first, vertices, box);
}
void append_node_lines(std::string& out, std::size_t first, std::span<const Point<3>> vertices, const Box<3>& box) {
  detail::append_node_lines<3>(out, first, vertices, box);
}

void append_ele_header(std::string& out, std::size_t cells, std::size_t corners) {
  if (corners == 3) return detail::append_ele_header<3>(out, cells);
  if (corners == 4) return detail::append_ele_header<4>(out, cells);
  throw std::invalid_argument("dynmesh: append_ele_header: 3 or 4 corners");
}

void append_ele_lines(std::string& out, std::size_t first, std::span<const std::array<std::uint64_t, 3>> cells) {
  detail::append_ele_lines<3, std::uint64_t>(out, first, cells);
}
void append_ele_lines(std::string& out, std::size_t first, std::span<const std::array<std::uint64_t, 4>> cells) {
  detail::append_ele_lines<4, std::uint64_t>(out, first, cells);
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
