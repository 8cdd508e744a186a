// sacapps/map.hpp — self-adjusting map over a modifiable list, and its conventional twin.
//
// Purpose: out = [f(x) for x in in], kept up to date as cells are inserted into, deleted from
// or replaced in the input list. The simplest self-adjusting list program and the template
// for the others: destination-passing style (each step writes the output cell it builds into
// the modifiable it was handed), keyed allocation (the output cell of input cell c is keyed
// by c, so a re-execution gets the same cell back) and memoized reads (the recursive call on
// the tail is memo_read(c->next, fn<step>(dst)), so change propagation stops at the first
// step that the change did not reach).
// Follows Acar's thesis (CMU 2005), "map", and the CEAL benchmark of Hammer, Acar and Chen,
// "CEAL: a C-based language for self-adjusting computation", PLDI 2009.
// Invariants: after run() or propagate(), *dst holds the list f(in) in input order; output
// cell i is keyed by input cell i and carries its id.
// Complexity: from scratch O(n) time and trace; an insertion, deletion or replacement of one
// input cell re-executes one read and changes O(1) trace (trace distance O(1)).
#pragma once

#include <cstdint>

#include <sac/sac.hpp>

#include "sacapps/list.hpp"
#include "sacapps/heap_list.hpp"

namespace sacapps::map {

using Value = std::int64_t;

/// The mapped function of the benchmark: cheap exact arithmetic (inputs are below 2^31).
constexpr Value f(Value x) { return 3 * x + 1; }

/// The step for the list whose first cell is c: builds f(c) and recurses on the tail.
template <auto F, class T>
void step(sac::Engine& rt, Cell<T>* c, List<T>* dst) {
  if (!c) {
    rt.write(*dst, static_cast<Cell<T>*>(nullptr));
    return;
  }
  Cell<T>* out = rt.alloc<Cell<T>>(c, F(c->value), c->id);  // keyed by the input cell
  rt.write(*dst, out);
  rt.memo_read(c->next, sac::fn<&step<F, T>>(&out->next));
}

/// Self-adjusting map (call inside the computation): writes the list F(in) into *dst.
template <auto F, class T>
void map_list(sac::Engine& rt, const List<T>& in, List<T>* dst) {
  rt.memo_read(in, sac::fn<&step<F, T>>(dst));
}

/// Conventional twin: one walk, one freshly allocated cell per element.
template <auto F, class T>
heap::List<T> map_conventional(const heap::Cell<T>* in) {
  heap::Cell<T>* head = nullptr;
  heap::Cell<T>** tail = &head;
  for (; in; in = in->next) {
    *tail = new heap::Cell<T>{F(in->value), nullptr};
    tail = &(*tail)->next;
  }
  return heap::List<T>::adopt(head);
}

}  // namespace sacapps::map
