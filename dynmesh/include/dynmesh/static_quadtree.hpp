// dynmesh/static_quadtree.hpp — the plain static quadtree/octree T* and the tree checker.
//
// Purpose: the oracle of docs/DESIGN.md, "The quadtree contract". From a set of located points it
// computes T*, the least set of split cells such that
//   (1) every crowded cell is split (a cell is crowded when it contains two or more points,
//       or exactly one point while its 3^d neighbourhood N(c) contains another);
//   (2) the parent of a split cell is split;
//   (3) every cell of level m−1 that touches a split cell of level m is split (grading);
// and exposes its leaves. It is written without the runtime, for clarity and as the
// reference the self-adjusting tree is tested against, and as the overhead baseline.
//
// How T* is computed (no work queue needed for a static build):
//   * Crowded cells, level by level from the root: a point whose level-l cell is not crowded
//     can never again make a deeper cell crowded (crowdedness is upward closed and symmetric),
//     so only the points still in crowded cells are hashed at the next level.
//   * Closure, level by level from the deepest crowded level up: S_m = crowded_m ∪ {level-m
//     cells touching a cell of S_{m+1}} (the parent of a cell touches it, so (2) is included).
//     Rules (2) and (3) only ever force shallower cells, so this single bottom-up pass is the
//     least fixed point. The result is a set: it does not depend on the input order.
//   * A crowded level-52 cell cannot be split: InputError(Resolution) ("spread beyond the
//     resolution of 2^52"). Equal positions: InputError(Duplicate).
// QuadTreeRefine (the paper's Figure 2, which the self-adjusting version follows) computes the
// same set (docs/DESIGN.md, "A stable quadtree program"); this file follows the definition instead, so the two are independent.
//
// check_tree(points, leaves) verifies any leaf set (this oracle's, the dynamic tree's, one
// read from a `.cells` file) against the contract, and reports every broken rule:
//   tiling      – valid cells, no duplicate, no leaf inside another, no gap;
//   occupancy   – each leaf holds at most one point and its npoints field is right;
//   separation  – no two touching leaves both hold points;
//   grading     – touching leaves differ by at most one level (equivalently: rule (3));
//   crowding    – no leaf is crowded (rule (1));
//   minimality  – every split cell is crowded, the parent of a split cell, or forced by
//                 grading (touches a split cell one level deeper).
// Passing all of them is equivalent to "the leaves are exactly the leaves of T*": closure
// gives T* ⊆ S, and local justification gives S ⊆ T* by induction from the deepest level.
//
// Invariants (of StaticQuadtree): split cells are closed under parent; leaves() are the
// children of split cells that are not split (the root alone when nothing is split), sorted
// by (level, i, j, k); each holds 0 or 1 point; check_invariants() holds after construction.
// Complexity: construction expected O(n lg n + n·(h+1)·3^d + |S|·(2^d + lg |S|) + |L|), where
// h is the average depth at which a point becomes isolated (O(lg L/s)), S the split cells and
// L the leaves (|L| = (2^d − 1)|S| + 1; the leaves are emitted in order, not sorted); locate
// O(lg 52) hash probes; leaf_index O(lg |L|); neighbours O(3^d·2^d) in a graded tree;
// check_tree expected O(|L| + |S|·2^d + n·(3^d + lg |L|) + |S|·lg n) hash probes and
// comparisons (plus O(|L| lg |L|) when the leaves are not given sorted). The hash tables
// hash blocks of 4^d cells together, and the build walks the points in Morton order, so
// most probes hit cache. T* of uniform points is large (about 11 leaves per point in 2D and
// 31 in 3D, since a point needs its whole 3^d neighbourhood to itself), so both the build
// and check_tree are dominated by the leaves, not the points.
// Paper: Acar & Hudson, Section 2: crowded / self-crowded / ill-graded cells, Figure 2
// (QuadTreeRefine), Lemma 2.1–2.3; Bern, Eppstein & Gilbert [BEG90] for the well-graded
// quadtree.
#pragma once

#include <compare>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/detail/cell_table.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh {

/// A leaf of a tree and the number of input points in it (0 or 1 in a valid tree).
template <std::size_t d>
  requires SupportedDim<d>
struct Leaf {
  CellId<d> cell;
  std::uint32_t npoints = 0;

  friend constexpr bool operator==(const Leaf& a, const Leaf& b) noexcept {
    return a.cell == b.cell && a.npoints == b.npoints;
  }
  friend constexpr std::strong_ordering operator<=>(const Leaf& a, const Leaf& b) noexcept {  // by cell first
    if (const auto c = a.cell <=> b.cell; c != 0) return c;
    return a.npoints <=> b.npoints;
  }
};

enum class ViolationKind {
  BadCell,           // level outside [0, 52] or an index outside [0, 2^level)
  DuplicateLeaf,     // the same cell listed twice
  Overlap,           // a leaf contains another leaf
  Gap,               // a child of a split cell is neither split nor a leaf (or no leaves)
  BadPoint,          // a position with a coordinate ≥ 2^52
  Overfull,          // a leaf holds two or more points
  CountMismatch,     // a leaf's npoints differs from the number of points in it
  TouchingOccupied,  // two touching leaves both hold points
  Grading,           // a leaf touches a leaf two or more levels smaller
  CrowdedLeaf,       // a leaf with one point whose neighbourhood holds another
  UnjustifiedSplit,  // a split cell that is not crowded, not a parent of a split cell, and
                     // not forced by grading
};

const char* to_string(ViolationKind kind) noexcept;

template <std::size_t d>
struct Violation {
  ViolationKind kind;
  CellId<d> cell;   // the offending cell (a leaf or a split cell)
  CellId<d> other;  // a witness when there is one (the touching leaf, the split cell), else cell
  std::string message;
};

template <std::size_t d>
struct CheckReport {
  std::vector<Violation<d>> violations;  // at most max_violations, in check order
  bool truncated = false;                // more violations existed than were kept

  bool ok() const noexcept { return violations.empty(); }
  bool has(ViolationKind kind) const noexcept;
  std::size_t count(ViolationKind kind) const noexcept;
  /// One line per violation (and a final "... more" line when truncated); "ok" when none.
  std::string summary() const;
};

/// Checks that `leaves` are exactly the leaves of T* for `points` (see the header comment),
/// reporting each broken rule. Structural (tiling) violations stop the check early, since
/// the later rules presuppose a tree. Positions must be distinct to pass (equal positions
/// show up as an overfull leaf). `split_below` > 0 checks T* with every cell coarser than
/// that level split as well (the distributed meshes' local trees, DynamicQuadtreeOptions).
template <std::size_t d>
CheckReport<d> check_tree(std::span<const Position<d>> points, std::span<const Leaf<d>> leaves,
                          std::size_t max_violations = 64, int split_below = 0);

/// check_tree, throwing InvariantError with the summary when it fails.
template <std::size_t d>
void require_valid_tree(std::span<const Position<d>> points, std::span<const Leaf<d>> leaves, int split_below = 0);

template <std::size_t d>
  requires SupportedDim<d>
class StaticQuadtree {
 public:
  /// Builds T* of the located points. Throws InputError(OutsideBox) for a coordinate
  /// ≥ 2^52, InputError(Duplicate) for two equal positions, InputError(Resolution) when a
  /// level-52 cell is crowded (two points within one grid unit per axis). Error messages
  /// name the points by their index in `points`.
  explicit StaticQuadtree(std::span<const Position<d>> points);

  /// Locates the points in `box` (InputError(NotFinite/OutsideBox) naming the point index)
  /// and builds T*.
  static StaticQuadtree from_points(const Box<d>& box, std::span<const Point<d>> points);

  /// The leaves, sorted by (level, i, j, k), with their point counts.
  std::span<const Leaf<d>> leaves() const noexcept { return leaves_; }
  /// The split cells of T*, sorted by (level, i, j, k).
  std::vector<CellId<d>> split_cells() const;
  std::span<const Position<d>> points() const noexcept { return points_; }

  std::size_t num_points() const noexcept { return points_.size(); }
  std::size_t num_split() const noexcept { return split_.size(); }
  /// Deepest leaf level (0 for the single-leaf tree).
  int depth() const noexcept { return depth_; }

  bool is_split(const CellId<d>& c) const noexcept { return split_.contains(c); }
  /// c is a valid cell, not split, and its parent is split (or c is the root).
  bool is_leaf(const CellId<d>& c) const noexcept;
  /// Index of leaf c in leaves() (binary search); throws std::invalid_argument if c is not a
  /// leaf.
  std::size_t leaf_index(const CellId<d>& c) const;

  /// The leaf containing the located point q (any q in [0, 2^52)^d, input point or not).
  CellId<d> locate(const Position<d>& q) const;
  /// The leaves touching leaf c (closed boxes intersect), sorted by (level, i, j, k), c
  /// excluded. Throws std::invalid_argument if c is not a leaf.
  std::vector<CellId<d>> neighbours(const CellId<d>& c) const;

  /// check_tree on this tree's own points and leaves; throws InvariantError when it fails.
  void check_invariants() const;

 private:
  std::vector<Position<d>> points_;
  detail::CellTable<d, std::uint8_t> split_;  // value: bit w set iff child(c, w) is split
  int max_split_level_ = -1;  // deepest split level, -1 when nothing is split
  int depth_ = 0;
  std::vector<Leaf<d>> leaves_;
};

extern template class StaticQuadtree<2>;
extern template class StaticQuadtree<3>;

}  // namespace dynmesh
