// cell_refiner.hpp (private) — the hpu mesh's refinement with every question answered from
// the cells near it (bucket_tree.hpp), never from a triangulation of all vertices.
//
// Purpose: the blueprint of the cell-based self-adjusting hpu program. It takes the static
// twin's decisions (hpu_mesh.cpp, rules 1-6 of dynmesh/hpu_mesh.hpp) in the twin's order and
// must reach the twin's mesh bit for bit; what differs is only where each answer comes from:
//   - a vertex's first class and its entry's collect: the star of v in the Delaunay
//     triangulation of the vertices within a radius of v (a local triangulation, same
//     predicates and perturbation as the twin's). A local triangle whose circumdisc lies
//     inside the gathered disc is a true one; the true star shows in full once every local
//     star triangle is such, and otherwise it holds a triangle with circumradius above half
//     the radius (the continuation rule needs no more: the radius is 2^(j+2) for class j);
//   - looseness: no vertex strictly inside the leaf, asked of the cells the leaf meets (an
//     empty leaf makes pq a Delaunay edge, so no triangulation is needed to say "edge");
//   - an off-center's Delaunay neighbour t: the local triangulation of the disc around pq's
//     midpoint that holds every circle through p and q centred no farther than the apex
//     (when t lies beyond it, the off-center is the apex whatever t is);
//   - encroached box edges: only the box edge holding r's projection on a side can have r
//     in its diametral disc; it is in r's cavity unless a vertex inside that disc makes its
//     triangle's circle miss r, which the local triangulation of the disc decides;
//   - the final mesh: each vertex's local star, each triangle emitted by its (x, y)-smallest
//     corner.
// Invariants: those of BucketTree after every insertion; the output equals HpuMesh's
// (tests/dynmesh/hpu_cells_test.cpp checks it on every distribution and angle bound).
// Complexity: the twin's steps, each on the vertices of the cells its disc meets: O(1)
// expected in a graded mesh; CellQuestionStats counts them (bench/RESULTS.md).
// Paper: Acar & Hudson, Figure 5 and Appendix A; Har-Peled & Üngör (2005), whose
// algorithm answers the same questions from the quadtree's cells.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh::detail {

/// What the cell questions cost: the figures a self-adjusting version pays in reads.
struct CellQuestionStats {
  std::size_t stars = 0;           // stars walked (first classes, collects, final mesh)
  std::size_t leaf_tests = 0;      // loose tests asked of the cells
  std::size_t neighbour_asks = 0;  // left searches (star steps, off-centers, box edges)
  std::size_t leaves_read = 0;     // bucket-tree leaves met by all questions
  std::size_t gathered_first = 0;  // vertices looked at for first classes
  // Leaves read by the collects, by the pairs' processing and by the final mesh.
  std::size_t leaves_collect = 0, leaves_process = 0, leaves_final = 0;
};

/// One step of the refinement as a self-adjusting version would record it: a digest of its
/// key (what it is: a vertex's first class, an entry's collect, a pair's processing, a
/// vertex's final triangles), of every vertex the cells it read handed it, and of its
/// answer; and the leaves it read. Two runs on point sets that differ by one point share
/// every step that a change-propagation of that update would leave alone, so the steps of
/// one run that the other lacks (a multiset difference) bound the update's trace distance
/// from above, up to the cost of each step (bench/dynmesh_hpu_locality.cpp).
struct CellStep {
  enum Kind : std::uint8_t { FirstClass, Collect, Process, Final };
  std::uint64_t digest;
  std::uint32_t leaves;  // distinct leaves read
  Kind kind;
  std::int16_t cls;      // the size class of a collect or a pair's processing; 0 otherwise
  friend bool operator<(const CellStep& a, const CellStep& b) noexcept { return a.digest < b.digest; }
};

struct CellRefinement {
  std::vector<Triangle> triangles;  // canonical, sorted
  HpuStats stats;                   // triangles_made and max_cavity stay 0 (no triangulation)
  CellQuestionStats questions;
  std::vector<CellStep> steps;      // with log_steps only
};

struct CellRefineOptions {
  bool check_tree = false;  // BucketTree::check_invariants after every insertion (O(n) each)
  bool log_steps = false;   // fill CellRefinement::steps
};

/// The hpu mesh of the points (validated as HpuMesh validates them) by cell questions.
CellRefinement cell_refine(const Box<2>& box, std::span<const Point<2>> points, double min_angle_deg,
                           const CellRefineOptions& options = {});

}  // namespace dynmesh::detail
