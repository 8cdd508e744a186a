// sacapps/partition.hpp — memoized, keyed filter and partition of modifiable lists.
//
// Purpose: the list-splitting steps of the classic apps: quicksort splits a list around a
// pivot, mergesort by coin flips, quickhull keeps the points beyond an edge. Both functions
// run inside the computation in destination-passing style: they write the head of each
// output list into a modifiable the caller provides, and every output cell's tail into that
// cell's own `next`.
//
//   lists::filter(rt, src, keep, &dst)             dst   = [c in src | keep(c)]
//   lists::partition(rt, src, pred, &yes, &no)     yes/no = [c in src | pred(c)] / [... | !pred(c)]
//
// A predicate is a small value type: `bool operator()(const Cell<T>&) const`, `==` and
// `std::size_t hash() const`. It is part of every memo key and allocation key, so it must be
// a pure function of the cell's value and id and of its own fields (a pivot, an edge), which
// should themselves be values and ids, not cell addresses; two predicates that are == must
// decide alike.
//
// Invariants: ids are unique within a list and a cell's value is a function of its id (as
// in InputList). Outputs keep input order. An output cell is keyed by (element id,
// predicate) and carries the element's value and id: the key names the element, not the
// copy of it that happens to be in this list, so when a change moves an element to another
// list of the same recursion (a quicksort pivot deleted, a hull edge replaced), a
// re-execution still finds that element's old cells, and the memo keys (predicate,
// destination) downstream of a change line up again. Every step is a memo_read of one input
// `next`, so an unchanged stretch of input is reused whole.
// Complexity: from scratch O(n) events. Inserting or deleting one input cell re-executes
// O(1 + r) steps, where r is the number of following cells that go to the other output (their
// memo keys mention the destination the changed cell moved): O(1) expected when the
// predicate splits at random, as it does in all three apps.
//
// Follows the filter of Acar, Blelloch, Blume, Harper, Tangwongsan, "An experimental analysis
// of self-adjusting computation" (TOPLAS 2009) and the list splitting of the quicksort and
// mergesort benchmarks there, in Acar's thesis (CMU 2005) and in CEAL (Hammer, Acar, Chen,
// PLDI 2009).
#pragma once

#include <tuple>

#include <sac/sac.hpp>

#include "sacapps/list.hpp"

namespace sacapps::lists {

namespace detail {

template <class T, class Keep>
void filter_step(sac::Engine& rt, Cell<T>* c, Keep keep, List<T>* dst) {
  if (!c) {
    rt.write(*dst, static_cast<Cell<T>*>(nullptr));
    return;
  }
  if (keep(*c)) {
    Cell<T>* o = rt.alloc<Cell<T>>(std::tuple(c->id, keep), c->value, c->id);
    rt.write(*dst, o);
    dst = &o->next;
  }
  rt.memo_read(c->next, sac::fn<filter_step<T, Keep>>(keep, dst));
}

template <class T, class Pred>
void partition_step(sac::Engine& rt, Cell<T>* c, Pred pred, List<T>* yes, List<T>* no) {
  if (!c) {
    rt.write(*yes, static_cast<Cell<T>*>(nullptr));
    rt.write(*no, static_cast<Cell<T>*>(nullptr));
    return;
  }
  Cell<T>* o = rt.alloc<Cell<T>>(std::tuple(c->id, pred), c->value, c->id);
  if (pred(*c)) {
    rt.write(*yes, o);
    yes = &o->next;
  } else {
    rt.write(*no, o);
    no = &o->next;
  }
  rt.memo_read(c->next, sac::fn<partition_step<T, Pred>>(pred, yes, no));
}

}  // namespace detail

/// Writes to *dst the cells of src that keep() accepts, in order (inside the computation).
template <class T, class Keep>
void filter(sac::Engine& rt, const List<T>& src, Keep keep, List<T>* dst) {
  rt.memo_read(src, sac::fn<detail::filter_step<T, Keep>>(keep, dst));
}

/// Writes to *yes the cells of src that pred() accepts and to *no the others, both in order.
template <class T, class Pred>
void partition(sac::Engine& rt, const List<T>& src, Pred pred, List<T>* yes, List<T>* no) {
  rt.memo_read(src, sac::fn<detail::partition_step<T, Pred>>(pred, yes, no));
}

}  // namespace sacapps::lists
