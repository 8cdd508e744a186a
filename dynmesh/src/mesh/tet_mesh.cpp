// The canonical tetrahedral mesh and the change feed's application (see dynmesh/tet_mesh.hpp).
#include "dynmesh/tet_mesh.hpp"

#include <algorithm>
#include <cstddef>
#include <functional>

#include "mesh/sorted_change.hpp"
#include "mesh/tet_numbering.hpp"

namespace dynmesh {

TetMesh make_tet_mesh(std::span<const Tetrahedron> tetrahedra) {
  TetMesh mesh;
  detail::TetNumbering numbering(mesh);
  for (const Tetrahedron& t : tetrahedra) numbering.gather(t);
  numbering.close(tetrahedra.size());
  for (const Tetrahedron& t : tetrahedra) numbering.add(t);
  numbering.sort();
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
