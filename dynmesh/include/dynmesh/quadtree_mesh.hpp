// dynmesh/quadtree_mesh.hpp — the quadtree mesh (Bern, Eppstein & Gilbert), static twin.
//
// Purpose: the plain static computation of the `quadtree` postprocess (docs/DESIGN.md,
// "The quadtree mesh"): from the points, T*; from T*, the refined tree T'; from T', a
// triangulation of the domain box in which every point is a vertex and no angle is below
// kQuadtreeMinAngle. It is the oracle of the self-adjusting mesh (DynamicMesh with
// Postprocess::Quadtree computes the same triangles bit for bit) and the baseline of its
// overhead. The rules are in detail/quadtree_mesh_rules.hpp, shared by both.
// Invariants: triangles() is a function of (box, point set) only; check_invariants() holds.
// Complexity: O(n lg n + |T'| ) expected.
// Paper: Bern, Eppstein & Gilbert, "Provably good mesh generation" (1994); Acar & Hudson,
// Section 2 (the quadtree) and Section 5 (postprocessing the quadtree).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace dynmesh {

/// The smallest angle the quadtree mesh guarantees, in degrees: arctan(1/3) = 18.43°,
/// stated with the margin the checker uses.
inline constexpr double kQuadtreeMinAngle = 18.4;

/// Throws InputError(Resolution) unless the mesh's cells are resolved in `box`
/// (mesh_resolution_level ≥ 2, detail/quadtree_mesh_rules.hpp). Each point's rule implies it,
/// so it matters for the empty set: a box far smaller than its offset (o + L == o) would
/// otherwise mesh as two degenerate triangles. Any side validate_box() accepts is meshed
/// otherwise: the rules scale their angle computations by powers of two. Shared by the
/// meshers.
void validate_mesh_box(const Box<2>& box);

/// The closure rule of T' (detail/quadtree_mesh_rules.hpp) on its sorted leaves: no leaf
/// twice, exactly `npoints` leaves hold a point, and each of them has its 3x3 block of
/// same-size leaves. Throws InvariantError. Shared by both meshers' check_invariants().
void require_refined_tree(std::span<const Leaf<2>> leaves, std::size_t npoints);

class QuadtreeMesh {
 public:
  /// Validates (InputError as DynamicMesh reports it, naming point indices) and meshes.
  QuadtreeMesh(const Box<2>& box, std::span<const Point<2>> points);

  const Box<2>& box() const noexcept { return box_; }
  /// The triangles, canonical and sorted.
  const std::vector<Triangle>& triangles() const noexcept { return triangles_; }
  Mesh mesh() const { return make_mesh(triangles_); }
  /// The leaves of T', sorted, with their point counts.
  const std::vector<Leaf<2>>& refined_leaves() const noexcept { return leaves_; }
  /// Leaves of T* (the quadtree before the closure).
  std::span<const Leaf<2>> tree_leaves() const noexcept { return tree_.leaves(); }

  /// T' satisfies the closure rules; the mesh tiles the box. Throws InvariantError.
  void check_invariants() const;

 private:
  Box<2> box_;
  std::vector<Point<2>> points_;
  StaticQuadtree<2> tree_;
  std::vector<Leaf<2>> leaves_;
  std::vector<Triangle> triangles_;
};

}  // namespace dynmesh
