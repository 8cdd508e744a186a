// sacapps/mergesort.hpp — self-adjusting mergesort of a modifiable list, and its twin.
//
// Purpose: out = the input list sorted by (value, id) (sorts_before), kept up to date as
// cells are inserted into, deleted from or replaced in the input. The classic functional
// mergesort, in destination-passing style:
//
//   msort(l, d) = l has at most one cell -> l
//                 otherwise              -> let (a, b) = split l by coins of depth d
//                                           in merge(msort(a, d+1), msort(b, d+1))
//
// The split is not "first half / second half" (one insertion would shift every later cell to
// the other half) but a coin flip per element, a hash of its id and the depth: an element
// goes to the same side whatever else is in the list, so an insertion changes one path of
// the recursion.
//
// Invariants: the node of a call (its halves and their sorted versions) is keyed by the
// list it sorts; split cells are keyed by (element id, depth), merge output cells by
// (element id, depth); every recursive call and every merge step is a memo_read keyed by
// its lists and destination, so a re-execution finds the old trace again right after the
// change. A one-element list is its own sorted version (no copy), as in the classic code.
// Complexity: from scratch O(n log n) expected. An insertion or deletion changes O(1)
// expected split steps and O(1) expected merge steps per level (the merge re-runs until
// the next element from the changed side, a geometric run): O(log n) expected trace
// distance.
//
// Follows Acar's thesis (CMU 2005), "mergesort"; Acar, Blelloch, Blume, Harper,
// Tangwongsan, "An experimental analysis of self-adjusting computation" (TOPLAS 2009); and
// the CEAL benchmark of Hammer, Acar, Chen (PLDI 2009).
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>
#include <tuple>

#include <sac/sac.hpp>

#include "sacapps/list.hpp"
#include "sacapps/partition.hpp"
#include "sacapps/sort_app.hpp"

namespace sacapps::mergesort {

/// Split predicate of depth d: a fair coin per element, independent between depths.
template <class T>
struct CoinAtDepth {
  unsigned depth;
  bool operator()(const Cell<T>& c) const {
    return (sac::mix64(c.id ^ sac::mix64(0x6a09e667u + depth)) & 1) != 0;
  }
  bool operator==(const CoinAtDepth&) const = default;
  std::size_t hash() const { return sac::Hash<unsigned>{}(depth); }
};

/// What one call owns: the two halves of its list and their sorted versions.
template <class T>
struct SortNode {
  List<T> half_a, half_b, sorted_a, sorted_b;
};

// ---- merge, one read per output cell: x and y are the first cells of the two sorted lists.
template <class T>
void merge_heads(sac::Engine& rt, Cell<T>* x, Cell<T>* y, unsigned depth, List<T>* dst);

template <class T>
void merge_next_x(sac::Engine& rt, Cell<T>* x, Cell<T>* y, unsigned depth, List<T>* dst) {
  merge_heads(rt, x, y, depth, dst);
}
template <class T>
void merge_next_y(sac::Engine& rt, Cell<T>* y, Cell<T>* x, unsigned depth, List<T>* dst) {
  merge_heads(rt, x, y, depth, dst);
}

template <class T>
void merge_heads(sac::Engine& rt, Cell<T>* x, Cell<T>* y, unsigned depth, List<T>* dst) {
  if (!x || !y) {  // one list is exhausted: the rest of the other follows as it is
    rt.write(*dst, x ? x : y);
    return;
  }
  Cell<T>* first = sorts_before(*x, *y) ? x : y;
  Cell<T>* o = rt.alloc<Cell<T>>(std::tuple(first->id, depth), first->value, first->id);
  rt.write(*dst, o);
  if (first == x)
    rt.memo_read(x->next, sac::fn<merge_next_x<T>>(y, depth, &o->next));
  else
    rt.memo_read(y->next, sac::fn<merge_next_y<T>>(x, depth, &o->next));
}

template <class T>
void merge_with_b(sac::Engine& rt, Cell<T>* x, const List<T>* b, unsigned depth, List<T>* dst) {
  rt.read(*b, sac::fn<merge_next_y<T>>(x, depth, dst));
}

/// Writes into *dst the merge of the sorted lists *a and *b (the merge of depth `depth`).
template <class T>
void merge(sac::Engine& rt, const List<T>* a, const List<T>* b, unsigned depth, List<T>* dst) {
  rt.memo_read(*a, sac::fn<merge_with_b<T>>(b, depth, dst));
}

// ---- msort(l, depth): reads the first two cells to tell the base cases apart.
template <class T>
void msort(sac::Engine& rt, const List<T>* l, unsigned depth, List<T>* dst);

template <class T>
void msort_second(sac::Engine& rt, Cell<T>* second, Cell<T>* first, const List<T>* l,
                  unsigned depth, List<T>* dst) {
  if (!second) {  // one cell: sorted already
    rt.write(*dst, first);
    return;
  }
  SortNode<T>* node = rt.alloc<SortNode<T>>(l);
  lists::partition(rt, *l, CoinAtDepth<T>{depth}, &node->half_a, &node->half_b);
  msort(rt, &node->half_a, depth + 1, &node->sorted_a);
  msort(rt, &node->half_b, depth + 1, &node->sorted_b);
  merge(rt, &node->sorted_a, &node->sorted_b, depth, dst);
}

template <class T>
void msort_first(sac::Engine& rt, Cell<T>* first, const List<T>* l, unsigned depth, List<T>* dst) {
  if (!first) {
    rt.write(*dst, static_cast<Cell<T>*>(nullptr));
    return;
  }
  rt.memo_read(first->next, sac::fn<msort_second<T>>(first, l, depth, dst));
}

template <class T>
void msort(sac::Engine& rt, const List<T>* l, unsigned depth, List<T>* dst) {
  rt.memo_read(*l, sac::fn<msort_first<T>>(l, depth, dst));
}

/// Self-adjusting mergesort (call inside the computation): writes `in` sorted into *dst.
template <class T>
void mergesort(sac::Engine& rt, const List<T>& in, List<T>* dst) {
  msort(rt, &in, 0u, dst);
}

/// Conventional twin: the textbook list mergesort (split alternately, recurse, merge); the
/// split and the merge build new cells, as the self-adjusting version does.
template <class T>
const SortCell<T>* mergesort_conventional(const SortCell<T>* l, SortArena<T>& arena) {
  if (!l || !l->next) return l;
  const SortCell<T>* halves[2] = {nullptr, nullptr};
  const SortCell<T>** ends[2] = {&halves[0], &halves[1]};
  int side = 0;
  for (const SortCell<T>* c = l; c; c = c->next, side ^= 1) {
    SortCell<T>* o = arena.make(c->value, c->id);
    *ends[side] = o;
    ends[side] = &o->next;
  }
  const SortCell<T>* x = mergesort_conventional(halves[0], arena);
  const SortCell<T>* y = mergesort_conventional(halves[1], arena);
  const SortCell<T>* out = nullptr;
  const SortCell<T>** end = &out;
  while (x && y) {
    const SortCell<T>*& first = sorts_before(*x, *y) ? x : y;
    SortCell<T>* o = arena.make(first->value, first->id);
    *end = o;
    end = &o->next;
    first = first->next;
  }
  *end = x ? x : y;
  return out;
}

/// The App adapter: int64 values uniform in [0, range).
class MergesortApp final : public SortApp {
 public:
  explicit MergesortApp(Value range = kFullRange) : SortApp(range) {}
  std::string_view name() const override { return "mergesort"; }
  std::unique_ptr<App> clone_current() const override;

 protected:
  void sort_self_adjusting(sac::Engine& rt, const List<Value>& in, List<Value>* dst) override;
  const SortCell<Value>* sort_conventional(const SortCell<Value>* in,
                                           SortArena<Value>& arena) override;
};

}  // namespace sacapps::mergesort
