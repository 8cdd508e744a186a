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
//   emit(k):     read the side neighbours (midpoints; one read of all four) and, when k is
//                marked, the warping point; make the leaf's triangle block
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

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
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
    rt.read(program->slot(rt, c).split, [program, k = pack_cell<2>(c)](sac::Engine& rt2, std::uint8_t v) {
      const CellId<2> cell = unpack_cell<2>(k);
      if (any_split(v)) rt2.memo(sac::fn<&visit>(program, cell));
      else sides(rt2, program, cell, v);
    });
  }

  static void visit(sac::Engine& rt, QuadtreeMeshProgram* program, CellId<2> c) {
    for (unsigned w = 0; w < 4; ++w) look(rt, program, child(c, w));
  }

  /// The leaf's sides as one read (Engine::read_many) of the neighbours across them, in side
  /// order: a split one puts a midpoint on its side. One event a leaf rather than one a
  /// side, and a closure of 32 bytes rather than four of 64: T' has about 30 leaves a point.
  struct SideRead {
    QuadtreeMeshProgram* program;
    PackedCell<2> cell;
    std::uint8_t mark;     // the leaf's own `split` value (its marks)
    std::uint8_t present;  // bit s: side s has a neighbour in the box, read in side order
    void operator()(sac::Engine& rt, std::span<const std::uint8_t* const> v) const {
      LeafShape shape{unpack_cell<2>(cell), 0, -1, {}};
      std::size_t i = 0;
      for (unsigned s = 0; s < 4; ++s)
        if ((present >> s) & 1u) {
          if (any_split(*v[i])) shape.midpoints = static_cast<std::uint8_t>(shape.midpoints | (1u << s));
          ++i;
        }
      finish(rt, program, shape, mark);
    }
  };
  static void sides(sac::Engine& rt, QuadtreeMeshProgram* program, const CellId<2>& c, std::uint8_t mark) {
    std::array<const sac::Mod<std::uint8_t>*, 4> mods{};
    std::uint8_t present = 0;
    std::size_t k = 0;
    for (unsigned s = 0; s < 4; ++s)
      if (CellId<2> nb; side_neighbour(c, s, nb)) {
        mods[k++] = &program->slot(rt, nb).split;
        present = static_cast<std::uint8_t>(present | (1u << s));
      }
    if (k == 0) return finish(rt, program, LeafShape{c, 0, -1, {}}, mark);  // the root alone
    rt.read_many(std::span<const sac::Mod<std::uint8_t>* const>(mods.data(), k),
                 SideRead{program, pack_cell<2>(c), mark, present});
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
