// sacapps/filter.hpp — self-adjusting filter over a modifiable list, and its conventional twin.
//
// Purpose: out = [x for x in in if P(x)], kept up to date under insertions, deletions and
// replacements of input cells. Like map (sacapps/map.hpp) it is written in
// destination-passing style: a kept cell allocates its output cell (keyed by the input
// cell), writes it into the destination and hands its own tail on as the next destination;
// a dropped cell hands the destination it was given on to the tail.
// Follows Acar's thesis (CMU 2005), "filter", and the CEAL benchmark of Hammer, Acar and
// Chen, "CEAL: a C-based language for self-adjusting computation", PLDI 2009.
// Invariants: after run() or propagate(), *dst holds the kept elements in input order;
// output cell i is keyed by input cell i and carries its id.
// Complexity: from scratch O(n). A change at one input cell re-executes one read; the steps
// of the dropped cells that follow the change until the next kept cell are redone too (their
// destination changed), so the trace distance is O(1 + that run), O(1) expected for a
// predicate that keeps each element independently with constant probability (the
// benchmark's keeps about half).
#pragma once

#include <cstdint>

#include <sac/sac.hpp>

#include "sacapps/list.hpp"
#include "sacapps/heap_list.hpp"

namespace sacapps::filter {

using Value = std::int64_t;

/// The predicate of the benchmark: keeps the even values (about half of random inputs).
constexpr bool keep(Value x) { return x % 2 == 0; }

/// The step for the list whose first cell is c; *dst receives the next kept cell.
template <auto P, class T>
void step(sac::Engine& rt, Cell<T>* c, List<T>* dst) {
  if (!c) {
    rt.write(*dst, static_cast<Cell<T>*>(nullptr));
    return;
  }
  if (P(c->value)) {
    Cell<T>* out = rt.alloc<Cell<T>>(c, c->value, c->id);  // keyed by the input cell
    rt.write(*dst, out);
    rt.memo_read(c->next, sac::fn<&step<P, T>>(&out->next));
  } else {
    rt.memo_read(c->next, sac::fn<&step<P, T>>(dst));
  }
}

/// Self-adjusting filter (call inside the computation): writes the kept list into *dst.
template <auto P, class T>
void filter_list(sac::Engine& rt, const List<T>& in, List<T>* dst) {
  rt.memo_read(in, sac::fn<&step<P, T>>(dst));
}

/// Conventional twin: one walk, one freshly allocated cell per kept element.
template <auto P, class T>
heap::List<T> filter_conventional(const heap::Cell<T>* in) {
  heap::Cell<T>* head = nullptr;
  heap::Cell<T>** tail = &head;
  for (; in; in = in->next) {
    if (!P(in->value)) continue;
    *tail = new heap::Cell<T>{in->value, nullptr};
    tail = &(*tail)->next;
  }
  return heap::List<T>::adopt(head);
}

}  // namespace sacapps::filter
