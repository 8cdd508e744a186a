// sacapps/quicksort.hpp — self-adjusting quicksort of a modifiable list, and its twin.
//
// Purpose: out = the input list sorted by (value, id) (sorts_before), kept up to date as
// cells are inserted into, deleted from or replaced in the input. The classic functional
// quicksort with an accumulator, in destination-passing style:
//
//   qsort(l, rest) = l empty     -> rest
//                    l = p :: t  -> let (less, greater) = partition t around p
//                                   in qsort(less, p' :: qsort(greater, rest))
//
// where p' is p's output cell. `rest` is a cell (the already sorted part that follows), and
// the result goes into a modifiable: the head of the output for the top call, the `next` of
// the pivot's output cell for the greater half.
//
// Invariants: every element is the pivot of exactly one call; its node (partition outputs
// and output cell) is keyed by the pivot's id, the partition cells by (element id, pivot),
// and each recursive call is a memo_read keyed by (list, rest, destination). So after a
// change the re-execution finds the old subtrees of the recursion whose pivot, list and
// successor did not change; and when a deleted pivot's subtree is rebuilt, its elements'
// cells below the new pivot are found again (the treap-like recursion changes along two
// spines only).
// Complexity: from scratch O(n log n) expected (O(n^2) on sorted input: the pivot is the
// first cell, as in the classic benchmark). An insertion or deletion at a random position
// changes O(1) expected partition steps per level of the recursion it passes and its own
// subtree's partitions: O(log n) expected trace distance (Acar's thesis; the figures are in
// bench/RESULTS.md, "The classic suite (`sac_suite`)").
//
// Follows Acar's thesis (CMU 2005), "quicksort"; Acar, Blelloch, Blume, Harper,
// Tangwongsan, "An experimental analysis of self-adjusting computation" (TOPLAS 2009); and
// the CEAL benchmark of Hammer, Acar, Chen (PLDI 2009).
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>

#include <sac/sac.hpp>

#include "sacapps/list.hpp"
#include "sacapps/partition.hpp"
#include "sacapps/sort_app.hpp"

namespace sacapps::quicksort {

/// Partition predicate: does a cell sort before the pivot? It names the pivot by value and
/// id, so it is the same predicate whichever copy of the pivot a call sees.
template <class T>
struct SortsBefore {
  T value;
  std::uint64_t id;
  bool operator()(const Cell<T>& c) const { return sorts_before(c, *this); }
  bool operator==(const SortsBefore&) const = default;
  std::size_t hash() const {
    return sac::hash_combine(sac::Hash<T>{}(value), sac::Hash<std::uint64_t>{}(id));
  }
};

/// What one pivot owns: its output cell (whose `next` receives the sorted greater half) and
/// the two halves of the rest of its list.
template <class T>
struct PivotNode {
  Cell<T> out;
  List<T> less, greater;
  explicit PivotNode(const Cell<T>* pivot) : out(pivot->value, pivot->id) {}
};

/// The call qsort(l, rest) for l's first cell c, writing the sorted list into *dst.
template <class T>
void step(sac::Engine& rt, Cell<T>* c, Cell<T>* rest, List<T>* dst) {
  if (!c) {
    rt.write(*dst, rest);
    return;
  }
  PivotNode<T>* node = rt.alloc<PivotNode<T>>(c->id, c);
  lists::partition(rt, c->next, SortsBefore<T>{c->value, c->id}, &node->less, &node->greater);
  rt.memo_read(node->greater, sac::fn<step<T>>(rest, &node->out.next));
  rt.memo_read(node->less, sac::fn<step<T>>(&node->out, dst));
}

/// Self-adjusting quicksort (call inside the computation): writes `in` sorted into *dst.
template <class T>
void quicksort(sac::Engine& rt, const List<T>& in, List<T>* dst) {
  rt.memo_read(in, sac::fn<step<T>>(static_cast<Cell<T>*>(nullptr), dst));
}

/// Conventional twin: the same algorithm on plain lists; the partitions build new cells.
template <class T>
const SortCell<T>* quicksort_conventional(const SortCell<T>* l, const SortCell<T>* rest,
                                          SortArena<T>& arena) {
  while (l) {  // the call on the less half is a tail call
    const SortCell<T>* pivot = l;
    const SortCell<T>* less = nullptr;
    const SortCell<T>* greater = nullptr;
    const SortCell<T>** less_end = &less;
    const SortCell<T>** greater_end = &greater;
    for (const SortCell<T>* c = pivot->next; c; c = c->next) {
      SortCell<T>* o = arena.make(c->value, c->id);
      const SortCell<T>**& end = sorts_before(*c, *pivot) ? less_end : greater_end;
      *end = o;
      end = &o->next;
    }
    const SortCell<T>* mid = quicksort_conventional<T>(greater, rest, arena);
    rest = arena.make(pivot->value, pivot->id, mid);
    l = less;
  }
  return rest;
}

/// The App adapter: int64 values uniform in [0, range).
class QuicksortApp final : public SortApp {
 public:
  explicit QuicksortApp(Value range = kFullRange) : SortApp(range) {}
  std::string_view name() const override { return "quicksort"; }
  std::unique_ptr<App> clone_current() const override;

 protected:
  void sort_self_adjusting(sac::Engine& rt, const List<Value>& in, List<Value>* dst) override;
  const SortCell<Value>* sort_conventional(const SortCell<Value>* in,
                                           SortArena<Value>& arena) override;
};

}  // namespace sacapps::quicksort
