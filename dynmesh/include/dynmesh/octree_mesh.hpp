// dynmesh/octree_mesh.hpp — the octree's tetrahedral mesh of a 3D point set, static twin.
//
// Purpose: the plain static computation of the 3D `quadtree` postprocess
// (docs/OCTREE_MESH.md): from the points, the octree T*; from T*, the refined tree T' in
// which each point owns a block of 2x2x2 same-size leaves around the grid vertex nearest to it;
// from T', a tetrahedral mesh of the closed box in which every input point is a vertex, the
// tetrahedra tile the box with no hanging vertex, and every dihedral angle lies in
// [kOctreeMinDihedral, kOctreeMaxDihedral]. It is the oracle of the self-adjusting mesh
// (DynamicOctreeMesh computes the same tetrahedra bit for bit) and the baseline of its
// overhead. The rules are in detail/octree_mesh_rules.hpp, shared by both.
// Invariants: tetrahedra() is a function of (box, point set) only; check_invariants() holds.
// Complexity: O(n lg n + |T'|) expected.
// Paper: Bern, Eppstein & Gilbert, "Provably good mesh generation" (1994); Mitchell &
// Vavasis, "Quality mesh generation in three dimensions" (1992); Acar & Hudson, Section 2.2.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/static_quadtree.hpp"
#include "dynmesh/tet_mesh.hpp"

namespace dynmesh {

/// The dihedral angles the octree mesh guarantees, in degrees. The enumeration of
/// tests/dynmesh/octree_mesh_bound_test.cpp proves every template within them, for every
/// legal neighbourhood and every position of a point in its allowed region (interval
/// arithmetic); docs/OCTREE_MESH.md states the argument.
inline constexpr double kOctreeMinDihedral = 13.0;
inline constexpr double kOctreeMaxDihedral = 164.5;

/// Throws InputError(Resolution) unless the mesh's cells are resolved in `box` (its
/// resolution level ≥ 2; see detail/octree_mesh_rules.hpp). Shared by both meshers.
void validate_mesh_box(const Box<3>& box);

/// The rules of T' on its leaves and the located points: no leaf twice, each point's leaf
/// says it holds one point and no other leaf holds any, and every cell of each point's block
/// is a leaf. Throws InvariantError. O((leaves + points·52) expected).
void require_refined_tree(std::span<const Leaf<3>> leaves, std::span<const Position<3>> points);

class OctreeMesh {
 public:
  /// Validates (InputError as DynamicOctreeMesh reports it, naming point indices) and meshes.
  OctreeMesh(const Box<3>& box, std::span<const Point<3>> points);

  const Box<3>& box() const noexcept { return box_; }
  /// The tetrahedra, canonical and sorted.
  const std::vector<Tetrahedron>& tetrahedra() const noexcept { return tets_; }
  TetMesh mesh() const { return make_tet_mesh(tets_); }
  /// The leaves of T', sorted, with their point counts (0 or 1).
  const std::vector<Leaf<3>>& refined_leaves() const noexcept { return leaves_; }
  /// The leaves of T* (the octree before the closure).
  std::span<const Leaf<3>> tree_leaves() const noexcept { return tree_.leaves(); }

  /// T' satisfies its rules. Throws InvariantError. (The mesh contract is
  /// require_valid_tet_mesh's, tet_mesh_check.hpp.)
  void check_invariants() const;

 private:
  Box<3> box_;
  std::vector<Point<3>> points_;
  StaticQuadtree<3> tree_;
  std::vector<Leaf<3>> leaves_;
  std::vector<Tetrahedron> tets_;
};

}  // namespace dynmesh
