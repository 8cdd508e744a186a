// dynmesh/tet_mesh.hpp — 3D tetrahedral meshes: tetrahedra named by their corners, the
// canonical mesh of the `.node`/`.ele` files, and the change feed of one update.
//
// Purpose: the 3D value types every tetrahedral mesher (the static OctreeMesh, the
// self-adjusting DynamicOctreeMesh) produces and every consumer (writers, checker, tests, the
// command, Python) reads; the 3D counterparts of mesh.hpp's Triangle, Mesh and MeshChange.
//   Tetrahedron    – four corners by coordinates, positively oriented (the determinant of
//                    (b − a, c − a, d − a) is positive), in the canonical rotation: the corner
//                    with the smallest (x, y, z) first, then the other three rotated so that
//                    the smallest of them comes next (an even permutation of the four, so the
//                    orientation stays positive). Ordered lexicographically on the twelve
//                    coordinates.
//   TetMesh        – the canonical form: vertices sorted by (x, y, z) (0-based here, written
//                    from 1); tetrahedra as index quadruples in the same canonical rotation,
//                    sorted. Index order is coordinate order, so the two forms sort alike.
//   TetMeshChange  – the tetrahedra removed and added by one update (each group sorted).
// Invariants: canonical_tetrahedron is the identity on a canonical tetrahedron and maps the
// twelve even permutations of a positive quadruple to one value; make_tet_mesh depends only
// on the set of tetrahedra; tetrahedra_of(make_tet_mesh(ts)) == sorted ts (distinct ts).
// Complexity: make_tet_mesh O(t log t); the rest O(1) per tetrahedron.
// Paper: none (the formats are TetGen's .node/.ele; docs/FORMATS.md, "`dynmesh mesh` in 3D").
#pragma once

#include <array>
#include <compare>
#include <cstdint>
#include <span>
#include <vector>

#include "dynmesh/point.hpp"

namespace dynmesh {

struct Tetrahedron {
  std::array<Point<3>, 4> v;  // positively oriented, canonical rotation

  friend bool operator==(const Tetrahedron&, const Tetrahedron&) = default;
  friend auto operator<=>(const Tetrahedron&, const Tetrahedron&) = default;
};

/// (x, y, z) lexicographic order of points (the vertex order of a canonical TetMesh).
inline bool xyz_less(const Point<3>& a, const Point<3>& b) noexcept {
  if (a[0] != b[0]) return a[0] < b[0];
  if (a[1] != b[1]) return a[1] < b[1];
  return a[2] < b[2];
}

namespace detail {
/// The canonical rotation of a positively oriented quadruple under a strict weak order
/// `less`: shared by the coordinate form and the index form, so that the two agree.
template <class T, class Less>
constexpr std::array<T, 4> canonical_rotation(const std::array<T, 4>& t, Less&& less) noexcept {
  unsigned low = 0;
  for (unsigned k = 1; k < 4; ++k)
    if (less(t[k], t[low])) low = k;
  // The double transposition that brings `low` to the front (even).
  std::array<T, 4> r = t;
  switch (low) {
    case 1: r = {t[1], t[0], t[3], t[2]}; break;
    case 2: r = {t[2], t[3], t[0], t[1]}; break;
    case 3: r = {t[3], t[2], t[1], t[0]}; break;
    default: break;
  }
  // A rotation of the last three (even).
  if (less(r[2], r[1]) && !less(r[3], r[2])) return {r[0], r[2], r[3], r[1]};
  if (less(r[3], r[1]) && less(r[3], r[2])) return {r[0], r[3], r[1], r[2]};
  return r;
}
}  // namespace detail

/// The tetrahedron a, b, c, d (already positively oriented) in its canonical rotation.
inline Tetrahedron canonical_tetrahedron(const Point<3>& a, const Point<3>& b, const Point<3>& c,
                                         const Point<3>& d) noexcept {
  return Tetrahedron{detail::canonical_rotation(std::array<Point<3>, 4>{a, b, c, d}, xyz_less)};
}

struct TetMesh {
  std::vector<Point<3>> vertices;                      // sorted by (x, y, z), distinct
  std::vector<std::array<std::uint32_t, 4>> tetrahedra;  // canonical, sorted

  friend bool operator==(const TetMesh&, const TetMesh&) = default;
  std::size_t num_vertices() const noexcept { return vertices.size(); }
  std::size_t num_tetrahedra() const noexcept { return tetrahedra.size(); }
  Tetrahedron tetrahedron(std::size_t i) const noexcept {
    const auto& t = tetrahedra[i];
    return Tetrahedron{{vertices[t[0]], vertices[t[1]], vertices[t[2]], vertices[t[3]]}};
  }
};

/// The canonical mesh of a set of positively oriented tetrahedra (any rotation, any order).
/// Duplicates are kept (the checker reports them).
TetMesh make_tet_mesh(std::span<const Tetrahedron> tetrahedra);

/// The tetrahedra of a mesh, canonical, in the mesh's (sorted) order.
std::vector<Tetrahedron> tetrahedra_of(const TetMesh& mesh);

/// One update's change: remove `removed` from the mesh before it and add `added` to get the
/// mesh after it. Both sorted, canonical, and disjoint.
struct TetMeshChange {
  std::vector<Tetrahedron> removed;
  std::vector<Tetrahedron> added;
  friend bool operator==(const TetMeshChange&, const TetMeshChange&) = default;
};

/// Applies a change to a sorted tetrahedron list; returns false (and leaves `tets`
/// unspecified) when a removed tetrahedron is absent or an added one is already present.
bool apply_change(std::vector<Tetrahedron>& tets, const TetMeshChange& change);

}  // namespace dynmesh
