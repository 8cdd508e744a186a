// cell_refiner.hpp (private) — the hpu mesh's refinement with every question answered from
// the cells near it (bucket_tree.hpp), never from a triangulation of all vertices.
//
// Purpose: the static form of the self-adjusting hpu program (hpu_cells_program.hpp): the
// same questions (cell_questions.hpp) on a static BucketTree. It takes the static twin's
// decisions (hpu_mesh.cpp, rules 1-6 of dynmesh/hpu_mesh.hpp) in the twin's order and must
// reach the twin's mesh bit for bit; what differs is only where each answer comes from,
// exact searches of the cells (docs/HPU_ON_CELLS.md has the arguments):
//   - the left search: the Delaunay neighbour of p→q on its left (the twin's perturbation
//     breaks ties) is the vertex whose circle through p and q is lowest in their pencil;
//     the cells are asked for the circles at heights 1/2, 1, 2, ... up to a cap, and
//     within the first that holds a vertex the search narrows to the best circle found;
//   - a star: walked by left searches from a sure neighbour (empty closed diametral
//     disc). A collect of class j caps the circles at radius 2^(j+2): a step beyond the
//     cap is a triangle that makes the entry go on, and the edges of class ≤ j inside such
//     a gap are found among the vertices within 2^(j+1) in its angle (a loose one is an
//     edge: its leaf is empty);
//   - a first class: the nearest vertices only (ties), unless rounding at a power of two
//     makes the star decide;
//   - looseness: no vertex strictly inside the leaf, asked of the cells the leaf meets;
//   - an off-center's neighbour: the left search capped at the apex (beyond it the
//     off-center is the apex, whatever the neighbour is);
//   - encroached box edges: only the box edge holding r's projection on a side can have r
//     in its diametral disc; it is in r's cavity unless its triangle's third corner lies
//     strictly inside that disc and its circle misses r;
//   - the final mesh: each vertex's star, each triangle emitted by its (x, y)-smallest
//     corner.
// With CellRefineOptions::log_steps it also logs each step (CellStep) for the locality
// experiment (bench/dynmesh_hpu_locality.cpp).
// Invariants: those of BucketTree after every insertion; the output equals HpuMesh's
// (tests/dynmesh/hpu_cells_test.cpp checks it on every distribution and angle bound).
// Complexity: the twin's steps, each on the vertices of the cells its disc meets: O(1)
// expected in a graded mesh; CellQuestionStats counts them.
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
#include "hpu/cell_questions.hpp"
#include "hpu/star_ledger.hpp"

namespace dynmesh::detail {

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
  Point<2> at{};         // the step's vertex (of a pair: its first end)
  friend bool operator<(const CellStep& a, const CellStep& b) noexcept { return a.digest < b.digest; }
};

struct CellRefinement {
  std::vector<Triangle> triangles;  // canonical, sorted
  HpuStats stats;                   // triangles_made and max_cavity stay 0 (no triangulation)
  CellQuestionStats questions;
  MaintainedStarStats maintained;   // with maintained_stars only
  std::vector<CellStep> steps;      // with log_steps only
};

struct CellRefineOptions {
  bool check_tree = false;  // BucketTree::check_invariants after every insertion (O(n) each)
  bool log_steps = false;   // fill CellRefinement::steps
  bool held_stars = false;  // count what stars held by the cells would save (CellQuestionStats)
  /// Count what stars kept up to date by the walks would answer (star_ledger.hpp;
  /// CellRefinement::maintained). Keeps a shadow triangulation beside the refiner.
  bool maintained_stars = false;
};

/// The hpu mesh of the points (validated as HpuMesh validates them) by cell questions.
CellRefinement cell_refine(const Box<2>& box, std::span<const Point<2>> points, double min_angle_deg,
                           const CellRefineOptions& options = {});

}  // namespace dynmesh::detail
