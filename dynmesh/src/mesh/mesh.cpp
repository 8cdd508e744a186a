// The canonical mesh and the change feed's application (see dynmesh/mesh.hpp).
#include "dynmesh/mesh.hpp"

#include "mesh/sorted_change.hpp"

#include <algorithm>
#include <cstddef>

namespace dynmesh {
namespace {

// Rotates a counter-clockwise index triple to start at its smallest index: a rotation keeps
// the orientation, a reflection would not.
std::array<std::uint32_t, 3> rotate_to_smallest(std::uint32_t a, std::uint32_t b, std::uint32_t c) noexcept {
  if (b < a && b <= c) return {b, c, a};
  if (c < a && c < b) return {c, a, b};
  return {a, b, c};
}

}  // namespace

Mesh make_mesh(std::span<const Triangle> triangles) {
  // Every corner with its slot (3·triangle + corner), sorted by (x, y): one pass then both
  // numbers the distinct points and tells each slot its vertex, with no searching.
  struct Corner {
    Point<2> p;
    std::size_t slot;
  };
  std::vector<Corner> corners;
  corners.reserve(3 * triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) corners.push_back({triangles[t].v[k], 3 * t + k});
  std::sort(corners.begin(), corners.end(), [](const Corner& l, const Corner& r) { return xy_less(l.p, r.p); });

  Mesh mesh;
  std::vector<std::uint32_t> vertex_of(corners.size());
  for (std::size_t i = 0; i < corners.size(); ++i) {
    if (i == 0 || xy_less(corners[i - 1].p, corners[i].p)) mesh.vertices.push_back(corners[i].p);
    vertex_of[corners[i].slot] = static_cast<std::uint32_t>(mesh.vertices.size() - 1);
  }
  corners = {};

  mesh.triangles.reserve(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    mesh.triangles.push_back(rotate_to_smallest(vertex_of[3 * t], vertex_of[3 * t + 1], vertex_of[3 * t + 2]));
  std::sort(mesh.triangles.begin(), mesh.triangles.end());
  return mesh;
}

std::vector<Triangle> triangles_of(const Mesh& mesh) {
  std::vector<Triangle> out;
  out.reserve(mesh.num_triangles());
  // Index order is (x, y) order, so a canonical index triple gives a canonical Triangle and
  // the sorted triples give sorted Triangles.
  for (std::size_t i = 0; i < mesh.num_triangles(); ++i) out.push_back(mesh.triangle(i));
  return out;
}

bool apply_change(std::vector<Triangle>& tris, const MeshChange& change) {
  return detail::apply_sorted_change(tris, change);
}

}  // namespace dynmesh
