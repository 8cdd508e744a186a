// hpu_cells_program.hpp (private) — DynHPU's off-center refinement as a self-adjusting program
// on sac-runtime, every question answered from the cells of the vertex store.
//
// Purpose: after run() and after every propagate(), the live triangles equal those of the
// static twin HpuMesh (hpu_mesh.cpp) on the current input points, box and angle, bit for bit.
// It takes the twin's decisions (rules 1-6 of dynmesh/hpu_mesh.hpp) in the twin's order,
// asking the questions of cell_questions.hpp (the same code as the static cell refiner) on a
// view of the cell store (cell_view.hpp):
//   1. the initial vertices: the box's corners in (Morton, xy) order, then the input list
//      (the inputs and their side midpoints in insertion_less order, kept by the mutator,
//      hpu_inputs.hpp), whose vertices are also the store's base values (cell_store.hpp);
//   2. each initial vertex's class (its shortest Delaunay edge's): a step; and, per block of
//      the initial list (cut where a vertex's coordinates hash to it, about 32 long), the set
//      of its classes and its vertices linked by class mod 64, in list order; the smallest
//      and the largest class from the blocks' sets;
//   3. per class j, smallest first: Q_j = (initial entries of class j, in initial order, from
//      the blocks whose set holds j, each walked along its links of j's class mod 64) ++
//      (continuations made during class j − 1); rounds: collect every entry of the round (a
//      step, memoized apart from the list: its loose pairs into the entry's own list, and its
//      continuation into the entry's `cont`, which the list step links into Q_{j+1}),
//      then process the pairs in collection order (each try a step: not loose, split box
//      edges, or insert the off-center; an insertion is a step that writes the store's leaf;
//      a Steiner vertex is the pool's object at its point, steiner_vertices.hpp);
//      births (off-centers and side midpoints) form the next round;
//   4. the final mesh: a pass over the store's newest leaves; a memoized step per vertex of
//      a leaf finds the triangles whose (x, y)-smallest corner it is, from its star, and
//      makes them one block of the change feed (hpu_mesh_feed.hpp).
// Lists by destination passing, with the memo keys that keep an update local
// (docs/EXPERIMENTS.md, "What made the trace distance flat"): every list cell is a keyed
// allocation (an entry by (vertex, class, birth), a pair by (its collector's entry, p, q), a
// class by j, a round by the modifiable holding its first entry), a list step's key holds its
// predecessor's predecessor, and phases that follow a list pass are issued after it as
// siblings. Q_j's initial entries are the exception: they append at a tail held in a
// modifiable per (class, block), so a vertex that joins or leaves class j re-runs the next
// member's append, not every step up to it. A step that does not depend on its place (an
// entry's collect, a pair's tries, a vertex's final triangles) is a memo of its own keyed
// without it: the collect and the tries with Engine::memo_near, so that an entry that an
// update moved far runs anew rather than undoing all the trace up to its old step. Each step
// reads its cells as a few multi-reads (cell_view.hpp), so its cost is a few events however
// many vertices it looks at, and it re-runs only when a cell it read changes.
// Invariants: those of the twin's rules; every list is terminated by its pass before a later
// phase reads it; a vertex has at most one entry per class, so the entry keys are unique in a
// run; a step writes, allocates and issues only in the round whose view did not fail.
// Complexity: the twin's steps (O(n lg n + m) expected), each O(1) cells in a graded mesh. An
// update re-runs the steps whose cells it changes, plus list steps up to the next cell
// appended as before, and a class's tail copies up to the next block that holds it
// (bench/RESULTS.md, docs/EXPERIMENTS.md).
// Paper: Acar & Hudson, Figure 5 and Appendix A (DynHPU), Section 4; Har-Peled & Üngör (2005);
// Üngör, "Off-centers" (2004); Acar, Ahmed & Blume (2008) for keyed allocation and
// destination passing.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include <sac/engine.hpp>
#include <sac/fn.hpp>
#include <sac/mod.hpp>

#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"
#include "hpu/cell_questions.hpp"
#include "hpu/cell_store.hpp"
#include "hpu/step_rounds.hpp"
#include "hpu/hpu_geometry.hpp"
#include "hpu/hpu_inputs.hpp"
#include "hpu/hpu_cells_state.hpp"
#include "hpu/hpu_mesh_feed.hpp"

namespace dynmesh::detail {

using HV = const CellVertex*;

struct HcPair;

/// A queue entry (the twin's Entry), keyed by (vertex, class, birth).
struct HcEntry {
  HcEntry(HV x, bool b) : v(x), birth(b) {}
  HcEntry(const HcEntry&) = delete;
  HcEntry& operator=(const HcEntry&) = delete;
  HV v;
  bool birth;
  sac::Mod<HcEntry*> next;
  sac::Mod<HcPair*> pairs;  // the loose pairs its collect found, in order
  sac::Mod<HcEntry*> cont;  // its collect's continuation into Q_{j+1} (null: none)
};

/// The births of one pair's tries, in order: the first, and the last one's `next` (where
/// the births after them link in). head null: none.
struct HcBirths {
  HcEntry* head = nullptr;
  sac::Mod<HcEntry*>* tail = nullptr;
  friend bool operator==(const HcBirths&, const HcBirths&) = default;
};

/// A collected pair p→q, keyed by (its collector's entry, p, q).
struct HcPair {
  HcPair(HV a, HV b) : p(a), q(b) {}
  HcPair(const HcPair&) = delete;
  HcPair& operator=(const HcPair&) = delete;
  HV p;
  HV q;
  sac::Mod<HcPair*> next;
  sac::Mod<HcBirths> births;  // its tries' births (try_pair)
};

/// An initial vertex, keyed by it: its class, and the rest of the list.
struct HcCell {
  explicit HcCell(HV x) : v(x) {}
  HcCell(const HcCell&) = delete;
  HcCell& operator=(const HcCell&) = delete;
  HV v;
  sac::Mod<int> cls;
  sac::Mod<HcCell*> next;
  sac::Mod<HcCell*> next_same;  // the next vertex of its block whose class is ≡ its own mod 64
};

/// A size class, keyed by j.
struct HcClass {
  explicit HcClass(int c) : j(c) {}
  HcClass(const HcClass&) = delete;
  HcClass& operator=(const HcClass&) = delete;
  int j;
  sac::Mod<HcEntry*> init;  // Q_j: the initial entries of class j, then `cont`
  sac::Mod<HcEntry*> cont;  // the continuations made during class j − 1
};

/// The classes of a block's initial vertices: bit c mod 64 for each class c, the largest and
/// the smallest.
struct HcClassSet {
  std::uint64_t mask = 0;
  int max = INT_MIN;
  int min = INT_MAX;
  bool has(int c) const noexcept { return (mask >> (static_cast<unsigned>(c) & 63)) & 1; }
  friend bool operator==(const HcClassSet&, const HcClassSet&) = default;
};

/// A block of the initial vertices: from the one that opens it (HpuCellsProgram::opens_block;
/// the list's head for the first) to the next block's. Keyed by that vertex (null: the first).
struct HcCellBlock {
  explicit HcCellBlock(HcCell* f) : first(f) {}
  HcCellBlock(const HcCellBlock&) = delete;
  HcCellBlock& operator=(const HcCellBlock&) = delete;
  HcCell* first;
  sac::Mod<HcClassSet> classes;
  sac::Mod<HcCellBlock*> next;
  // The block's vertices by class mod 64, in list order: the first of each (head), and where
  // the next goes (tail, while the walk of the block runs). A class's walk of the block
  // passes its own members only (HpuCellsProgram::class_member).
  std::array<sac::Mod<HcCell*>, 64> head;  // written only for the classes the block holds
  std::array<sac::Mod<sac::Mod<HcCell*>*>, 64> tail;
};

/// Class j's place in a block of the initial vertices, keyed by (j, the block's first
/// vertex): the tail Q_j's initial entries append at. Each append reads it and writes the new
/// one, and the block's last step copies it into the next block's.
struct HcBlock {
  HcBlock() = default;
  HcBlock(const HcBlock&) = delete;
  HcBlock& operator=(const HcBlock&) = delete;
  sac::Mod<sac::Mod<HcEntry*>*> init_tail;
};

/// A round, keyed by the modifiable holding its first entry.
struct HcRound {
  HcRound() = default;
  HcRound(const HcRound&) = delete;
  HcRound& operator=(const HcRound&) = delete;
  sac::Mod<HcEntry*> births;               // the next round
  sac::Mod<sac::Mod<HcEntry*>*> cont_tail;  // Q_{j+1}'s tail after this round's collect
};

/// The run's fixed state (allocated once by main, which never re-runs).
struct HcStart {
  HcStart() = default;
  HcStart(const HcStart&) = delete;
  HcStart& operator=(const HcStart&) = delete;
  sac::Mod<HcCell*> cells;  // the initial vertices, in order
  sac::Mod<int> min_class;  // the smallest initial class
  sac::Mod<int> max_class;  // the largest
  HcCellBlock* blocks = nullptr;  // the first block of the initial vertices
};

/// Steps completed (first run included, re-runs of change propagation too), by kind.
struct HcStepCounts {
  enum Kind : std::uint8_t { FirstClass, Collect, Try, Insert, Final, kKinds };
  std::array<std::uint64_t, kKinds> done{};
  std::uint64_t total() const noexcept {
    std::uint64_t t = 0;
    for (auto x : done) t += x;
    return t;
  }
};

/// The program. The mutator keeps `input` equal to the inputs and their side midpoints in
/// insertion_less order, and the store's base values equal to the bucket tree of those and
/// the four corners (HpuInputs with InputCells attached), and calls propagate().
struct HpuCellsProgram {
  struct Coords {
    const Point<2>& operator()(HV v) const noexcept { return v->p; }
  };
  using Questions = CellQuestions<CellView, HV, Coords>;

  HpuCellsProgram(sac::Engine& e, CellDirectory& d, sac::Mod<HpuInputNode*>& in,
                  const std::array<const CellVertex*, 4>& box_corners, double min_angle_deg, HpuMeshFeed& f,
                  SteinerVertices& sv)
      : dir(&d), input(&in), corners(box_corners), feed(&f), steiner(&sv), view(e, d),
        q(d.box(), min_angle_deg, view, Coords{}, nullptr, stats) {}
  HpuCellsProgram(sac::Engine& e, HpuCellsState& st, double min_angle_deg)
      : HpuCellsProgram(e, st.cells, st.inputs.head(), st.corner_vertices(), min_angle_deg, st.feed, st.steiner) {}
  HpuCellsProgram(const HpuCellsProgram&) = delete;
  HpuCellsProgram& operator=(const HpuCellsProgram&) = delete;

  CellDirectory* dir;
  sac::Mod<HpuInputNode*>* input;
  std::array<const CellVertex*, 4> corners;
  HpuMeshFeed* feed;
  SteinerVertices* steiner;
  HcStart* start = nullptr;
  CellView view;  // the running step's (steps run one at a time)
  CellQuestionStats stats;
  HcStepCounts steps;
  Questions q;
  // Scratch of the running step: its answers, which a run in a kept view takes as they are
  // (CellView::kept()).
  int first_class = 0;
  bool go_on = false;
  std::vector<std::array<HV, 2>> pairs, tris;
  CellDecision<HV> decision;
  CellNode* at_node = nullptr;
  const CellState* at_state = nullptr;
  std::vector<Triangle> block;

  const Box<2>& box() const noexcept { return dir->box(); }
  /// The distance scale of class j.
  static double scale_of(int j) noexcept { return std::ldexp(1.0, std::clamp(j, -1070, 1020)); }

  // ---------------------------------------------------------------- 1. initial vertices

  static void main(sac::Engine& e, HpuCellsProgram* pg) {
    pg->start = e.alloc<HcStart>(0);
    std::array<HV, 4> order = pg->corners;
    std::sort(order.begin(), order.end(), [pg](HV a, HV b) { return morton_less(pg->box(), a->p, b->p); });
    sac::Mod<HcCell*>* dest = &pg->start->cells;
    HcCell* head = nullptr;  // the list's first cell: a corner's, fixed
    for (HV v : order) {
      HcCell* c = e.alloc<HcCell>(v, v);
      e.write(*dest, c);
      dest = &c->next;
      if (!head) head = c;
    }
    e.memo_read(*pg->input, sac::fn<&place>(pg, dest));
    e.memo_read(pg->start->cells, sac::fn<&class_step>(pg));
    // The corners come first, so the list's head is a fixed cell.
    pg->start->blocks = e.alloc<HcCellBlock>(HV{nullptr}, head);
    e.memo(sac::fn<&block_classes>(pg->start->blocks->first, pg, pg->start->blocks, std::uint64_t{0}, INT_MIN, INT_MAX));
    e.memo(sac::fn<&block_bounds>(pg->start->blocks, pg, INT_MAX, INT_MIN));
    e.memo(sac::fn<&refine_start>(pg));
    e.memo(sac::fn<&final_start>(pg));
  }

  static sac::Mod<HcCell*>* append_cell(sac::Engine& e, HV v, sac::Mod<HcCell*>* dest) {
    HcCell* c = e.alloc<HcCell>(v, v);
    e.write(*dest, c);
    return &c->next;
  }

  static void place(sac::Engine& e, HpuInputNode* n, HpuCellsProgram* pg, sac::Mod<HcCell*>* dest) {
    if (!n) return e.write(*dest, nullptr);
    dest = append_cell(e, n, dest);
    e.memo_read(n->next, sac::fn<&place>(pg, dest));
  }

  // ---------------------------------------------------------------- 2. initial classes

  /// The class of an initial vertex. Its key holds nothing of the vertices before it: with
  /// the least class so far in it, an update that changed that least class ran every step
  /// after again (7,488 nearest searches in one update at uniform 10^5); the least class is
  /// now the blocks' (block_bounds). The view's searches take no scale, so none is guessed.
  struct FirstClassStep {
    HpuCellsProgram* pg;
    HcCell* cell;
    CellView* view(sac::Engine&) const { return &pg->view; }
    const Box<2>& box() const noexcept { return pg->box(); }
    const CellDirectory& dir() const noexcept { return *pg->dir; }
    bool run(sac::Engine& e, CellView& v) const {
      if (!v.kept()) pg->first_class = pg->q.first_class(cell->v, pg->box().side / 4);
      if (!v.done()) return false;
      ++pg->steps.done[HcStepCounts::FirstClass];
      e.write(cell->cls, pg->first_class);
      e.memo_read(cell->next, sac::fn<&class_step>(pg));
      return true;
    }
  };

  static void class_step(sac::Engine& e, HcCell* cell, HpuCellsProgram* pg) {
    if (cell) run_step(e, FirstClassStep{pg, cell});
  }

  // ---------------------------------------------------------------- 3. classes and rounds

  static void refine_start(sac::Engine& e, HpuCellsProgram* pg) {
    e.read(pg->start->min_class, [pg](sac::Engine& e2, int j) {
      HcClass* cs = e2.alloc<HcClass>(j, j);
      e2.write(cs->cont, nullptr);  // nothing continues into the first class
      e2.memo(sac::fn<&class_start>(pg, cs));
    });
  }

  /// One in about kBlockSpan initial vertices opens a block, chosen by its coordinates
  /// (never by an address, so the blocks are the same in every run). The mix is a short one
  /// (two shifts, one multiply), not sac::mix64: its values place the block boundaries, and
  /// with them the trace, so it stays as it is.
  static constexpr std::uint64_t kBlockSpan = 32;
  static bool opens_block(HV v) noexcept {
    std::uint64_t h = std::bit_cast<std::uint64_t>(v->p[0]) * sac::kGoldenGamma ^ std::bit_cast<std::uint64_t>(v->p[1]);
    h ^= h >> 31;
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 29;
    return h % kBlockSpan == 0;
  }

  /// The classes of block b's initial vertices from `cell` on, given those before it (mask,
  /// max), and the block's vertices linked by class: `cell` goes after the last vertex of its
  /// class mod 64, through that class's tail. A class that changes re-runs the steps after it
  /// in its block only, and the next member's link of the classes it left and joined.
  static void block_classes(sac::Engine& e, HcCell* cell, HpuCellsProgram* pg, HcCellBlock* b, std::uint64_t mask,
                            int max, int min) {
    e.read(cell->cls, [cell, pg, b, mask, max, min](sac::Engine& e2, int c) {
      const unsigned k = static_cast<unsigned>(c) & 63;
      if (!((mask >> k) & 1)) {
        e2.write(b->head[k], cell);
        e2.write(b->tail[k], &cell->next_same);
      } else {
        e2.read(b->tail[k], [cell, b, k](sac::Engine& e3, sac::Mod<HcCell*>* qd) {
          e3.write(*qd, cell);
          e3.write(b->tail[k], &cell->next_same);
        });
      }
      e2.memo_read(cell->next,
                   sac::fn<&block_classes_next>(pg, b, mask | std::uint64_t{1} << k, std::max(max, c), std::min(min, c)));
    });
  }

  static void block_classes_next(sac::Engine& e, HcCell* nx, HpuCellsProgram* pg, HcCellBlock* b, std::uint64_t mask,
                                 int max, int min) {
    if (nx && !opens_block(nx->v)) return block_classes(e, nx, pg, b, mask, max, min);
    e.write(b->classes, HcClassSet{mask, max, min});
    for (std::uint64_t m = mask; m; m &= m - 1)
      e.read(b->tail[static_cast<unsigned>(std::countr_zero(m))],
             [](sac::Engine& e2, sac::Mod<HcCell*>* qd) { e2.write(*qd, nullptr); });
    if (!nx) return e.write(b->next, nullptr);
    HcCellBlock* nb = e.alloc<HcCellBlock>(nx->v, nx);
    e.write(b->next, nb);
    block_classes(e, nx, pg, nb, 0, INT_MIN, INT_MAX);
  }

  /// The smallest and the largest initial class, from the blocks' sets, in a walk of the
  /// blocks. A block that changes the least or the greatest so far re-runs this walk up to
  /// the next block beyond it, a step per block with no question asked. Threaded through
  /// the first-class steps instead, a new least class re-ran every one after it; threaded
  /// through each class's walk of the blocks ("a block before holds a class above j"), a
  /// change of the first block above j re-ran that class's walk up to the next.
  static void block_bounds(sac::Engine& e, HcCellBlock* cb, HpuCellsProgram* pg, int mn, int mx) {
    e.read(cb->classes, [cb, pg, mn, mx](sac::Engine& e2, const HcClassSet& set) {
      e2.memo_read(cb->next, sac::fn<&block_bounds_next>(pg, std::min(mn, set.min), std::max(mx, set.max)));
    });
  }

  static void block_bounds_next(sac::Engine& e, HcCellBlock* cb, HpuCellsProgram* pg, int mn, int mx) {
    if (cb) return block_bounds(e, cb, pg, mn, mx);
    e.write(pg->start->min_class, mn);
    e.write(pg->start->max_class, mx);
  }

  /// Class j: its initial entries from the blocks that hold some, then its rounds.
  static void class_start(sac::Engine& e, HpuCellsProgram* pg, HcClass* cs) {
    HcClass* csn = e.alloc<HcClass>(cs->j + 1, cs->j + 1);
    HcBlock* b = e.alloc<HcBlock>(std::tuple{cs->j, HV{nullptr}});
    e.write(b->init_tail, &cs->init);
    e.memo(sac::fn<&class_block>(pg->start->blocks, pg, cs, b));
    e.memo(sac::fn<&round>(pg, cs, csn, &cs->init, &csn->cont));
  }

  /// Class j in block cb: its members appended at b's tail, which the next block's copy
  /// continues.
  /// The tail is a modifiable, not an argument: with it in the key, a vertex that joined or
  /// left the class gave every step after it a new key up to the next member, thousands of
  /// steps at the class holding most vertices. Through the tail's versions it re-runs the
  /// next member's append, or the copies up to the next block with a member. A block bounds
  /// a tail's versions, which the runtime walks from the newest to read or write at a time:
  /// one tail for the whole class was as exact, and several times slower (bench/RESULTS.md,
  /// "Class lists by block").
  static void class_block(sac::Engine& e, HcCellBlock* cb, HpuCellsProgram* pg, HcClass* cs, HcBlock* b) {
    e.read(cb->classes, [cb, pg, cs, b](sac::Engine& e2, const HcClassSet& set) {
      if (set.has(cs->j)) e2.memo_read(cb->head[static_cast<unsigned>(cs->j) & 63], sac::fn<&class_member>(pg, cs, b));
      HcBlock* nb = e2.alloc<HcBlock>(std::tuple{cs->j, cb->first->v});
      e2.read(b->init_tail, [nb](sac::Engine& e3, sac::Mod<HcEntry*>* qd) { e3.write(nb->init_tail, qd); });
      e2.memo_read(cb->next, sac::fn<&class_block_next>(pg, cs, nb));
    });
  }

  static void class_block_next(sac::Engine& e, HcCellBlock* cb, HpuCellsProgram* pg, HcClass* cs, HcBlock* b) {
    if (cb) return class_block(e, cb, pg, cs, b);
    // Q_j = its initial entries ++ the continuations of class j − 1 (terminated by now).
    e.read(b->init_tail, [cs](sac::Engine& e2, sac::Mod<HcEntry*>* qd) {
      e2.read(cs->cont, [qd](sac::Engine& e3, HcEntry* h) { e3.write(*qd, h); });
    });
  }

  /// One initial vertex of class j mod 64 in a block: appended to Q_j's initial entries if of
  /// class j. The walk passes the block's members of j's class mod 64 only: it used to pass
  /// every vertex of the block, five for each member (bench/RESULTS.md, "Class walks over a
  /// block's members").
  static void class_member(sac::Engine& e, HcCell* cell, HpuCellsProgram* pg, HcClass* cs, HcBlock* b) {
    if (!cell) return;
    e.read(cell->cls, [cell, cs, b](sac::Engine& e2, int c) {
      if (c != cs->j) return;
      HcEntry* ent = e2.alloc<HcEntry>(std::tuple{cell->v, cs->j, true}, cell->v, true);
      e2.read(b->init_tail, [b, ent](sac::Engine& e3, sac::Mod<HcEntry*>* qd) {
        e3.write(*qd, ent);
        e3.write(b->init_tail, &ent->next);
      });
    });
    e.memo_read(cell->next_same, sac::fn<&class_member>(pg, cs, b));
  }

  /// A round of class j on the entries from `head`: collect all, then process the pairs,
  /// then the next round (the births) or the next class.
  static void round(sac::Engine& e, HpuCellsProgram* pg, HcClass* cs, HcClass* csn, sac::Mod<HcEntry*>* head,
                    sac::Mod<HcEntry*>* cdest) {
    HcRound* rs = e.alloc<HcRound>(head);
    e.memo_read(*head, sac::fn<&collect_step>(pg, cs, rs, cdest, nullptr, nullptr));
    e.memo_read(*head, sac::fn<&process_entry>(pg, cs, rs, &rs->births, nullptr, nullptr));
    e.memo(sac::fn<&round_end>(pg, cs, csn, rs));
  }

  static void round_end(sac::Engine& e, HpuCellsProgram* pg, HcClass* cs, HcClass* csn, HcRound* rs) {
    e.read(rs->births, [pg, cs, csn, rs](sac::Engine& e2, HcEntry* b) {
      e2.read(rs->cont_tail, [pg, cs, csn, rs, b](sac::Engine& e3, sac::Mod<HcEntry*>* tail) {
        if (b) return e3.memo(sac::fn<&round>(pg, cs, csn, &rs->births, tail));
        e3.write(*tail, nullptr);
        e3.memo(sac::fn<&class_end>(pg, cs, csn));
      });
    });
  }

  /// The next class when anything is left: continuations, or initial vertices above j.
  static void class_end(sac::Engine& e, HpuCellsProgram* pg, HcClass* cs, HcClass* csn) {
    e.read(csn->cont, [pg, cs, csn](sac::Engine& e2, HcEntry* c) {
      e2.read(pg->start->max_class, [pg, cs, csn, c](sac::Engine& e3, int max) {
        if (c || cs->j < max) e3.memo(sac::fn<&class_start>(pg, csn));
      });
    });
  }

  // ---------------------------------------------------------------- collect

  /// The twin's collect(v, j, birth): loose pairs (both sides, of class j, ≤ j at a birth) in
  /// (x, y) order, and v's continuation into Q_{j+1}.
  struct CollectStep {
    HpuCellsProgram* pg;
    HcClass* cs;
    HcRound* rs;
    HcEntry* ent;
    CellView* view(sac::Engine&) const { return &pg->view; }
    const Box<2>& box() const noexcept { return pg->box(); }
    const CellDirectory& dir() const noexcept { return *pg->dir; }
    bool run(sac::Engine& e, CellView& v) const {
      const int j = cs->j;
      if (!v.kept()) pg->go_on = pg->q.collect(ent->v, j, ent->birth, pg->pairs);
      if (!v.done()) return false;
      ++pg->steps.done[HcStepCounts::Collect];
      // The entry's own list: no tail threads through the round, so a change in one
      // entry's pairs does not change the keys of the (mostly pairless) entries after it.
      sac::Mod<HcPair*>* pd = &ent->pairs;
      for (const auto& [a, b] : pg->pairs) {
        HcPair* pc = e.alloc<HcPair>(std::tuple{ent, a, b}, a, b);
        e.write(*pd, pc);
        pd = &pc->next;
      }
      e.write(*pd, nullptr);
      e.write(ent->cont, pg->go_on ? e.alloc<HcEntry>(std::tuple{ent->v, j + 1, false}, ent->v, false) : nullptr);
      return true;
    }
  };

  /// The collect of ent, memoized apart from the list step: its key holds no destination
  /// and no place, so an entry that an update gave another predecessor keeps its collect.
  /// The old call is reused only when it is at most kCollectReach stamps ahead
  /// (Engine::memo_near): an entry that an update moved matched its old collect far ahead,
  /// and the hit discarded all the trace in between (a deletion at uniform 32,000 re-ran
  /// 10,020 collects when the key held ent alone and the reuse had no bound).
  static constexpr std::uint32_t kCollectReach = 64;
  static void collect_entry(sac::Engine& e, HpuCellsProgram* pg, HcClass* cs, HcRound* rs, HcEntry* ent) {
    run_step(e, CollectStep{pg, cs, rs, ent});
  }

  /// ent was read from owner's `next` (owner null: the round's head). owner's predecessor
  /// is in the key: when an update moves an entry earlier in the list, its own `next` and the
  /// destinations can be those of its old step far ahead, which would then match and discard
  /// everything in between; with the predecessor it runs anew in place.
  static void collect_step(sac::Engine& e, HcEntry* ent, HpuCellsProgram* pg, HcClass* cs, HcRound* rs,
                           sac::Mod<HcEntry*>* cdest, HcEntry* owner, HcEntry* owner_pred) {
    (void)owner_pred;
    if (!ent) return e.write(rs->cont_tail, cdest);
    // The continuations' tail threads through the list, and a continuation that appears or
    // goes changes it for every entry up to the next one that continues. So the collect
    // itself is a memo of its own, which such a change re-runs as a hit, and only this
    // link step runs again.
    e.memo_near(kCollectReach, sac::fn<&collect_entry>(pg, cs, rs, ent));
    e.read(ent->cont, [pg, cs, rs, cdest, ent, owner](sac::Engine& e2, HcEntry* c) {
      sac::Mod<HcEntry*>* cd = cdest;
      if (c) {
        e2.write(*cd, c);
        cd = &c->next;
      }
      e2.memo_read(ent->next, sac::fn<&collect_step>(pg, cs, rs, cd, ent, owner));
    });
  }

  // ---------------------------------------------------------------- process

  /// Where a pair's tries stand: the pair, and the births so far (the first, and where the
  /// next goes; null: none yet).
  struct Ctx {
    HpuCellsProgram* pg;
    HcClass* cs;
    HcRound* rs;
    HcPair* pc;
    HcEntry* head;
    sac::Mod<HcEntry*>* bdest;
  };

  static void process_entry(sac::Engine& e, HcEntry* nent, HpuCellsProgram* pg, HcClass* cs, HcRound* rs,
                            sac::Mod<HcEntry*>* bdest, HcEntry* owner, HcEntry* owner_pred) {
    (void)owner_pred;
    if (!nent) return e.write(*bdest, nullptr);
    e.memo_read(nent->pairs, sac::fn<&process_step>(pg, cs, rs, bdest, nent, owner, nullptr, nullptr));
  }

  static void process_step(sac::Engine& e, HcPair* pc, HpuCellsProgram* pg, HcClass* cs, HcRound* rs,
                           sac::Mod<HcEntry*>* bdest, HcEntry* ent, HcEntry* ent_prev, HcPair* owner,
                           HcPair* owner_pred) {
    (void)owner_pred;
    if (!pc) return e.memo_read(ent->next, sac::fn<&process_entry>(pg, cs, rs, bdest, ent, ent_prev));
    // The tries are a memo of their own, as a collect is: their key holds neither the births'
    // tail nor the pair's place, which an earlier pair's births or an update to the lists
    // change for every pair after it. They hand their births over in pc->births, and only
    // this link step runs again for such a change.
    e.memo_near(kTryReach, sac::fn<&try_pair>(pg, cs, rs, pc));
    e.read(pc->births, [pg, cs, rs, bdest, ent, ent_prev, pc, owner](sac::Engine& e2, const HcBirths& b) {
      sac::Mod<HcEntry*>* bd = bdest;
      if (b.head) {
        e2.write(*bd, b.head);
        bd = b.tail;
      }
      e2.memo_read(pc->next, sac::fn<&process_step>(pg, cs, rs, bd, ent, ent_prev, pc, owner));
    });
  }

  static constexpr std::uint32_t kTryReach = 64;
  static void try_pair(sac::Engine& e, HpuCellsProgram* pg, HcClass* cs, HcRound* rs, HcPair* pc) {
    run_step(e, TryStep{Ctx{pg, cs, rs, pc, nullptr, nullptr}});
  }

  /// The pair is done: its births go to the link step.
  static void done(sac::Engine& e, const Ctx& c) { e.write(c.pc->births, HcBirths{c.head, c.bdest}); }

  /// x was inserted: its birth entry joins the next round, after the pair's births before it.
  static Ctx birth(sac::Engine& e, Ctx c, HV x) {
    HcEntry* ent = e.alloc<HcEntry>(std::tuple{x, c.cs->j, true}, x, true);
    if (c.head) e.write(*c.bdest, ent);
    else c.head = ent;
    c.bdest = &ent->next;
    return c;
  }

  /// The Steiner vertex at p: one object per point for as long as the trace holds it
  /// (steiner_vertices.hpp), so a try that re-runs elsewhere in the trace hands the steps
  /// that read it the vertex they saw.
  static const CellVertex* steiner_at(sac::Engine& e, HpuCellsProgram* pg, const Point<2>& p) {
    return e.alloc<SteinerRef>(std::pair{p[0], p[1]}, pg->steiner, p)->v;
  }

  /// Box edges to split, in order.
  struct Splits {
    std::array<std::array<HV, 2>, 4> s{};
    std::uint32_t n = 0;
  };

  /// One try of the twin's process(p, q, j) loop.
  struct TryStep {
    Ctx c;
    CellView* view(sac::Engine&) const { return &c.pg->view; }
    const Box<2>& box() const noexcept { return c.pg->box(); }
    const CellDirectory& dir() const noexcept { return *c.pg->dir; }
    bool run(sac::Engine& e, CellView& v) const {
      HpuCellsProgram* pg = c.pg;
      if (!v.kept()) pg->decision = pg->q.decide(c.pc->p, c.pc->q, c.cs->j);
      if (!v.done()) return false;
      const CellDecision<HV> d = pg->decision;  // a copy: the steps it issues use the scratch
      ++pg->steps.done[HcStepCounts::Try];
      switch (d.kind) {
        case CellDecision<HV>::Done:
          done(e, c);
          break;
        case CellDecision<HV>::Split: {
          Splits sp;
          if (d.splits.size() > sp.s.size()) throw InvariantError("dynmesh: more than four box edges to split");
          for (const auto& s : d.splits) sp.s[sp.n++] = s;
          split_next(e, c, sp, 0);
          break;
        }
        case CellDecision<HV>::Insert: {
          const CellVertex* x = steiner_at(e, pg, d.at);
          run_step(e, InsertStep<AfterOffCenter>{pg, x, c.cs->j, AfterOffCenter{c}});
          break;
        }
      }
      return true;
    }
  };

  struct AfterOffCenter {
    Ctx c;
    void operator()(sac::Engine& e, HV x) const { done(e, birth(e, c, x)); }
  };

  /// Splits sp.s[i..] in order, then tries the pair again.
  static void split_next(sac::Engine& e, const Ctx& c, const Splits& sp, std::uint32_t i) {
    if (i == sp.n) return run_step(e, TryStep{c});
    const Point<2> mid = side_midpoint(sp.s[i][0]->p, sp.s[i][1]->p);
    const CellVertex* m = steiner_at(e, c.pg, mid);
    run_step(e, InsertStep<AfterSplit>{c.pg, m, c.cs->j, AfterSplit{c, sp, i}});
  }

  struct AfterSplit {
    Ctx c;
    Splits sp;
    std::uint32_t i;
    void operator()(sac::Engine& e, HV x) const { split_next(e, birth(e, c, x), sp, i + 1); }
  };

  /// Inserts x into the store at this time (the leaf that holds it now gets its next value,
  /// or splits), then k(e, x).
  template <class K>
  struct InsertStep {
    HpuCellsProgram* pg;
    HV x;
    int j;
    K k;
    CellView* view(sac::Engine&) const { return &pg->view; }
    const Box<2>& box() const noexcept { return pg->box(); }
    const CellDirectory& dir() const noexcept { return *pg->dir; }
    bool run(sac::Engine& e, CellView& v) const {
      if (!v.kept()) std::tie(pg->at_node, pg->at_state) = v.locate(pg->dir->position(x->p), scale_of(j));
      if (!v.done()) return false;
      CellNode* const node = pg->at_node;
      const CellState* const s = pg->at_state;
      ++pg->steps.done[HcStepCounts::Insert];
      std::array<HV, CellState::kCapacity + 1> items;
      std::size_t n = 0;
      for (std::size_t i = 0; i < s->count; ++i) {
        if (s->items[i]->p == x->p) throw InvariantError("dynmesh: a Steiner vertex inserted twice");
        items[n++] = s->items[i];
      }
      items[n++] = x;
      put(e, pg, node, std::span<HV>(items.data(), n));
      k(e, x);
      return true;
    }
  };

  /// Writes n's value holding `items` (n's cell), splitting while they overflow: the children
  /// first, then n (no read sees a split without its children).
  static void put(sac::Engine& e, HpuCellsProgram* pg, CellNode* n, std::span<HV> items) {
    if (items.size() <= CellState::kCapacity) return e.write(n->state, CellState::leaf(items.begin(), items.end()));
    if (n->key.level >= BucketTree::kMaxLevel)
      throw InvariantError("dynmesh: the cell store: vertices closer than the finest cell");
    std::array<std::array<HV, CellState::kCapacity + 1>, 4> part;
    std::array<std::size_t, 4> count{};
    for (HV w : items) {
      const CellKey c = CellDirectory::cell_at(pg->dir->position(w->p), n->key.level + 1);
      const unsigned k = CellDirectory::child_index(c);
      part[k][count[k]++] = w;
    }
    for (unsigned k = 0; k < 4; ++k)
      put(e, pg, pg->dir->node(e, n->key.child(k)), std::span<HV>(part[k].data(), count[k]));
    e.write(n->state, CellState::split());
  }

  // ---------------------------------------------------------------- 4. the final mesh

  static void final_start(sac::Engine& e, HpuCellsProgram* pg) {
    e.memo(sac::fn<&final_node>(pg, pg->dir->node(e, CellKey{})));
  }

  static void final_node(sac::Engine& e, HpuCellsProgram* pg, CellNode* n) {
    e.read(n->state, [pg, n](sac::Engine& e2, const CellState& s) {
      if (s.kind == CellState::Split) {
        for (unsigned k = 0; k < 4; ++k) e2.memo(sac::fn<&final_node>(pg, pg->dir->node(e2, n->key.child(k))));
      } else if (s.kind == CellState::Leaf) {
        // One step a vertex, each memoized on the vertex alone: when the leaf gains or loses
        // a vertex, splits or merges, the others' steps are found again with their reads,
        // and a change near one vertex re-runs its star walk only, not the leaf's.
        for (std::size_t i = 0; i < s.count; ++i) e2.memo(sac::fn<&final_vertex>(pg, s.items[i]));
      }
    });
  }

  static void final_vertex(sac::Engine& e, HpuCellsProgram* pg, HV a) { run_step(e, FinalStep{pg, a}); }

  /// The triangles whose (x, y)-smallest corner is a, as one block.
  struct FinalStep {
    HpuCellsProgram* pg;
    HV a;
    CellView* view(sac::Engine&) const { return &pg->view; }
    const Box<2>& box() const noexcept { return pg->box(); }
    const CellDirectory& dir() const noexcept { return *pg->dir; }
    bool run(sac::Engine& e, CellView& v) const {
      if (!v.kept()) {
        pg->block.clear();
        // The view's nearest search starts at a's leaf and ignores the scale, so the step
        // is a function of a alone, whichever leaf holds it.
        pg->q.triangles_of(a, 0.0, pg->tris);
        for (const auto& [b, c] : pg->tris) pg->block.push_back(canonical_triangle(a->p, b->p, c->p));
      }
      if (!v.done()) return false;
      ++pg->steps.done[HcStepCounts::Final];
      if (!pg->block.empty()) e.make<HpuTriBlock>(pg->feed, std::span<const Triangle>(pg->block));
      return true;
    }
  };
};

}  // namespace dynmesh::detail
