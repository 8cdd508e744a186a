// step_rounds.hpp (private) — the step protocol of the hpu program: how a step runs, fails,
// reads the cells it used in rounds, runs again and acts.
//
// Purpose: a step asks its questions on a CellView (cell_view.hpp) and must depend, in the
// trace, on exactly the cells its answers used. It cannot know them before it asks, so it
// runs more than once. Its states, in the names the code uses:
//   S1 First run. run_step(): view.begin_run() empties the view; step.run() asks the
//      questions, which peek at the cells they need (exact answers, nothing recorded); a
//      cell they use that no round has read becomes pending. → S2.
//   S2 Verdict. step.run() calls view.done() before it acts. While a cell is pending
//      (failed()), done() is false and run() returns false at once: the run has written,
//      allocated and issued nothing, since its answers rest on cells the trace does not yet
//      record. → S3. Otherwise done() gives each read cell what the answers used of it (its
//      CellInterest, kept in the round that read it) and is true. → S5.
//   S3 Hand over. The failed run gives the view to the round it is about to issue
//      (hand_over_first_run() after S1, hand_over(round) after a round's run), then issues it:
//      issue_round(), one Engine::read_many of at most kCellsPerRead pending cells, nested in
//      the step's reads so far. In a first run or a re-run the read runs at once. → S4.
//   S4 Round run. CellRound::operator(): view.begin_run(parent, serial).
//      S4a Kept: the view was handed over to this round, so nothing ran since the run that
//          issued it. The view keeps its cells (peeked ones included) and adds this round's;
//          kept() is true, and the step takes its last run's answers from its scratch instead
//          of asking again (the same values at the same time).
//      S4b Rebuilt: change propagation re-runs the round (S6). The view starts from this
//          round's values and the outer rounds' (Engine::current), kept() is false, and the
//          step asks again, peeking beyond those cells.
//      Then view.settle() and step.run(). → S2.
//   S5 Act. The run whose answers stand does the step's effects in this order: writes and
//      allocations first (they use the view and the program's scratch), then the reads,
//      memo calls and run_step calls that continue the program (a write after an issued call
//      would run that call on the spot, and that call would reuse the view).
//   S6 Propagation. Later, a change of a cell a round read re-runs the round (S4b) only when
//      affected() says it changes what the step used of the cell (interest_changed); a leaf
//      that split or merged away is first followed (follow(), follow_cell), which moves the
//      read to the cell now holding the used vertices and re-runs nothing when they are the
//      same. The runtime asks when propagation reaches the read, so a change undone by then
//      costs nothing.
// The common path is S1 → S2 → S3 → S4a → S2 → S5: one read event per step, holding exactly
// the cells its answers used.
// Invariants: a step writes, allocates and issues only in S5; a round's closure holds, per
// cell, the interest of the step's last run that stood; kept() is true only in a run that
// directly follows the run that issued its round.
// Complexity: a round is one trace event for up to kCellsPerRead cells; a step needs more than
// one round only when it uses more cells than that, or when S4b's answers need new cells.
// Paper: Acar & Hudson, Section 4; Hammer, Acar & Chen (CEAL, 2009) for reads as the unit of
// re-execution; docs/HPU_ON_CELLS.md, "A step peeks, then reads exactly the cells it used".
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>

#include <sac/engine.hpp>
#include <sac/mod.hpp>
#include <sac/read_slots.hpp>

#include "dynmesh/errors.hpp"
#include "hpu/cell_interest.hpp"
#include "hpu/cell_store.hpp"
#include "hpu/cell_view.hpp"

namespace dynmesh::detail {

inline constexpr std::size_t kCellsPerRead = 16;  // Engine::read_many's most

/// The part of a round's closure that later rounds look through: the round before, how many
/// cells this one read, and its read's modifiables (the cells' states), which the round
/// learns when it first runs: the cells are not copied into the closure.
struct CellRoundHead {
  const CellRoundHead* parent;
  std::uint32_t n;       // cells read
  std::uint32_t serial;  // a first round: its step's first run, which issued it (S3)
  mutable sac::ReadSlots<CellState> slots;  // the read's own record; follow() moves a slot
  CellNode* cell(std::size_t i) const { return CellDirectory::node_of(slots[i]); }
};

/// A round's head, and what the step used of each cell (the read's own state: the step's
/// last run that did not fail wrote it, CellView::done(); the read asks it on every change).
template <std::size_t N>
struct CellRoundCells {
  CellRoundHead head;
  mutable std::array<CellInterest, N> used;
};

// Every CellRound<Step, N> starts with a CellRoundCells<N> (standard layout), whose `used`
// follows the head at the same offset for every N. It is a mutable member, so a const round
// hands out writable interests.
inline CellInterest* used_of(const CellRoundHead* h) {
  return reinterpret_cast<const CellRoundCells<1>*>(h)->used.data();
}

template <class Step>
void issue_round(sac::Engine& rt, const Step& step, const CellRoundHead* parent, std::uint32_t serial,
                 std::span<CellNode* const> misses);

/// One round of a step (S4): reads its cells, then runs the step on the view of all its
/// rounds. A read of a projection (sac::Engine::read_many): a change of a cell re-runs it
/// only when it changes what the step used of that cell (S6).
template <class Step, std::size_t N>
struct CellRound {
  CellRoundCells<N> c;
  Step step;

  void operator()(sac::Engine& rt, std::span<const CellState* const> vals, sac::ReadSlots<CellState> slots) const {
    c.head.slots = slots;
    CellView& v = *step.view(rt);
    const bool kept = v.begin_run(c.head.parent, c.head.serial);  // S4a kept, or S4b rebuilt
    for (std::uint32_t i = 0; i < c.head.n; ++i) v.add(c.head.cell(i), vals[i], &c.used[i]);
    if (!kept)
      for (const CellRoundHead* outer = c.head.parent; outer; outer = outer->parent) {
        CellInterest* used = used_of(outer);
        for (std::uint32_t i = 0; i < outer->n; ++i) {
          CellNode* cell = outer->cell(i);
          v.add(cell, &rt.current(cell->state), &used[i]);
        }
      }
    v.settle();
    if (!step.run(rt, v)) {  // S2 failed: S3
      v.hand_over(&c.head);
      issue_round(rt, step, &c.head, 0, v.pending());
    }
  }

  bool affected(const sac::Engine& rt, std::size_t i, const CellState& before, const CellState& after) const {
    return interest_changed(step.box(rt), c.head.cell(i)->key, c.used[i], before, after);
  }

  /// S6: a leaf that split or merged away: its read moves to the cell that holds what the
  /// step used of it, when that is unchanged (follow_cell).
  const sac::Mod<CellState>* follow(std::size_t i, const CellState& seen, const CellState& now,
                                    const sac::Engine::At& at) const {
    CellInterest in = c.used[i];
    CellNode* d = follow_cell(step.box(at.engine()), step.dir(at.engine()), c.head.cell(i), &in, seen, now,
                              [&](const CellNode* node) { return at.value(node->state); });
    if (!d) return nullptr;
    c.used[i] = in;  // the runtime moves slot i to d's state
    return &d->state;
  }
};

template <class Step, std::size_t N>
void issue_round_n(sac::Engine& rt, const Step& step, const CellRoundHead* parent, std::uint32_t serial,
                   std::span<CellNode* const> misses) {
  static_assert(std::is_standard_layout_v<CellRoundCells<N>>);
  static_assert(offsetof(CellRoundCells<N>, used) == offsetof(CellRoundCells<1>, used));
  CellRound<Step, N> round{
      {{parent, static_cast<std::uint32_t>(misses.size()), serial, {}}, {}}, step};
  std::array<const sac::Mod<CellState>*, N> mods;
  for (std::size_t i = 0; i < misses.size(); ++i) mods[i] = &misses[i]->state;
  rt.read_many(std::span<const sac::Mod<CellState>* const>(mods.data(), misses.size()), std::move(round));
}

/// S3's issue: the next round, on the first kCellsPerRead pending cells (the rest, if any,
/// stay pending and the round's run fails again).
template <class Step>
void issue_round(sac::Engine& rt, const Step& step, const CellRoundHead* parent, std::uint32_t serial,
                 std::span<CellNode* const> misses) {
  if (misses.empty()) throw InvariantError("dynmesh: a step failed without a pending cell");
  if (misses.size() > kCellsPerRead) misses = misses.first(kCellsPerRead);  // the rest next round
  step.view(rt)->count_round(misses.size());
  // Closures of 1, 2, 3, 4, 6, 8, 12 or 16 cells: a round holds at most a third more room than
  // it reads (a cell's interest, 4 bytes), against twice as much with powers of two.
  switch (misses.size()) {
    case 1: return issue_round_n<Step, 1>(rt, step, parent, serial, misses);
    case 2: return issue_round_n<Step, 2>(rt, step, parent, serial, misses);
    case 3: return issue_round_n<Step, 3>(rt, step, parent, serial, misses);
    case 4: return issue_round_n<Step, 4>(rt, step, parent, serial, misses);
    case 5:
    case 6: return issue_round_n<Step, 6>(rt, step, parent, serial, misses);
    case 7:
    case 8: return issue_round_n<Step, 8>(rt, step, parent, serial, misses);
    case 9:
    case 10:
    case 11:
    case 12: return issue_round_n<Step, 12>(rt, step, parent, serial, misses);
    default: return issue_round_n<Step, kCellsPerRead>(rt, step, parent, serial, misses);
  }
}

/// Runs a step: S1, then S2 to S5 as the header states. Step: copyable (it is each round's
/// closure), with CellView* view(const Engine&), const Box<2>& box(const Engine&) and const
/// CellDirectory& dir(const Engine&) (the store's, from the engine's context), and bool
/// run(Engine&, CellView&), which returns false when CellView::done()
/// does (S2 failed: it has written, allocated and issued nothing) and otherwise acts (S5).
template <class Step>
void run_step(sac::Engine& rt, const Step& step) {
  CellView& v = *step.view(rt);
  v.begin_run();  // S1
  if (!step.run(rt, v)) issue_round(rt, step, nullptr, v.hand_over_first_run(), v.pending());  // S2 failed: S3
}

}  // namespace dynmesh::detail
