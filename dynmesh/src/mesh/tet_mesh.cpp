// The canonical tetrahedral mesh and the change feed's application (see dynmesh/tet_mesh.hpp).
#include "dynmesh/tet_mesh.hpp"

#include <algorithm>
#include <cstddef>
#include <functional>

#include "mesh/sorted_change.hpp"

namespace dynmesh {

TetMesh make_tet_mesh(std::span<const Tetrahedron> tetrahedra) {
  // Every corner with its slot (4·tetrahedron + corner), sorted by (x, y, z): one pass numbers
  // the distinct points and tells each slot its vertex.
  struct Corner {
    Point<3> p;
    std::size_t slot;
  };
  std::vector<Corner> corners;
  corners.reserve(4 * tetrahedra.size());
  for (std::size_t t = 0; t < tetrahedra.size(); ++t)
    for (std::size_t k = 0; k < 4; ++k) corners.push_back({tetrahedra[t].v[k], 4 * t + k});
  std::sort(corners.begin(), corners.end(), [](const Corner& l, const Corner& r) { return xyz_less(l.p, r.p); });

  TetMesh mesh;
  std::vector<std::uint32_t> vertex_of(corners.size());
  for (std::size_t i = 0; i < corners.size(); ++i) {
    if (i == 0 || xyz_less(corners[i - 1].p, corners[i].p)) mesh.vertices.push_back(corners[i].p);
    vertex_of[corners[i].slot] = static_cast<std::uint32_t>(mesh.vertices.size() - 1);
  }
  corners = {};

  mesh.tetrahedra.reserve(tetrahedra.size());
  for (std::size_t t = 0; t < tetrahedra.size(); ++t)
    mesh.tetrahedra.push_back(detail::canonical_rotation(
        std::array<std::uint32_t, 4>{vertex_of[4 * t], vertex_of[4 * t + 1], vertex_of[4 * t + 2], vertex_of[4 * t + 3]},
        std::less<>{}));
  std::sort(mesh.tetrahedra.begin(), mesh.tetrahedra.end());
  return mesh;
}

std::vector<Tetrahedron> tetrahedra_of(const TetMesh& mesh) {
  std::vector<Tetrahedron> out;
  out.reserve(mesh.num_tetrahedra());
  for (std::size_t i = 0; i < mesh.num_tetrahedra(); ++i) out.push_back(mesh.tetrahedron(i));
  return out;
}

bool apply_change(std::vector<Tetrahedron>& tets, const TetMeshChange& change) {
  return detail::apply_sorted_change(tets, change);
}

}  // namespace dynmesh
