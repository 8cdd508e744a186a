// sacapps/reverse.hpp — self-adjusting list reversal, and its conventional twin.
//
// Purpose: out = in reversed, kept up to date under insertions, deletions and replacements
// of input cells. Accumulator style: walking the input front to back, each input cell c gets
// an output cell (keyed by c) whose tail is the output built so far (the accumulator); at
// the end of the input the accumulator is written to the destination. The recursive call on
// the tail is memoized on (tail modifiable, accumulator, destination): after a deletion the
// step of the deleted cell's successor is redone with its new accumulator and the very next
// call matches the old trace, so propagation stops there.
// Follows Acar's thesis (CMU 2005) and the CEAL benchmark "reverse" of Hammer, Acar and
// Chen, "CEAL: a C-based language for self-adjusting computation", PLDI 2009.
// Invariants: after run() or propagate(), *dst holds the input's elements in reverse order;
// the output cell of input cell c is keyed by c and carries c's id.
// Complexity: from scratch O(n). An insertion, deletion or replacement re-executes one read
// and changes O(1) trace (one step redone, one or two undone).
#pragma once

#include <sac/sac.hpp>

#include "sacapps/list.hpp"
#include "sacapps/heap_list.hpp"

namespace sacapps::reverse {

/// The step for the list whose first cell is c; acc is the reversal of the cells before c.
template <class T>
void step(sac::Engine& rt, Cell<T>* c, Cell<T>* acc, List<T>* dst) {
  if (!c) {
    rt.write(*dst, acc);
    return;
  }
  Cell<T>* out = rt.alloc<Cell<T>>(c, c->value, c->id);  // keyed by the input cell
  rt.write(out->next, acc);
  rt.memo_read(c->next, sac::fn<&step<T>>(out, dst));
}

/// Self-adjusting reversal (call inside the computation): writes reverse(in) into *dst.
template <class T>
void reverse_list(sac::Engine& rt, const List<T>& in, List<T>* dst) {
  rt.memo_read(in, sac::fn<&step<T>>(static_cast<Cell<T>*>(nullptr), dst));
}

/// Conventional twin: one walk, pushing a freshly allocated cell on the front of the output.
template <class T>
heap::List<T> reverse_conventional(const heap::Cell<T>* in) {
  heap::Cell<T>* acc = nullptr;
  for (; in; in = in->next) acc = new heap::Cell<T>{in->value, acc};
  return heap::List<T>::adopt(acc);
}

}  // namespace sacapps::reverse
