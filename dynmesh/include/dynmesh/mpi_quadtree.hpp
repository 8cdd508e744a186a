// dynmesh/mpi_quadtree.hpp — the dynamic quadtree/octree T* on MPI ranks, equal to the
// one-process tree.
//
// Purpose: T* of a point set too large for one process, kept up to date under insertions
// and deletions, as p4est distributes its forests (docs/DISTRIBUTED.md gives the argument
// and the figures). Every call is collective over the communicator.
//   * Partition: the cells of a partition level l0 ("root cells") in Morton order; rank r
//     owns the contiguous run [starts()[r], starts()[r+1]), balanced by point count.
//   * Ghosts: rank r runs an ordinary DynamicQuadtree on the points of its root cells and of
//     the ring of root cells around them (width 1: whether a cell c is split depends only on
//     the points of N(c)), and answers for the leaves of level ≥ l0 inside its own cells.
//   * Coarse cells (level < l0) are decided on every rank, identically, from per-root-cell
//     summaries (point count, split) exchanged with MPI_Allgatherv after each propagation.
//   * apply() routes each edit to the owner of its root cell and to every rank holding that
//     cell as a ghost; each rank propagates its own tree once per call.
//   * When the ranks' point counts drift apart by more than rebalance_factor, whole root cells
//     move (the trees of the ranks that change are rebuilt); the result stays exact.
//
// Invariants (check_invariants(), collective):
//   * the starts are monotone, cover every root cell, and every rank holds them alike, as it
//     holds the per-root-cell counts and split bits and the coarse levels;
//   * each rank's tree holds exactly the points of its owned and ghost root cells, its
//     counts agree with the global counts, and its split bits of owned root cells with them;
//   * every rank's tree passes its own check_invariants();
//   * gather_leaves() tiles the box, and the leaves of all ranks are disjoint.
// The contract the tests check: after every apply(), gather_leaves() equals
// StaticQuadtree's leaves of the current point set, byte for byte once formatted.
// Errors: bad input throws InputError on every rank, with the same message, agreed
// collectively before anything changes, so no rank is left waiting in a collective:
// point_indices() holds global indices (points: in the concatenation of the ranks' inputs in
// rank order; edits: in the concatenation of the ranks' edits, rank order). A failing apply()
// leaves the point set as it was.
// Determinism: the result is a function of the point set (and l0, the partition: the leaves
// are not); nothing depends on pointer values, hash order or message arrival order.
// Complexity: construction O(n/P·h + ghosts) per rank plus O(4^l0 or 8^l0) for the counts;
// apply() O(trace distance) per rank plus one MPI_Alltoallv and one MPI_Allgatherv of the
// changed summaries, and O(2^(d·l0)) when a summary changed; gather_leaves O(|T*| lg |T*|)
// on the root.
// Paper: Acar & Hudson, Section 2 (T*); p4est (Burstedde, Wilcox, Ghattas 2011) for the
// Morton partition.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <mpi.h>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace dynmesh {

struct MpiQuadtreeOptions {
  /// l0; negative: chosen from the input (docs/DISTRIBUTED.md, "Partition").
  int partition_level = -1;
  /// Repartition after an apply() when the largest rank owns more than this times the mean
  /// number of points (and at least 64 more); 0 never repartitions.
  double rebalance_factor = 1.5;
  /// Ghost ring width in root cells. 1 is what exactness needs; tests set 0 to see a
  /// narrower ring fail. Nothing else should change it.
  int ghost_ring = 1;
};

/// One rank's figures (MpiQuadtree::rank_stats()).
struct MpiRankStats {
  std::size_t owned_points = 0;
  std::size_t ghost_points = 0;
  std::size_t owned_roots = 0;     // root cells owned
  std::size_t trace_bytes = 0;     // of this rank's DynamicQuadtree
  std::size_t propagations = 0;    // apply() calls that changed this rank's tree
  double propagate_seconds = 0;    // their total wall time (the local propagate)
  double propagate_cpu_seconds = 0;  // their total CPU time (this thread's: not the time
                                     // the rank waited for a core)
  std::size_t repartitions = 0;
};

namespace detail {
template <std::size_t d, class Local>
struct MpiState;
}

template <std::size_t d>
  requires SupportedDim<d>
class MpiQuadtree {
 public:
  /// Collective. Each rank passes any part of the initial points (rank 0 all of them, or each
  /// rank its own share); the point set is their union. `comm` is duplicated; the destructor
  /// frees the duplicate, so it too is collective and must run before MPI_Finalize.
  MpiQuadtree(MPI_Comm comm, const Box<d>& box, std::span<const Point<d>> points,
              const MpiQuadtreeOptions& options = {});
  ~MpiQuadtree();
  MpiQuadtree(MpiQuadtree&&) noexcept;
  MpiQuadtree& operator=(MpiQuadtree&&) noexcept;

  /// Collective. The edits of all ranks, rank 0's first, then rank 1's, ..., applied in that
  /// order with one propagation per rank. Validated as a whole first (InputError on every
  /// rank, nothing changed).
  void apply(std::span<const Edit<d>> edits);

  const Box<d>& box() const noexcept;
  int partition_level() const noexcept;
  /// starts()[r] is the Morton index of rank r's first root cell; size P + 1.
  std::span<const std::uint64_t> starts() const noexcept;
  /// The number of points of all ranks.
  std::size_t size() const noexcept;

  /// The leaves of T* this rank answers for (inside its root cells; rank 0 also the leaves
  /// coarser than l0), sorted.
  std::vector<Leaf<d>> local_leaves() const;
  /// Collective: every leaf of T*, sorted, on rank `root`; empty on the others.
  std::vector<Leaf<d>> gather_leaves(int root = 0) const;

  MpiRankStats rank_stats() const;

  /// Collective; throws InvariantError (on every rank) when any rank finds a fault.
  void check_invariants() const;

 private:
  std::unique_ptr<detail::MpiState<d, DynamicQuadtree<d>>> s_;
};

/// Collective: the leaves of every rank's `local`, sorted, on rank `root`; empty on the
/// others. (MpiQuadtree::gather_leaves without the tree: a caller can free the trees first.)
template <std::size_t d>
std::vector<Leaf<d>> gather_leaves(MPI_Comm comm, std::span<const Leaf<d>> local, int root = 0);

extern template class MpiQuadtree<2>;
extern template class MpiQuadtree<3>;

}  // namespace dynmesh
