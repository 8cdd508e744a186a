// hpu_cells_program.hpp (private) — DynHPU's off-center refinement as a self-adjusting program
// on sac-runtime, every question answered from the cells of the vertex store.
//
// Purpose: after run() and after every propagate(), the live triangles equal those of the
// static twin HpuMesh (hpu_mesh.cpp) on the current input points, box and angle, bit for bit.
// It takes the twin's decisions (rules 1-6 of dynmesh/hpu_mesh.hpp) in the twin's order,
// asking the questions of cell_questions.hpp (the same code as the static cell refiner) on a
// view of the cell store (cell_view.hpp), each step run by the protocol of step_rounds.hpp:
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
// (docs/HPU_ON_CELLS.md, "The rest"): every list cell is a keyed
// allocation (an entry by (vertex, class, birth), a pair by (its collector's entry, p, q), a
// class by j, a round by the modifiable holding its first entry), a list step's key holds its
// predecessor's predecessor, and phases that follow a list pass are issued after it as
// siblings. Q_j's initial entries are the exception: they append at a tail held in a
// modifiable per (class, block), so a vertex that joins or leaves class j re-runs the next
// member's append, not every step up to it. A step that does not depend on its place (an
// entry's collect, a pair's tries, a vertex's final triangles) is a memo of its own keyed
// without it: the collect and the tries with Engine::memo_near, so that an entry that an
// update moved far runs anew rather than undoing all the trace up to its old step. Each step
// reads its cells as a few multi-reads (step_rounds.hpp), so its cost is a few events however
// many vertices it looks at, and it re-runs only when a cell it read changes.
// Invariants: those of the twin's rules; every list is terminated by its pass before a later
// phase reads it; a vertex has at most one entry per class, so the entry keys are unique in a
// run; a step writes, allocates and issues only in the round whose view did not fail.
// Complexity: the twin's steps (O(n lg n + m) expected), each O(1) cells in a graded mesh. An
// update re-runs the steps whose cells it changes, plus list steps up to the next cell
// appended as before, and a class's tail copies up to the next block that holds it.
// Paper: Acar & Hudson, Figure 5 and Appendix A (DynHPU), Section 4; Har-Peled & Üngör (2005);
// Üngör, "Off-centers" (2004); Acar, Ahmed & Blume (2008) for keyed allocation and
// destination passing; docs/DESIGN.md, "DynHPU"; docs/HPU_ON_CELLS.md, "The
// self-adjusting program".
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
  HcEntry(HV vertex, bool is_birth) : v(vertex), birth(is_birth) {}
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
  HcPair(HV from, HV to) : p(from), q(to) {}
  HcPair(const HcPair&) = delete;
  HcPair& operator=(const HcPair&) = delete;
  HV p;
  HV q;
  sac::Mod<HcPair*> next;
  sac::Mod<HcBirths> births;  // its tries' births (try_pair)
};

/// An initial vertex, keyed by it: its class, and the rest of the list.
struct HcCell {
  explicit HcCell(HV vertex) : v(vertex) {}
  HcCell(const HcCell&) = delete;
  HcCell& operator=(const HcCell&) = delete;
  HV v;
  sac::Mod<int> cls;
  sac::Mod<HcCell*> next;
  sac::Mod<HcCell*> next_same;  // the next vertex of its block whose class is ≡ its own mod 64
};

/// A size class, keyed by j.
struct HcClass {
  explicit HcClass(int size_class) : j(size_class) {}
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
  explicit HcCellBlock(HcCell* opener) : first(opener) {}
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

/// A round, keyed by the modifiable holding its first entry, which also names its class (a
/// class's initial list, or a round's births). It holds its class, so the steps and list
/// steps of the round name the round only.
struct HcRound {
  explicit HcRound(HcClass* c) : size_class(c) {}
  HcRound(const HcRound&) = delete;
  HcRound& operator=(const HcRound&) = delete;
  HcClass* size_class;
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
    for (auto count : done) t += count;
    return t;
  }
};

/// The program. The mutator sets its engine's context to it (Engine::set_context) and runs
/// main(); it keeps `input` equal to the inputs and their side midpoints in
/// insertion_less order, and the store's base values equal to the bucket tree of those and
/// the four corners (HpuInputs with InputCells attached), and calls propagate().
struct HpuCellsProgram {
  struct Coords {
    const Point<2>& operator()(HV v) const noexcept { return v->p; }
  };
  using Questions = CellQuestions<CellView, HV, Coords>;

  HpuCellsProgram(sac::Engine& rt, CellDirectory& cells, sac::Mod<HpuInputNode*>& inputs,
                  const std::array<const CellVertex*, 4>& box_corners, double min_angle_deg, HpuMeshFeed& out,
                  SteinerVertices& steiner_pool)
      : dir(&cells), input(&inputs), corners(box_corners), feed(&out), steiner(&steiner_pool), view(rt, cells),
        questions(cells.box(), min_angle_deg, view, Coords{}, nullptr, stats) {}
  HpuCellsProgram(sac::Engine& rt, HpuCellsState& state, double min_angle_deg)
      : HpuCellsProgram(rt, state.cells, state.inputs.head(), state.corner_vertices(), min_angle_deg, state.feed,
                        state.steiner) {}
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
  Questions questions;
  // Scratch of the running step: its answers, which a run in a kept view takes as they are
  // (S4a of step_rounds.hpp, CellView::kept()).
  int first_class = 0;
  bool go_on = false;
  std::vector<std::array<HV, 2>> pairs, tris;
  CellDecision<HV> decision;
  CellNode* at_node = nullptr;
  const CellState* at_state = nullptr;

  const Box<2>& box() const noexcept { return dir->box(); }
  /// The distance scale of class j.
  static double scale_of(int j) noexcept { return std::ldexp(1.0, std::clamp(j, -1070, 1020)); }

  /// The program, from its engine's context: no closure carries it (8 bytes a record). The
  /// steps' projection test gets the engine for it too (sac::Engine::read_many).
  static HpuCellsProgram* ctx(const sac::Engine& rt) { return rt.context<HpuCellsProgram>(); }

  /// What the five steps (FirstClassStep, CollectStep, TryStep, InsertStep, FinalStep) share:
  /// the part of run_step's Step interface that comes from the program, whose view, store and
  /// scratch they use (step_rounds.hpp). Each step adds its own operands and run(). A step is
  /// its rounds' closure, so it holds pointers only.
  struct StepBase {
    static CellView* view(const sac::Engine& rt) { return &ctx(rt)->view; }
    static const Box<2>& box(const sac::Engine& rt) { return ctx(rt)->box(); }
    static const CellDirectory& dir(const sac::Engine& rt) { return *ctx(rt)->dir; }
  };

  // ---------------------------------------------------------------- 1. initial vertices

  /// The computation: the owner sets the engine's context to the program first.
  static void main(sac::Engine& rt) {
    HpuCellsProgram* const program = ctx(rt);
    program->start = rt.alloc<HcStart>(0);
    std::array<HV, 4> order = program->corners;
    std::sort(order.begin(), order.end(), [program](HV a, HV b) { return morton_less(program->box(), a->p, b->p); });
    sac::Mod<HcCell*>* dest = &program->start->cells;
    HcCell* head = nullptr;  // the list's first cell: a corner's, fixed
    for (HV v : order) {
      HcCell* c = rt.alloc<HcCell>(v, v);
      rt.write(*dest, c);
      dest = &c->next;
      if (!head) head = c;
    }
    rt.memo_read(*program->input, sac::fn<&place>(dest));
    rt.memo_read(program->start->cells, sac::fn<&class_step>());
    // The corners come first, so the list's head is a fixed cell.
    program->start->blocks = rt.alloc<HcCellBlock>(HV{nullptr}, head);
    rt.memo(sac::fn<&block_classes>(program->start->blocks->first, program->start->blocks, std::uint64_t{0},
                                    INT_MIN, INT_MAX));
    rt.memo(sac::fn<&block_bounds>(program->start->blocks, INT_MAX, INT_MIN));
    rt.memo(sac::fn<&refine_start>());
    rt.memo(sac::fn<&final_start>());
  }

  static sac::Mod<HcCell*>* append_cell(sac::Engine& rt, HV v, sac::Mod<HcCell*>* dest) {
    HcCell* c = rt.alloc<HcCell>(v, v);
    rt.write(*dest, c);
    return &c->next;
  }

  static void place(sac::Engine& rt, HpuInputNode* n, sac::Mod<HcCell*>* dest) {
    if (!n) return rt.write(*dest, nullptr);
    dest = append_cell(rt, n, dest);
    rt.memo_read(n->next, sac::fn<&place>(dest));
  }

  // ---------------------------------------------------------------- 2. initial classes

  /// The class of an initial vertex. Its key holds nothing of the vertices before it: a
  /// running least class in the key would change for every step after a vertex whose class
  /// an update lowered, and re-run them all; the least class comes from the blocks instead
  /// (block_bounds). The view's searches take no scale, so none is guessed.
  struct FirstClassStep : StepBase {
    HcCell* cell;
    bool run(sac::Engine& rt, CellView& v) const {
      HpuCellsProgram* const program = ctx(rt);
      if (!v.kept()) program->first_class = program->questions.first_class(cell->v, program->box().side / 4);
      if (!v.done()) return false;
      ++program->steps.done[HcStepCounts::FirstClass];
      rt.write(cell->cls, program->first_class);
      rt.memo_read(cell->next, sac::fn<&class_step>());
      return true;
    }
  };

  static void class_step(sac::Engine& rt, HcCell* cell) {
    if (cell) run_step(rt, FirstClassStep{{}, cell});
  }

  // ---------------------------------------------------------------- 3. classes and rounds

  static void refine_start(sac::Engine& rt) {
    HpuCellsProgram* const program = ctx(rt);
    rt.read(program->start->min_class, [](sac::Engine& rt2, int j) {
      HcClass* size_class = rt2.alloc<HcClass>(j, j);
      rt2.write(size_class->cont, nullptr);  // nothing continues into the first class
      rt2.memo(sac::fn<&class_start>(size_class));
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

  /// The classes of the block's initial vertices from `cell` on, given those before it (mask,
  /// max), and the block's vertices linked by class: `cell` goes after the last vertex of its
  /// class mod 64, through that class's tail. A class that changes re-runs the steps after it
  /// in its block only, and the next member's link of the classes it left and joined.
  static void block_classes(sac::Engine& rt, HcCell* cell, HcCellBlock* block,
                            std::uint64_t mask, int max, int min) {
    rt.read(cell->cls, [cell, block, mask, max, min](sac::Engine& rt2, int c) {
      const unsigned k = static_cast<unsigned>(c) & 63;
      if (!((mask >> k) & 1)) {
        rt2.write(block->head[k], cell);
        rt2.write(block->tail[k], &cell->next_same);
      } else {
        rt2.read(block->tail[k], [cell, block, k](sac::Engine& rt3, sac::Mod<HcCell*>* dest) {
          rt3.write(*dest, cell);
          rt3.write(block->tail[k], &cell->next_same);
        });
      }
      rt2.memo_read(cell->next, sac::fn<&block_classes_next>(block, mask | std::uint64_t{1} << k,
                                                             std::max(max, c), std::min(min, c)));
    });
  }

  static void block_classes_next(sac::Engine& rt, HcCell* next, HcCellBlock* block,
                                 std::uint64_t mask, int max, int min) {
    if (next && !opens_block(next->v)) return block_classes(rt, next, block, mask, max, min);
    rt.write(block->classes, HcClassSet{mask, max, min});
    for (std::uint64_t m = mask; m; m &= m - 1)
      rt.read(block->tail[static_cast<unsigned>(std::countr_zero(m))],
             [](sac::Engine& rt2, sac::Mod<HcCell*>* dest) { rt2.write(*dest, nullptr); });
    if (!next) return rt.write(block->next, nullptr);
    HcCellBlock* next_block = rt.alloc<HcCellBlock>(next->v, next);
    rt.write(block->next, next_block);
    block_classes(rt, next, next_block, 0, INT_MIN, INT_MAX);
  }

  /// The smallest and the largest initial class, from the blocks' sets, in a walk of the
  /// blocks. A block that changes the least or the greatest so far re-runs this walk up to
  /// the next block beyond it, a step per block with no question asked. Not threaded through
  /// the first-class steps, where a new least class would re-run every one after it; nor
  /// through each class's walk of the blocks ("a block before holds a class above j"), where
  /// a change of the first block above j would re-run that class's walk up to the next.
  static void block_bounds(sac::Engine& rt, HcCellBlock* block, int least, int greatest) {
    rt.read(block->classes, [block, least, greatest](sac::Engine& rt2, const HcClassSet& set) {
      rt2.memo_read(block->next,
                    sac::fn<&block_bounds_next>(std::min(least, set.min), std::max(greatest, set.max)));
    });
  }

  static void block_bounds_next(sac::Engine& rt, HcCellBlock* block, int least,
                                int greatest) {
    HpuCellsProgram* const program = ctx(rt);
    if (block) return block_bounds(rt, block, least, greatest);
    rt.write(program->start->min_class, least);
    rt.write(program->start->max_class, greatest);
  }

  /// Class j: its initial entries from the blocks that hold some, then its rounds.
  static void class_start(sac::Engine& rt, HcClass* size_class) {
    HpuCellsProgram* const program = ctx(rt);
    HcClass* next_class = rt.alloc<HcClass>(size_class->j + 1, size_class->j + 1);
    HcBlock* class_tail = rt.alloc<HcBlock>(std::tuple{size_class->j, HV{nullptr}});
    rt.write(class_tail->init_tail, &size_class->init);
    rt.memo(sac::fn<&class_block>(program->start->blocks, size_class, class_tail));
    rt.memo(sac::fn<&round_start>(size_class, next_class, &size_class->init, &next_class->cont));
  }

  /// Class j in `block`: its members appended at class_tail's tail, which the next block's
  /// copy continues.
  /// The tail is a modifiable, not an argument: with it in the key, a vertex that joined or
  /// left the class would give every step after it a new key up to the next member. Through
  /// the tail's versions it re-runs the next member's append, or the copies up to the next
  /// block with a member. A tail per block, not one for the whole class: the runtime walks a
  /// modifiable's versions from the newest to read or write at a time, and a block bounds
  /// how many a tail has.
  static void class_block(sac::Engine& rt, HcCellBlock* block, HcClass* size_class,
                          HcBlock* class_tail) {
    rt.read(block->classes, [block, size_class, class_tail](sac::Engine& rt2, const HcClassSet& set) {
      if (set.has(size_class->j))
        rt2.memo_read(block->head[static_cast<unsigned>(size_class->j) & 63],
                      sac::fn<&class_member>(size_class, class_tail));
      HcBlock* next_class_tail = rt2.alloc<HcBlock>(std::tuple{size_class->j, block->first->v});
      rt2.read(class_tail->init_tail, [next_class_tail](sac::Engine& rt3, sac::Mod<HcEntry*>* dest) {
        rt3.write(next_class_tail->init_tail, dest);
      });
      rt2.memo_read(block->next, sac::fn<&class_block_next>(size_class, next_class_tail));
    });
  }

  static void class_block_next(sac::Engine& rt, HcCellBlock* block, HcClass* size_class,
                               HcBlock* class_tail) {
    if (block) return class_block(rt, block, size_class, class_tail);
    // Q_j = its initial entries ++ the continuations of class j − 1 (terminated by now).
    rt.read(class_tail->init_tail, [size_class](sac::Engine& rt2, sac::Mod<HcEntry*>* dest) {
      rt2.read(size_class->cont, [dest](sac::Engine& rt3, HcEntry* h) { rt3.write(*dest, h); });
    });
  }

  /// One initial vertex of class j mod 64 in a block: appended to Q_j's initial entries if of
  /// class j. The walk passes the block's members of j's class mod 64 only (next_same), not
  /// every vertex of the block.
  static void class_member(sac::Engine& rt, HcCell* cell, HcClass* size_class,
                           HcBlock* class_tail) {
    if (!cell) return;
    rt.read(cell->cls, [cell, size_class, class_tail](sac::Engine& rt2, int c) {
      if (c != size_class->j) return;
      HcEntry* entry = rt2.alloc<HcEntry>(std::tuple{cell->v, size_class->j, true}, cell->v, true);
      rt2.read(class_tail->init_tail, [class_tail, entry](sac::Engine& rt3, sac::Mod<HcEntry*>* dest) {
        rt3.write(*dest, entry);
        rt3.write(class_tail->init_tail, &entry->next);
      });
    });
    rt.memo_read(cell->next_same, sac::fn<&class_member>(size_class, class_tail));
  }

  /// A round of class j on the entries from `head`: collect all, then process the pairs,
  /// then the next round (the births) or the next class.
  static void round_start(sac::Engine& rt, HcClass* size_class, HcClass* next_class,
                          sac::Mod<HcEntry*>* head, sac::Mod<HcEntry*>* cont_dest) {
    HcRound* round = rt.alloc<HcRound>(head, size_class);
    rt.memo_read(*head, sac::fn<&collect_step>(round, cont_dest, nullptr, nullptr));
    rt.memo_read(*head, sac::fn<&process_entry>(round, &round->births, nullptr, nullptr));
    rt.memo(sac::fn<&round_end>(size_class, next_class, round));
  }

  static void round_end(sac::Engine& rt, HcClass* size_class, HcClass* next_class,
                        HcRound* round) {
    rt.read(round->births, [size_class, next_class, round](sac::Engine& rt2, HcEntry* births) {
      rt2.read(round->cont_tail,
               [size_class, next_class, round, births](sac::Engine& rt3, sac::Mod<HcEntry*>* tail) {
                 if (births)
                   return rt3.memo(sac::fn<&round_start>(size_class, next_class, &round->births, tail));
                 rt3.write(*tail, nullptr);
                 rt3.memo(sac::fn<&class_end>(size_class, next_class));
               });
    });
  }

  /// The next class when anything is left: continuations, or initial vertices above j.
  static void class_end(sac::Engine& rt, HcClass* size_class, HcClass* next_class) {
    rt.read(next_class->cont, [size_class, next_class](sac::Engine& rt2, HcEntry* cont) {
      HpuCellsProgram* const program = ctx(rt2);
      rt2.read(program->start->max_class, [size_class, next_class, cont](sac::Engine& rt3, int max) {
        if (cont || size_class->j < max) rt3.memo(sac::fn<&class_start>(next_class));
      });
    });
  }

  // ---------------------------------------------------------------- collect

  /// The twin's collect(v, j, birth): loose pairs (both sides, of class j, ≤ j at a birth) in
  /// (x, y) order, and v's continuation into Q_{j+1}.
  struct CollectStep : StepBase {
    HcRound* round;
    HcEntry* entry;
    bool run(sac::Engine& rt, CellView& v) const {
      HpuCellsProgram* const program = ctx(rt);
      const int j = round->size_class->j;
      if (!v.kept()) program->go_on = program->questions.collect(entry->v, j, entry->birth, program->pairs);
      if (!v.done()) return false;
      ++program->steps.done[HcStepCounts::Collect];
      // The entry's own list: no tail threads through the round, so a change in one
      // entry's pairs does not change the keys of the (mostly pairless) entries after it.
      sac::Mod<HcPair*>* pairs_dest = &entry->pairs;
      for (const auto& [a, b] : program->pairs) {
        HcPair* pair = rt.alloc<HcPair>(std::tuple{entry, a, b}, a, b);
        rt.write(*pairs_dest, pair);
        pairs_dest = &pair->next;
      }
      rt.write(*pairs_dest, nullptr);
      rt.write(entry->cont,
               program->go_on ? rt.alloc<HcEntry>(std::tuple{entry->v, j + 1, false}, entry->v, false) : nullptr);
      return true;
    }
  };

  /// The collect of an entry, memoized apart from the list step: its key holds no destination
  /// and no place, so an entry that an update gave another predecessor keeps its collect.
  /// The old call is reused only when it is at most kCollectReach stamps ahead
  /// (Engine::memo_near): an entry that an update moved would match its old collect far
  /// ahead, and the hit would discard all the trace in between.
  static constexpr std::uint32_t kCollectReach = 64;
  static void collect_entry(sac::Engine& rt, HcRound* round, HcEntry* entry) {
    run_step(rt, CollectStep{{}, round, entry});
  }

  /// entry was read from owner's `next` (owner null: the round's head). owner's predecessor
  /// is in the key: when an update moves an entry earlier in the list, its own `next` and the
  /// destinations can be those of its old step far ahead, which would then match and discard
  /// everything in between; with the predecessor it runs anew in place.
  static void collect_step(sac::Engine& rt, HcEntry* entry, HcRound* round, sac::Mod<HcEntry*>* cont_dest,
                           HcEntry* owner, HcEntry* owner_pred) {
    // owner_pred is in the memo key only: without it, an entry an update moved earlier
    // could match its old step far ahead (same entry, next and destination), and the hit
    // would discard the trace in between; with it the step runs anew in place.
    (void)owner_pred;
    if (!entry) return rt.write(round->cont_tail, cont_dest);
    // The continuations' tail threads through the list, and a continuation that appears or
    // goes changes it for every entry up to the next one that continues. So the collect
    // itself is a memo of its own, which such a change re-runs as a hit, and only this
    // link step runs again.
    rt.memo_near(kCollectReach, sac::fn<&collect_entry>(round, entry));
    rt.read(entry->cont, [round, cont_dest, entry, owner](sac::Engine& rt2, HcEntry* cont) {
      sac::Mod<HcEntry*>* dest = cont_dest;
      if (cont) {
        rt2.write(*dest, cont);
        dest = &cont->next;
      }
      rt2.memo_read(entry->next, sac::fn<&collect_step>(round, dest, entry, owner));
    });
  }

  // ---------------------------------------------------------------- process

  /// Where a pair's tries stand: the pair, and the births so far (the first, and where the
  /// next goes; null: none yet).
  struct PairTries : StepBase {
    HcRound* round;
    HcPair* pair;
    HcEntry* head;
    sac::Mod<HcEntry*>* births_dest;
  };

  static void process_entry(sac::Engine& rt, HcEntry* entry, HcRound* round, sac::Mod<HcEntry*>* births_dest,
                            HcEntry* owner, HcEntry* owner_pred) {
    // owner_pred is in the memo key only: without it, an entry an update moved earlier
    // could match its old step far ahead (same entry, next and destination), and the hit
    // would discard the trace in between; with it the step runs anew in place.
    (void)owner_pred;
    if (!entry) return rt.write(*births_dest, nullptr);
    rt.memo_read(entry->pairs,
                 sac::fn<&process_step>(round, births_dest, entry, owner, nullptr, nullptr));
  }

  static void process_step(sac::Engine& rt, HcPair* pair, HcRound* round, sac::Mod<HcEntry*>* births_dest,
                           HcEntry* entry, HcEntry* entry_prev, HcPair* owner, HcPair* owner_pred) {
    // owner_pred is in the memo key only (entry_prev too, for process_entry's): without it,
    // a pair an update moved earlier could match its old step far ahead (same pair, next and
    // destination), and the hit would discard the trace in between.
    (void)owner_pred;
    if (!pair)
      return rt.memo_read(entry->next,
                          sac::fn<&process_entry>(round, births_dest, entry, entry_prev));
    // The tries are a memo of their own, as a collect is: their key holds neither the births'
    // tail nor the pair's place, which an earlier pair's births or an update to the lists
    // change for every pair after it. They hand their births over in pair->births, and only
    // this link step runs again for such a change.
    rt.memo_near(kTryReach, sac::fn<&try_pair>(round, pair));
    rt.read(pair->births, [round, births_dest, entry, entry_prev, pair, owner](
                              sac::Engine& rt2, const HcBirths& births) {
      sac::Mod<HcEntry*>* dest = births_dest;
      if (births.head) {
        rt2.write(*dest, births.head);
        dest = births.tail;
      }
      rt2.memo_read(pair->next,
                    sac::fn<&process_step>(round, dest, entry, entry_prev, pair, owner));
    });
  }

  static constexpr std::uint32_t kTryReach = 64;
  static void try_pair(sac::Engine& rt, HcRound* round, HcPair* pair) {
    run_step(rt, TryStep{PairTries{{}, round, pair, nullptr, nullptr}});
  }

  /// The pair is done: its births go to the link step.
  static void done(sac::Engine& rt, const PairTries& tries) {
    rt.write(tries.pair->births, HcBirths{tries.head, tries.births_dest});
  }

  /// v was inserted: its birth entry joins the next round, after the pair's births before it.
  static PairTries birth(sac::Engine& rt, PairTries tries, HV v) {
    HcEntry* entry = rt.alloc<HcEntry>(std::tuple{v, tries.round->size_class->j, true}, v, true);
    if (tries.head) rt.write(*tries.births_dest, entry);
    else tries.head = entry;
    tries.births_dest = &entry->next;
    return tries;
  }

  /// The Steiner vertex at p: one object per point for as long as the trace holds it
  /// (steiner_vertices.hpp), so a try that re-runs elsewhere in the trace hands the steps
  /// that read it the vertex they saw.
  static const CellVertex* steiner_at(sac::Engine& rt, HpuCellsProgram* program, const Point<2>& p) {
    return rt.alloc<SteinerRef>(std::pair{p[0], p[1]}, program->steiner, p)->v;
  }

  /// Box edges to split, in order.
  struct Splits {
    std::array<std::array<HV, 2>, 4> s{};
    std::uint32_t n = 0;
  };

  /// One try of the twin's process(p, q, j) loop.
  struct TryStep : PairTries {
    bool run(sac::Engine& rt, CellView& v) const {
      HpuCellsProgram* const program = ctx(rt);
      if (!v.kept()) program->decision = program->questions.decide(pair->p, pair->q, round->size_class->j);
      if (!v.done()) return false;
      const CellDecision<HV> decision = program->decision;  // a copy: the steps it issues use the scratch
      ++program->steps.done[HcStepCounts::Try];
      switch (decision.kind) {
        case CellDecision<HV>::Done:
          done(rt, *this);
          break;
        case CellDecision<HV>::Split: {
          Splits splits;
          if (decision.splits.size() > splits.s.size())
            throw InvariantError("dynmesh: more than four box edges to split");
          for (const auto& edge : decision.splits) splits.s[splits.n++] = edge;
          split_next(rt, *this, splits, 0);
          break;
        }
        case CellDecision<HV>::Insert: {
          const CellVertex* off_center = steiner_at(rt, program, decision.at);
          run_step(rt, InsertStep<AfterOffCenter>{{}, off_center, round->size_class->j, AfterOffCenter{*this}});
          break;
        }
      }
      return true;
    }
  };

  struct AfterOffCenter {
    PairTries tries;
    void operator()(sac::Engine& rt, HV v) const { done(rt, birth(rt, tries, v)); }
  };

  /// Splits splits.s[i..] in order, then tries the pair again.
  static void split_next(sac::Engine& rt, const PairTries& tries, const Splits& splits, std::uint32_t i) {
    if (i == splits.n) return run_step(rt, TryStep{tries});
    const Point<2> mid = side_midpoint(splits.s[i][0]->p, splits.s[i][1]->p);
    const CellVertex* m = steiner_at(rt, ctx(rt), mid);
    run_step(rt, InsertStep<AfterSplit>{{}, m, tries.round->size_class->j, AfterSplit{tries, splits, i}});
  }

  struct AfterSplit {
    PairTries tries;
    Splits splits;
    std::uint32_t i;
    void operator()(sac::Engine& rt, HV v) const { split_next(rt, birth(rt, tries, v), splits, i + 1); }
  };

  /// Inserts vertex into the store at this time (the leaf that holds it now gets its next
  /// value, or splits), then then(rt, vertex).
  template <class Then>
  struct InsertStep : StepBase {
    HV vertex;
    int j;
    Then then;
    bool run(sac::Engine& rt, CellView& v) const {
      HpuCellsProgram* const program = ctx(rt);
      if (!v.kept())
        std::tie(program->at_node, program->at_state) = v.locate(program->dir->position(vertex->p), scale_of(j));
      if (!v.done()) return false;
      CellNode* const node = program->at_node;
      const CellState* const s = program->at_state;
      ++program->steps.done[HcStepCounts::Insert];
      std::array<HV, CellState::kCapacity + 1> items;
      std::size_t n = 0;
      for (std::size_t i = 0; i < s->count; ++i) {
        if (s->items[i]->p == vertex->p) throw InvariantError("dynmesh: a Steiner vertex inserted twice");
        items[n++] = s->items[i];
      }
      items[n++] = vertex;
      put(rt, program, node, std::span<HV>(items.data(), n));
      then(rt, vertex);
      return true;
    }
  };

  /// Writes n's value holding `items` (n's cell), splitting while they overflow: the children
  /// first, then n (no read sees a split without its children).
  static void put(sac::Engine& rt, HpuCellsProgram* program, CellNode* n, std::span<HV> items) {
    if (items.size() <= CellState::kCapacity) return rt.write(n->state, CellState::leaf(items.begin(), items.end()));
    if (n->key.level >= BucketTree::kMaxLevel)
      throw InvariantError("dynmesh: the cell store: vertices closer than the finest cell");
    std::array<std::array<HV, CellState::kCapacity + 1>, 4> part;
    std::array<std::size_t, 4> count{};
    for (HV w : items) {
      const CellKey c = CellDirectory::cell_at(program->dir->position(w->p), n->key.level + 1);
      const unsigned k = CellDirectory::child_index(c);
      part[k][count[k]++] = w;
    }
    for (unsigned k = 0; k < 4; ++k)
      put(rt, program, program->dir->node(rt, n->key.child(k)), std::span<HV>(part[k].data(), count[k]));
    rt.write(n->state, CellState::split());
  }

  // ---------------------------------------------------------------- 4. the final mesh

  static void final_start(sac::Engine& rt) {
    HpuCellsProgram* const program = ctx(rt);
    rt.memo(sac::fn<&final_node>(program->dir->node(rt, CellKey{})));
  }

  static void final_node(sac::Engine& rt, CellNode* n) {
    rt.read(n->state, [n](sac::Engine& rt2, const CellState& s) {
      HpuCellsProgram* const program = ctx(rt2);
      if (s.kind == CellState::Split) {
        for (unsigned k = 0; k < 4; ++k)
          rt2.memo(sac::fn<&final_node>(program->dir->node(rt2, n->key.child(k))));
      } else if (s.kind == CellState::Leaf) {
        // One step a vertex, each memoized on the vertex alone: when the leaf gains or loses
        // a vertex, splits or merges, the others' steps are found again with their reads,
        // and a change near one vertex re-runs its star walk only, not the leaf's.
        for (std::size_t i = 0; i < s.count; ++i) rt2.memo(sac::fn<&final_vertex>(s.items[i]));
      }
    });
  }

  static void final_vertex(sac::Engine& rt, HV a) { run_step(rt, FinalStep{{}, a}); }

  /// The triangles whose (x, y)-smallest corner is a, as one block.
  struct FinalStep : StepBase {
    HV a;
    bool run(sac::Engine& rt, CellView& v) const {
      HpuCellsProgram* const program = ctx(rt);
      // The view's nearest search starts at a's leaf and ignores the scale, so the step is a
      // function of a alone, whichever leaf holds it.
      if (!v.kept()) program->questions.triangles_of(a, 0.0, program->tris);
      if (!v.done()) return false;
      ++program->steps.done[HcStepCounts::Final];
      // (a, b, c) counter-clockwise with a the (x, y)-smallest: canonical as it is.
      program->feed->make(rt, a, std::span<const HpuCorners>(program->tris));
      return true;
    }
  };
};

}  // namespace dynmesh::detail
