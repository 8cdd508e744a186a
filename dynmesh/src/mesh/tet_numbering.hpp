// tet_numbering.hpp (private) — numbering a tetrahedral mesh's vertices in the canonical
// order with little memory: the corners are gathered in rounds, each ended by a sort and
// unique once they double, so at most about twice the distinct vertices are held (a mesh has
// about six times as many tetrahedra as vertices); then each corner's number is found by
// binary search. Used by make_tet_mesh and by DynamicOctreeMesh::mesh(), which makes its
// tetrahedra block by block and never holds them all as coordinates.
// Complexity: O(c log c) for c corners.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "dynmesh/tet_mesh.hpp"

namespace dynmesh::detail {

class TetNumbering {
 public:
  explicit TetNumbering(TetMesh& mesh) : mesh_(mesh) {}

  /// First pass: every tetrahedron's corners.
  void gather(const Tetrahedron& t) {
    for (const Point<3>& p : t.v) mesh_.vertices.push_back(p);
    if (mesh_.vertices.size() >= limit_) {
      compact();
      limit_ = std::max(limit_, 2 * mesh_.vertices.size());
    }
  }
  /// Between the passes: the vertices are final.
  void close(std::size_t tetrahedra) {
    compact();
    mesh_.vertices.shrink_to_fit();
    mesh_.tetrahedra.reserve(tetrahedra);
  }
  /// Second pass: the tetrahedra, numbered, in any order; sort() puts them in order.
  void add(const Tetrahedron& t) {
    mesh_.tetrahedra.push_back(canonical_rotation(
        std::array<std::uint32_t, 4>{number(t.v[0]), number(t.v[1]), number(t.v[2]), number(t.v[3])}, std::less<>{}));
  }
  void sort() { std::sort(mesh_.tetrahedra.begin(), mesh_.tetrahedra.end()); }

 private:
  void compact() {
    std::sort(mesh_.vertices.begin(), mesh_.vertices.end(), xyz_less);
    mesh_.vertices.erase(std::unique(mesh_.vertices.begin(), mesh_.vertices.end()), mesh_.vertices.end());
  }
  std::uint32_t number(const Point<3>& p) const {
    return static_cast<std::uint32_t>(std::lower_bound(mesh_.vertices.begin(), mesh_.vertices.end(), p, xyz_less) -
                                      mesh_.vertices.begin());
  }

  TetMesh& mesh_;
  std::size_t limit_ = std::size_t{1} << 16;
};

}  // namespace dynmesh::detail
