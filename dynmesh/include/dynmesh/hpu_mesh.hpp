// dynmesh/hpu_mesh.hpp — the off-center quality Delaunay mesh (DynHPU's static twin).
//
// Purpose: a Delaunay mesh of the domain box in which every input point is a vertex and no
// angle is below θ (--min-angle, 1 to 30 degrees; default 20.7, radius-edge ratio ρ = √2),
// with few Steiner points. It refines the Delaunay triangulation of the box's corners and
// the points by off-centers processed in size classes, smallest first (Har-Peled & Üngör's
// order, the seed's Figure 5), and treats the box's sides as segments, as Triangle does with
// a .poly file. It is the oracle and the baseline of the self-adjusting hpu mesh
// (src/hpu/hpu_cells_program.hpp).
//
// The algorithm is the seed's Figure 5 on loose pairs, with the choices it leaves open made
// as follows (ρ = 1/(2 sin θ), k = √(ρ² − 1/4) = 1/(2 tan θ); docs/DESIGN.md, "DynHPU"):
//   1. Vertices: the box's corners, the points, and the midpoints that splitting encroached
//      box edges adds (an edge's diametral disc holds its halves', and a point strictly
//      inside one projects strictly inside the edge, so these form one path down the
//      halvings per point, computed from the points alone). Candidates are edges of their
//      Delaunay triangulation (unique: degenerate cases follow a symbolic perturbation by
//      (x, y) rank, src/geometry/delaunay.hpp).
//   2. Loose: p→q is ccw-loose when no vertex lies strictly inside its ccw-leaf, the disc
//      through p and q with centre m + k·J(q − p) (m the midpoint, J the +90° turn), decided
//      exactly by predicates.hpp's pencil(). For a Delaunay edge pq the leaf is empty exactly
//      when neither neighbour (left t, right u) is inside it. k is taken 2^−30 lower than
//      its value, so that "no loose pair" leaves every angle above θ by more than rounding.
//      The outside of a box side is never a side of a pair.
//   3. Classes: the class of pq is ⌊log2 |pq|⌋ (from the double exponent of |pq|²). Queue
//      entries are vertices, Q_j a FIFO per class. A vertex enters at the class of its
//      shortest edge (the first entries: the corners, then the other vertices in BRIO order,
//      src/hpu/hpu_geometry.hpp's insertion_less, which keeps the self-adjusting version's
//      updates local); its entry in Q_j collects its loose pairs of class j (≤ j at its
//      first entry; both sides, in (x, y) order of their ends) and re-enters it in Q_{j+1}
//      while its star has a triangle of circumradius above 2^{j+2} or a loose edge of a
//      class above j. A new vertex enters at max(current class, its shortest edge's class).
//      Since edges between old vertices only vanish, looseness once lost never returns, and
//      every new edge has a new end, each pair loose at the end was loose and an edge since
//      its newer end was born, whose entries reach its class: nothing loose remains. The
//      rule reads the vertices within 2^{j+3} of v only: without a larger triangle, both
//      triangles of every longer edge are in the star, and they decide its looseness.
//      (Not every longer edge and every triangle above 2^{j+1}: most of the entries that
//      would make collect nothing.)
//   4. A while-iteration of class j (a "round") takes all of Q_j, collects, and processes the
//      pairs in collection order (a pair found from both ends is no longer loose the second
//      time: looseness and edges, once lost, never return): a pair still loose gets
//      its off-center r, the apex c' = m + h·J(q − p) with h = 0.95·(ρ + k) as in Triangle
//      (at h = ρ + k the new triangle's angle is θ exactly, which rounding would judge bad
//      again), or the circumcentre of p, q, t when that is no farther from m (the crescent
//      holds t). Entries made meanwhile go to later rounds.
//   5. Sides are segments, as Triangle treats a .poly file: if r lies outside the box, the
//      box edge crossed first by the segment from m to r is split at its midpoint (computed
//      from the edge's (x, y)-smaller end); if r encroaches box edges (its cavity's sides),
//      those are split instead; then the pair is tried again. The crossing lies in the
//      leaf, so halving around it ends with a vertex in the leaf.
//   6. When no queue holds an entry, the Delaunay triangulation is the mesh.
// Every decision is a predicate on the current vertex set, or a key made of coordinates,
// never insertion order or addresses, so the mesh is a function of (box, point set, θ); the
// tests shuffle and reverse the input and compare bits. The triangulation only answers the
// questions quickly (stars, neighbours, cavities). The self-adjusting version answers the
// same questions from the cells of a bucket tree of the vertices instead (each question
// reads O(1) cells near its pair or vertex, docs/HPU_ON_CELLS.md), and must reach the same
// mesh: one algorithm and one oracle.
//
// The self-adjusting version: DynamicMesh with Postprocess::Hpu (dynamic_mesh.hpp) runs
// this algorithm on the runtime (src/hpu/hpu_cells_program.hpp: every question answered from
// the cells of a vertex store, the inputs and side midpoints read from a list the mutator
// keeps, src/hpu/hpu_inputs.hpp), and is bit-identical to this twin after every update
// (tests/dynmesh/dynamic_mesh_test.cpp, hpu_cells_program_test.cpp).
//
// Invariants: check_invariants(): the triangulation's own invariants (Delaunay, tiling) and
// the mesh contract through check_mesh (every angle ≥ θ, every input a vertex).
// Complexity: O(n lg n + m) expected for m output vertices (the inputs triangulated in BRIO
// order, so that cavities are of expected O(1) size whatever the input, points along curves
// included; walks from nearby triangles; O(1) entries per vertex, stars of O(1) size).
// Paper: Acar & Hudson, Figure 5 and Appendix A (DynHPU); Har-Peled & Üngör, "A
// time-optimal Delaunay refinement algorithm in two dimensions" (2005); Üngör,
// "Off-centers" (2004); Ruppert (1995) and Shewchuk's Triangle for segments.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh {

/// The default angle bound of the hpu mesh, in degrees: radius-edge ratio √2, the seed's.
inline constexpr double kHpuDefaultMinAngle = 20.7;
/// The accepted range of --min-angle for hpu.
inline constexpr double kHpuMinAngleLow = 1.0;
inline constexpr double kHpuMinAngleHigh = 30.0;

/// Counts of one refinement (what the mesher did, for reports and tests).
struct HpuStats {
  std::size_t off_centers = 0;    // off-centers inserted (apexes and circumcentres)
  std::size_t circumcentres = 0;  // of which circumcentres
  std::size_t side_splits = 0;    // box edges split at their midpoints
  std::size_t rounds = 0;
  std::size_t triangles_made = 0;  // by every insertion, the final ones included: the work
  std::size_t max_cavity = 0;      // the most triangles one insertion replaced
  std::size_t entries = 0;         // queue entries processed (vertex, class)
  std::size_t loose_pairs = 0;     // loose pairs handled (each inserts or splits a side)
};

class HpuMesh {
 public:
  /// Validates (InputError as QuadtreeMesh reports it, naming point indices; the angle out
  /// of [1, 30] is InputError(Malformed)) and meshes.
  HpuMesh(const Box<2>& box, std::span<const Point<2>> points, double min_angle_deg = kHpuDefaultMinAngle);

  const Box<2>& box() const noexcept { return box_; }
  double min_angle() const noexcept { return min_angle_; }
  /// The triangles, canonical and sorted.
  const std::vector<Triangle>& triangles() const noexcept { return triangles_; }
  Mesh mesh() const { return make_mesh(triangles_); }
  const HpuStats& stats() const noexcept { return stats_; }

  /// The mesh satisfies the contract at the angle bound, Delaunay included. Throws
  /// InvariantError.
  void check_invariants() const;

 private:
  Box<2> box_;
  double min_angle_;
  std::vector<Point<2>> points_;
  std::vector<Triangle> triangles_;
  HpuStats stats_;
};

}  // namespace dynmesh
