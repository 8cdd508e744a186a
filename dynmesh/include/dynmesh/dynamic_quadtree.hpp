// dynmesh/dynamic_quadtree.hpp — the well-graded quadtree/octree T*, kept up to date under
// point insertions and deletions by self-adjusting computation.
//
// Purpose: the public dynamic API. QuadTreeRefine (Acar & Hudson, Figure 2) is written as
// ordinary static code on sac-runtime, inside the library; this class owns the engine, the
// input point list and the cell directory, runs the program once, and after each insert /
// erase / batch calls propagate(), which leaves exactly the tree a
// from-scratch run on the current point set would build (docs/DESIGN.md, "The
// quadtree contract"), in O(lg L/s) trace distance per single-point update.
//
// Invariants (check_invariants()):
//   * the engine's own invariants (order list, queue, trace, tables);
//   * leaves() are exactly the leaves of T* of the current points (check_tree: tiling,
//     occupancy, separation, grading, crowding, minimality), and every point lies in the
//     leaf that holds it;
//   * the position index, the id index and the input list hold the same points;
//   * the cell directory is consistent: each slot is filed under its own cell, every
//     child of a split cell has a slot whose point list was written, and each point's
//     per-level list nodes hold that point.
// Built with the CMake option SAC_DEBUG_CHECKS, every insert, erase and apply ends with
// check_invariants().
// Failure atomicity: every mutator call validates its whole input before changing anything,
// so a call that throws InputError leaves the tree, the ids and the engine as they were.
// Determinism: results depend only on the point set; ids never enter the computation, and
// nothing depends on pointer values or hash iteration order.
// Complexity: construction O(n·h + |T*|) trace events (h = mean depth at which a point is
// isolated, O(lg L/s)); insert/erase O(lg L/s) expected trace distance (the stability
// experiments measure it); leaves() O(|T*| lg |T*|); leaves_in(c) O(leaves in c · lg); is_split
// O(1); locate O(depth); neighbours O(3^d·2^d).
// Paper: Acar & Hudson, "Optimal-time dynamic mesh refinement", Section 2 (QuadTreeRefine),
// Section 4 (dynamization, keyed work-queue entries, monotonicity).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <sac/memory_breakdown.hpp>
#include <sac/stats.hpp>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace dynmesh {

/// Stable identity of an input point (never reused within one tree).
using PointId = std::uint64_t;

/// A leaf and the ids of the points in it (at most one in T*).
template <std::size_t d>
  requires SupportedDim<d>
struct LeafPoints {
  CellId<d> cell;
  std::vector<PointId> points;
};

/// Figures of the last update (insert, erase or batch).
struct UpdateStats {
  std::uint64_t trace_distance = 0;  // trace events created + undone by its propagation
  std::uint64_t reexecuted = 0;      // reads re-executed
  double seconds = 0.0;              // wall time of propagate()
};

/// Where DynamicQuadtree::trace_bytes() goes: the engine's trace by record kind and the
/// base versions (the directory slots' two defaults each, the input list's links), then
/// what lives outside the engine: the cell directory and the input list's nodes.
struct QuadtreeMemory {
  sac::MemoryBreakdown engine;
  std::size_t slots = 0;             // directory slots (cells the computation has named)
  std::size_t slot_bytes = 0;        // their pool, freed slots included
  std::size_t level_nodes = 0;       // the points' list nodes below level 0
  std::size_t level_node_bytes = 0;  // their pool, freed nodes included
  std::size_t table_bytes = 0;       // the directory's hash table, as trace_bytes() counts it
  std::size_t input_nodes = 0;       // the input list's nodes, one per point
  std::size_t input_node_bytes = 0;  // their pool, freed nodes included

  /// == trace_bytes() (when engine.unaccounted == 0).
  std::size_t total() const {
    return engine.trace() + engine.inputs.bytes() + slot_bytes + level_node_bytes + table_bytes +
           input_node_bytes;
  }
};

/// The deepest level split_below may name: a distributed mesh's partition level is at most 10.
inline constexpr int kMaxSplitBelow = 16;

struct DynamicQuadtreeOptions {
  /// Split every cell coarser than this level as well, whatever its points (0: T* itself).
  /// A rank of a distributed mesh runs its program on some of the points with this set to
  /// the partition level, so that its tree has the one-process shape there
  /// (docs/DISTRIBUTED.md); the leaves are then T*'s leaves of that level or finer, and T*'s
  /// coarser leaves cut down to it. std::invalid_argument outside 0..kMaxSplitBelow.
  int split_below = 0;
};

namespace detail {
template <std::size_t d>
struct DynamicState;
}

template <std::size_t d>
  requires SupportedDim<d>
class DynamicQuadtree {
 public:
  /// Builds T* of `points` in `box` from scratch. Throws InputError (NotFinite, OutsideBox,
  /// Duplicate, Resolution) naming the point index; ids are 0..n−1 in input order.
  explicit DynamicQuadtree(const Box<d>& box, std::span<const Point<d>> points = {},
                           const DynamicQuadtreeOptions& options = {});
  ~DynamicQuadtree();
  DynamicQuadtree(DynamicQuadtree&&) noexcept;
  DynamicQuadtree& operator=(DynamicQuadtree&&) noexcept;

  /// Inserts p and returns its id. InputError: NotFinite, OutsideBox, Duplicate (same
  /// located position as a present point), Resolution (another point within one grid
  /// unit: a level-52 cell would have to split).
  PointId insert(const Point<d>& p);
  /// Erases the point with this id; InputError(Absent) if there is none.
  void erase(PointId id);
  /// Erases the point with exactly these coordinates; InputError(Absent) if there is none.
  void erase(const Point<d>& p);
  /// Applies the edits in order and propagates once. Validated as a whole first: on error
  /// nothing changes, and InputError::point_indices() holds the failing edit's index.
  /// Returns the ids of the inserted points in edit order.
  std::vector<PointId> apply(std::span<const Edit<d>> edits);

  const Box<d>& box() const noexcept;
  std::size_t size() const noexcept;
  bool contains(PointId id) const noexcept;
  std::optional<PointId> find(const Point<d>& p) const noexcept;
  /// The coordinates of a present point; InputError(Absent) otherwise.
  const Point<d>& point(PointId id) const;
  /// The present points with their ids, in the order of the input list.
  std::vector<std::pair<PointId, Point<d>>> points() const;
  /// The located positions of the present points (input-list order).
  std::vector<Position<d>> positions() const;

  /// The leaves of T*, sorted by (level, i, j, k), with point counts (the `.cells` order).
  std::vector<Leaf<d>> leaves() const;
  /// The leaves with the ids of their points, same order.
  std::vector<LeafPoints<d>> leaves_with_points() const;
  /// The leaves of T* inside cell c (c itself when it is a leaf), sorted; empty when c lies
  /// strictly inside a leaf. O(leaves inside c · lg).
  std::vector<Leaf<d>> leaves_in(const CellId<d>& c) const;
  /// Is c split in T*? O(1) directory probe.
  bool is_split(const CellId<d>& c) const noexcept;
  /// The leaf containing p (any point of the box). InputError for NaN or outside the box.
  CellId<d> locate(const Point<d>& p) const;
  /// The leaves touching leaf c (closed boxes intersect), sorted, c excluded.
  /// std::invalid_argument if c is not a leaf.
  std::vector<CellId<d>> neighbours(const CellId<d>& leaf) const;
  /// Number of split cells and of leaves.
  std::size_t num_split() const;
  std::size_t num_leaves() const { return num_split() * (kChildren<d> - 1) + 1; }

  const UpdateStats& last_update() const noexcept;
  const sac::Stats& engine_stats() const noexcept;
  /// Live trace memory (records, closures, tables), input list and directory included.
  std::size_t trace_bytes() const;
  /// Live trace records only (equal for equal traces).
  std::size_t record_bytes() const;
  /// trace_bytes() by part (for bench/RESULTS.md). O(live events + directory).
  QuadtreeMemory memory_breakdown() const;
  std::uint64_t live_events() const;
  /// Directory slots held (cells the computation has named).
  std::size_t directory_size() const noexcept;

  /// Releases directory slots that no trace event references. Runs automatically when the
  /// directory has doubled since the last compaction, so memory stays proportional to the
  /// live trace; call it before comparing memory with a from-scratch run.
  void compact();

  /// See the header comment; throws InvariantError (or sac::InvariantError) on failure.
  void check_invariants() const;

 private:
  // Test-only hook: tests/dynmesh/dynamic_quadtree_test.cpp defines it to corrupt the
  // directory and the tree and see check_invariants() fail. Nothing else may define it.
  friend struct DynamicQuadtreeTestAccess;

  std::unique_ptr<detail::DynamicState<d>> s_;
};

extern template class DynamicQuadtree<2>;
extern template class DynamicQuadtree<3>;

}  // namespace dynmesh
