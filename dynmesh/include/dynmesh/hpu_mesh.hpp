// dynmesh/hpu_mesh.hpp — the off-center quality Delaunay mesh (DynHPU's static twin).
//
// Purpose: a Delaunay mesh of the domain box in which every input point is a vertex and no
// angle is below θ (--min-angle, 1 to 30 degrees; default 20.7, radius-edge ratio ρ = √2),
// with few Steiner points. It refines the Delaunay triangulation of the box's corners and
// the points by off-centers processed in size classes, smallest first (Har-Peled & Üngör's
// order, the seed's Figure 5), and treats the box's sides as segments, as Triangle does with
// a .poly file. It is meant as the oracle and the baseline of the self-adjusting hpu mesh,
// which does not exist yet: see "Next" below.
//
// The algorithm, with the choices the seed leaves open (ρ = 1/(2 sin θ)):
//   1. T := the Delaunay triangulation of the corners and the points (unique: degenerate
//      cases follow a symbolic perturbation by (x, y) rank, src/delaunay.hpp).
//   2. Sides: while a vertex lies strictly inside the diametral circle of a box edge
//      (encroaches it), split the edge at its midpoint (computed from its (x, y)-smaller
//      end). The result is the unique fixed point (midpoints never encroach, and halving an
//      edge only shrinks its circle); it is computed from the points alone, one path down
//      the halvings per point, and inserted before them.
//   3. A triangle is bad when one of its angles is below θ, computed by corner_angle_deg,
//      the checker's own definition (so "no bad triangle" is exactly "the checker's bound
//      holds"). Its key edge pq is its shortest (ties: the edge with the smaller ends in
//      (x, y) order), oriented so that the triangle lies on its left; its size class is
//      ⌊log2 |pq|⌋ (from the double exponent of |pq|²). Every bad triangle is in the
//      bucket of its class.
//   4. Rounds: take the smallest class holding a live bad triangle; its round is every
//      live bad triangle of that class, in the order of their canonical corners. Each, if
//      still live, gets its off-center r: the apex c' = m + (ρ + k)·J(q − p) of pq's leaf
//      (k = √(ρ² − 1/4), m the midpoint, J the +90° turn), or the circumcentre when that
//      is no farther from m than c' (Üngör's off-center; DESIGN.md's crescent rule picks
//      the same point when the triangle's third corner is pq's Delaunay neighbour).
//      Triangles made by the round go to their buckets and are handled by later rounds:
//      rounds are the FIFO of the seed taken one generation at a time.
//   5. Sides again: if r lies outside the box, the box edge the walk towards r leaves by is
//      split at its midpoint; if r encroaches box edges on its cavity's boundary, those are
//      split (in (x, y) order of their ends) instead of inserting r. The triangle, if still
//      live, goes back to its bucket.
//   6. When no bucket holds a live triangle, the triangulation is the mesh.
// Each step depends only on the current vertex set and on keys made of coordinates, never
// on insertion order or addresses, so the mesh is a function of (box, point set, θ).
// Constructions are plain doubles in one fixed sequence of operations.
//
// Next: the self-adjusting version needs every decision local, and these are not: whether a
// bad triangle is still live depends on its circumcircle, which has no bound. The seed's
// formulation is local by construction (loose pairs tested on leaves of radius ρ|pq|, the
// crescent rule bounding the circumcentre used, points kept in quadtree cells by class), so
// the twin is to be rewritten in that form, with this one as its reference for size and
// quality, and then written on the runtime in the tree's trace.
//
// Invariants: check_invariants(): the triangulation's own invariants (Delaunay, tiling) and
// the mesh contract through check_mesh (every angle ≥ θ, every input a vertex).
// Complexity: O(n lg n + m) expected for m output vertices (walks from nearby triangles,
// cavities of expected O(1) size), plus O(m log m) for the rounds' sorting.
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
