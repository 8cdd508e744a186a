// dynmesh/mpi_mesh.hpp — the quadtree mesh (2D) and the octree's tetrahedral mesh (3D) on MPI
// ranks, equal to the one-process mesh.
//
// Purpose: the dynamic tree meshes of a point set spread over MPI ranks, under insertions and
// deletions, as MpiQuadtree spreads T* (docs/DISTRIBUTED.md, "The meshes on ranks", gives the
// argument). Every call is collective over the communicator.
//   * Partition and routing are MpiQuadtree's (root cells of a partition level l0 in Morton
//     order, runs balanced by point count), with a wider ghost ring (kMeshGhostRing) and l0
//     never finer than T*'s coarsest leaf: no leaf of T* is coarser than a root cell.
//   * Each rank runs the single-process dynamic mesh (DynamicMesh with the quadtree
//     postprocess, or DynamicOctreeMesh) on the points of its own and its ghost root cells,
//     its tree splitting every cell coarser than l0 (DynamicQuadtreeOptions::split_below).
//   * A simplex belongs to the root cell holding its centroid (computed in doubles alike on
//     every rank): each simplex of the one-process mesh has exactly one owner, whose local
//     mesh holds it.
//   * When an apply() leaves a leaf of T* coarser than l0, the ranks undo it, rebuild at the
//     coarser level and apply it again; so each apply's owned changes are exactly the
//     one-process change, split by owner.
// Invariants (check_invariants(), collective): MpiQuadtree's partition invariants; every T*
// cell coarser than l0 is split; each rank's structure passes its own checks; the union of
// the owned simplices is the one-process mesh of the union of the points (rank 0 builds it
// from scratch: a test's checker, O(n lg n) there).
// Errors: as MpiQuadtree (agreed on every rank, global indices; nothing changes).
// Determinism: the owned simplices are a function of the point set and the partition; their
// union of the point set alone.
// Complexity: construction O(n/P · depth + ghosts) per rank, plus a second build when l0
// must move to a coarser level; apply() O(trace distance) per rank plus MpiQuadtree's
// messages, and a rebuild when l0 moves.
// Paper: Acar & Hudson, Sections 2 and 4; Bern, Eppstein & Gilbert (the quadtree mesh);
// p4est (Burstedde, Wilcox, Ghattas 2011) for the Morton partition.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <type_traits>
#include <vector>

#include <mpi.h>

#include "dynmesh/box.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/dynamic_octree_mesh.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/mpi_quadtree.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/tet_mesh.hpp"

namespace dynmesh {

/// The ghost ring, in root cells, that the meshes' exactness needs (docs/DISTRIBUTED.md, "The
/// meshes on ranks": derived there, and a narrower ring checked to fail).
inline constexpr int kMeshGhostRing = 3;

/// MpiQuadtreeOptions with the meshes' ring.
inline MpiQuadtreeOptions mpi_mesh_defaults() {
  MpiQuadtreeOptions o;
  o.ghost_ring = kMeshGhostRing;
  return o;
}

template <std::size_t d>
using MeshSimplex = std::conditional_t<d == 2, Triangle, Tetrahedron>;
/// The canonical index form: Mesh (2D) or TetMesh (3D).
template <std::size_t d>
using CanonicalMesh = std::conditional_t<d == 2, Mesh, TetMesh>;

/// An update's change restricted to one rank's simplices: both sorted, canonical.
template <std::size_t d>
struct OwnedChange {
  std::vector<MeshSimplex<d>> removed;
  std::vector<MeshSimplex<d>> added;
};

namespace detail {
template <std::size_t d>
struct MpiMeshState;
}

template <std::size_t d>
  requires SupportedDim<d>
class MpiMesh {
 public:
  using Simplex = MeshSimplex<d>;

  /// Collective. Each rank passes any part of the initial points; the point set is their
  /// union. `options.partition_level`, if given, is lowered as far as T* needs.
  MpiMesh(MPI_Comm comm, const Box<d>& box, std::span<const Point<d>> points,
          const MpiQuadtreeOptions& options = mpi_mesh_defaults());
  ~MpiMesh();
  MpiMesh(MpiMesh&&) noexcept;
  MpiMesh& operator=(MpiMesh&&) noexcept;

  /// Collective: the ranks' edits as one batch (rank 0's first), one propagation per rank
  /// (two and a rebuild when l0 moves). Validated as a whole; InputError on every rank and
  /// nothing changed otherwise.
  void apply(std::span<const Edit<d>> edits);

  const Box<d>& box() const noexcept;
  int partition_level() const noexcept;
  std::size_t size() const noexcept;

  /// The simplices this rank owns, canonical and sorted.
  std::vector<Simplex> local_simplices() const;
  /// The same in index form: the vertices they use, sorted, and the simplices as canonical
  /// index tuples, sorted (a sixth of the coordinates' memory in 3D: what the writer uses).
  CanonicalMesh<d> owned_mesh() const;
  /// The last apply()'s change to the simplices this rank owns (empty after construction).
  const OwnedChange<d>& local_change() const noexcept;

  MpiRankStats rank_stats() const;

  /// Collective; throws InvariantError (on every rank) when any rank finds a fault.
  void check_invariants() const;

 private:
  std::unique_ptr<detail::MpiMeshState<d>> s_;
};

extern template class MpiMesh<2>;
extern template class MpiMesh<3>;

}  // namespace dynmesh
