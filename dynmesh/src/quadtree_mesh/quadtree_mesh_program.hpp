// quadtree_mesh_program.hpp (private) — the quadtree postprocess written as static code on
// sac-runtime, run after QuadTreeRefine in the same run() (DynamicMesh).
//
// Purpose: the rules of detail/quadtree_mesh_rules.hpp as a program whose trace is local, so
// that a point update changes O(lg L/s) of it:
//
//   main:        place(each input point); then visit(the root)
//   place(p):    descend to p's leaf in T*; target c_t; SPLIT' each level-(t−1) cell
//                touching c_t; mark the leaves around the warped vertex; c_t.pts := p
//   split'(c):   unless c is split: c.split := kRefineSplit; split' each coarser cell
//                touching c (grading)
//   visit(c):    for each child k: split → visit(k), leaf → emit(k)
//   emit(k):     read the side neighbours (midpoints) and, when k is marked, the warping
//                point; make the leaf's triangle block
//
// How it is made stable and order independent:
//   * T' is written into the same `split` modifiables as T*, as later versions: QuadTreeRefine
//     reads earlier in the trace and never sees them, the postprocess reads T' (see
//     kRefineSplit). Marks are leaf values of `split` (low bits 0), read by emit anyway.
//   * p's T* level is found by reading the `split` values down p's path and testing only
//     their T* bit (tree_split): postprocess writes land only on cells T* left unsplit and
//     never set that bit, so the descent sees T* whatever the order of the points. (Reading
//     the point lists instead would re-run every descent through a cell whose list head
//     changed: about one per level per deletion, each re-running its whole tail.)
//   * T' is the least closure of the seeds, a set: the order in which the points add to it
//     changes the trace, not the result. Each point's work is memoized on its list node,
//     so an insertion or deletion re-runs only its own place() and what reads the cells it
//     changes; the walk of T' is memoized per cell, so it re-runs only where split changed.
//   * A leaf's triangles are a keyless allocation (LeafBlock) whose constructor and
//     destructor tell the feed log: what propagation creates and undoes is the change feed.
// Complexity: from scratch O(Σ_p depth(p) + |T'|) events; per update O(lg L/s) expected.
// Paper: Acar & Hudson, Section 4 (dynamizing by change propagation) and Section 5
// (postprocessing the quadtree); Bern, Eppstein & Gilbert (1994).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <sac/engine.hpp>
#include <sac/fn.hpp>

#include "dynmesh/detail/quadtree_mesh_rules.hpp"
#include "dynmesh/mesh.hpp"
#include "mesh/block_feed.hpp"
#include "mesh/point_placement.hpp"
#include "quadtree/quadtree_core.hpp"

namespace dynmesh::detail {

/// A leaf's triangles, as one block of the feed (mesh/block_feed.hpp).
using FeedLog = BlockFeed<LeafShape>;
using LeafBlock = FeedBlock<LeafShape>;

struct QuadtreeMeshProgram {
  using Node = PNode<2>;
  Directory<2>* dir;
  sac::Mod<Node*>* input;
  FeedLog* log;

  using Placement = PointPlacement<2, QuadtreeMeshProgram>;

  Slot<2>& slot(sac::Engine& rt, const CellId<2>& c) { return dir->get(rt, c); }
  const MeshGrid& grid() const { return log->grid; }

  static void main(sac::Engine& rt, QuadtreeMeshProgram* program) {
    rt.memo_read(*program->input, sac::fn<&Placement::place>(program));
    rt.memo(sac::fn<&visit_root>(program));
  }

  // ------------------------------------------------------------------ the points
  static void settle(sac::Engine& rt, QuadtreeMeshProgram* program, Node* n, int tree_level) {
    const auto* in = static_cast<const InputNode<2>*>(n);
    const WarpTarget t = warp_target(program->grid(), n->q, in->point, tree_level);
    for_each_coarser_touching(t.leaf, [&](const CellId<2>& s) { Placement::split(rt, program, s); });
    for_each_marked(t, [&](const CellId<2>& cell, std::uint8_t mark) { Placement::mark(rt, program, cell, mark); });
    rt.write(program->slot(rt, t.leaf).pts, n);
  }

  // ------------------------------------------------------------------ the leaves
  static void visit_root(sac::Engine& rt, QuadtreeMeshProgram* program) { look(rt, program, CellId<2>::root()); }

  static void look(sac::Engine& rt, QuadtreeMeshProgram* program, const CellId<2>& c) {
    rt.read(program->slot(rt, c).split, [program, c](sac::Engine& rt2, std::uint8_t v) {
      if (any_split(v)) rt2.memo(sac::fn<&visit>(program, c));
      else side(rt2, program, LeafShape{c, 0, -1, {}}, v, 0);
    });
  }

  static void visit(sac::Engine& rt, QuadtreeMeshProgram* program, CellId<2> c) {
    for (unsigned w = 0; w < 4; ++w) look(rt, program, child(c, w));
  }

  /// Reads the neighbour across side s (a split one puts a midpoint on the side), then the
  /// next side; after the last, the warping point if the leaf is marked.
  static void side(sac::Engine& rt, QuadtreeMeshProgram* program, LeafShape shape, std::uint8_t mark, unsigned s) {
    CellId<2> nb;
    while (s < 4 && !side_neighbour(shape.cell, s, nb)) ++s;
    if (s == 4) return finish(rt, program, shape, mark);
    rt.read(program->slot(rt, nb).split, [program, shape, mark, s](sac::Engine& rt2, std::uint8_t v) {
      LeafShape next = shape;
      if (any_split(v)) next.midpoints = static_cast<std::uint8_t>(next.midpoints | (1u << s));
      side(rt2, program, next, mark, s + 1);
    });
  }

  static void finish(sac::Engine& rt, QuadtreeMeshProgram* program, LeafShape shape, std::uint8_t mark) {
    if (!is_warped(mark)) {
      rt.make<LeafBlock>(program->log, shape);
      return;
    }
    shape.warped = static_cast<std::int8_t>(warped_corner(mark));
    rt.read(program->slot(rt, warp_source(shape.cell, mark)).pts, [program, shape](sac::Engine& rt2, Node* p) {
      if (!p) throw InvariantError("dynmesh: a warped leaf without its point");
      LeafShape s = shape;
      s.warp_to = static_cast<const InputNode<2>*>(p)->point;
      rt2.make<LeafBlock>(program->log, s);
    });
  }
};

}  // namespace dynmesh::detail
