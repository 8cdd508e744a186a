// point_placement.hpp (private) — the part of a tree mesh's program that places each input
// point in the refined tree T': shared by the quadtree mesh (2D) and the octree mesh (3D).
//
// Purpose:
//   place(p):    for each node of the input list: descend(p); then the next node
//   descend(p):  read cell_of(q, l).split down p's path, steered by its T* bit alone
//                (tree_split), to p's T* leaf level l; then Program::settle(p, l), which
//                picks p's target, splits what it needs with split() and marks its cells
//   split(c):    unless c is split: c.split := kRefineSplit; split each coarser cell touching
//                c (grading)
//   mark(c, m):  unless c is split: c.split := m, a leaf's mark (low two bits 0), read by the
//                walk that makes c's simplices
// Why it is stable and order independent: the postprocess writes land only on cells T* left
// unsplit and never set the T* bit, so a descent sees T* whatever the order of the points;
// T' is the least closure of the seeds, a set, so the order in which points add to it changes
// the trace, not the result; each point's work is memoized on its list node, so an insertion
// or deletion re-runs only its own descent and what reads the cells it changes.
// Program provides `Slot<d>& slot(sac::Engine&, const CellId<d>&)` and
// `static void settle(sac::Engine&, Program*, PNode<d>*, int tree_level)`.
// Complexity: O(depth(p)) events per point; split O(1) per cell it newly splits.
// Paper: Acar & Hudson, Section 4; the grading of Section 2.
#pragma once

#include <cstddef>
#include <cstdint>

#include <sac/engine.hpp>
#include <sac/fn.hpp>

#include "dynmesh/cell.hpp"
#include "dynmesh/detail/cell_table.hpp"
#include "quadtree/quadtree_refine.hpp"

namespace dynmesh::detail {

template <std::size_t d, class Program>
struct PointPlacement {
  using Node = PNode<d>;

  static void place(sac::Engine& rt, Node* n, Program* program) {
    if (!n) return;
    rt.memo(sac::fn<&descend>(program, n, 0));
    rt.memo_read(n->next, sac::fn<&place>(program));
  }

  static void descend(sac::Engine& rt, Program* program, Node* n, int l) {
    if (l >= kMaxLevel) return Program::settle(rt, program, n, kMaxLevel);
    rt.read(program->slot(rt, cell_of(n->q, l)).split, [program, n, l](sac::Engine& rt2, std::uint8_t v) {
      if (tree_split(v)) descend(rt2, program, n, l + 1);
      else Program::settle(rt2, program, n, l);
    });
  }

  // The closures hold their cell packed (8·d bytes, not 8·d + 8): T' makes one split or mark
  // read for each of its cells.
  static void split(sac::Engine& rt, Program* program, const CellId<d>& c) {
    rt.read(program->slot(rt, c).split, [program, k = pack_cell<d>(c)](sac::Engine& rt2, std::uint8_t v) {
      if (any_split(v)) return;
      const CellId<d> cell = unpack_cell<d>(k);
      rt2.write(program->slot(rt2, cell).split, kRefineSplit);
      if (cell.level > 0) for_each_coarser_touching(cell, [&](const CellId<d>& u) { split(rt2, program, u); });
    });
  }

  static void mark(sac::Engine& rt, Program* program, const CellId<d>& c, std::uint8_t value) {
    rt.read(program->slot(rt, c).split, [program, k = pack_cell<d>(c), value](sac::Engine& rt2, std::uint8_t v) {
      // A split value here would break the closure's rule; the checkers report it.
      if (!any_split(v)) rt2.write(program->slot(rt2, unpack_cell<d>(k)).split, value);
    });
  }
};

}  // namespace dynmesh::detail
