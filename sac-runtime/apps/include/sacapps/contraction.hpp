// sacapps/contraction.hpp — stable reduction of a modifiable list by random list contraction.
//
// Purpose: combine all elements of a list with an associative operation (the extreme points
// and the farthest point of quickhull, the largest distance of diameter) so that one changed
// element costs O(log n), not O(n). A left fold would be a chain of n dependent steps: a
// change near the front re-runs all of it. Instead each round walks the list and cuts it into
// blocks with coin flips (a block ends at a cell whose coin, a hash of its id and the round,
// comes up heads, or at the end); it combines each block into one cell of the next round's
// list. Rounds repeat until one cell is left; its value is the result.
//
//   lists::reduce(rt, src, reducer, &dst)     dst = combine over src, or reducer.identity()
//
// src is a List<T> of Cell<T> (element values come from reducer.leaf(cell)) or an
// RList<V> of RCell<V> (element values are read from each cell's `value` modifiable, so one
// reduction's output can feed another). A reducer is a small value type:
//   using value_type = V;   V identity() const;   V leaf(const Cell<T>&) const;
//   V combine(const V&, const V&) const;   bool operator==;   std::size_t hash() const;
// combine must be associative (blocks are combined in list order) and a pure function of its
// arguments and the reducer's fields, which are part of every memo and allocation key.
//
// Invariants: coins depend only on ids and the round, never on addresses; the next round's
// cell for a block is keyed by (the block's last cell, reducer) and holds the block's value
// in a modifiable, so a changed block value re-runs only the readers of that value and the
// next round's list keeps its shape; each step is a memo_read keyed by (cell, value so far,
// round, reducer, destination), so past the end of the affected block a re-execution finds
// the old trace again.
// Complexity: from scratch O(n) expected events (the list halves each round in expectation,
// O(log n) rounds). One inserted, deleted or changed element changes O(1) expected blocks per
// round: O(log n) expected per update.
//
// Follows the randomized "reduce" of Acar, Blelloch, Blume, Harper, Tangwongsan, "An
// experimental analysis of self-adjusting computation" (TOPLAS 2009), Section 7, as used by
// minimum, sum, quickhull and diameter in CEAL (Hammer, Acar, Chen, PLDI 2009).
#pragma once

#include <cstdint>
#include <tuple>

#include <sac/sac.hpp>

#include "sacapps/list.hpp"

namespace sacapps::lists {

/// A cell of a contracted list: the combined value of one block of the previous round.
template <class V>
struct RCell {
  sac::Mod<V> value;
  sac::Mod<RCell*> next;
  std::uint64_t id;  // the id of the block's last cell: it drives the next round's coins
  explicit RCell(std::uint64_t i) : id(i) {}
};

template <class V>
using RList = sac::Mod<RCell<V>*>;

namespace detail {

/// True when a cell closes its block in this round (probability 1/2, independent per round).
inline bool ends_block(std::uint64_t id, unsigned round) {
  return (sac::mix64(id ^ sac::mix64(0x5bd1e995u + round)) & 1) != 0;
}

/// The head of one round's list; keyed by (previous round's list, reducer).
template <class V>
struct RoundList {
  RList<V> head;
};

/// Passes the value of list element c to k(rt, value): a Cell's through the reducer's leaf,
/// an RCell's by reading its modifiable (a read that re-runs k when the value changes).
template <class R, class T, class K>
void with_value(sac::Engine& rt, Cell<T>* c, const R& r, K k) {
  k(rt, r.leaf(*c));
}
template <class R, class V, class K>
void with_value(sac::Engine& rt, RCell<V>* c, const R&, K k) {
  rt.read(c->value, [k](sac::Engine& rt2, const V& v) { k(rt2, v); });
}

template <class C, class R>
void round_first(sac::Engine& rt, C* first, const sac::Mod<C*>* list, unsigned round, R r,
                 sac::Mod<typename R::value_type>* dst);
template <class C, class R>
void round_second(sac::Engine& rt, C* second, C* first, typename R::value_type x,
                  const sac::Mod<C*>* list, unsigned round, R r,
                  sac::Mod<typename R::value_type>* dst);
template <class C, class R>
void contract_step(sac::Engine& rt, C* next, C* c, typename R::value_type acc, unsigned round,
                   R r, RList<typename R::value_type>* dst);

// One round starts here: an empty list reduces to the identity (only in round 0, contracted
// lists are never empty) ...
template <class C, class R>
void round_first(sac::Engine& rt, C* first, const sac::Mod<C*>* list, unsigned round, R r,
                 sac::Mod<typename R::value_type>* dst) {
  using V = typename R::value_type;
  if (!first) {
    rt.write(*dst, r.identity());
    return;
  }
  with_value(rt, first, r, [=](sac::Engine& rt2, const V& x) {
    rt2.memo_read(first->next, sac::fn<round_second<C, R>>(first, x, list, round, r, dst));
  });
}

// ... a single element is the result; otherwise contract this round into the next one.
template <class C, class R>
void round_second(sac::Engine& rt, C* second, C* first, typename R::value_type x,
                  const sac::Mod<C*>* list, unsigned round, R r,
                  sac::Mod<typename R::value_type>* dst) {
  using V = typename R::value_type;
  if (!second) {
    rt.write(*dst, x);
    return;
  }
  RoundList<V>* next_round = rt.alloc<RoundList<V>>(std::tuple(list, r));
  contract_step<C, R>(rt, second, first, x, round, r, &next_round->head);
  rt.memo_read(next_round->head,
               sac::fn<round_first<RCell<V>, R>>(static_cast<const RList<V>*>(&next_round->head),
                                                 round + 1, r, dst));
}

// c's successor is `next`; acc is the value of c's block up to and including c. If the block
// ends at c, emit its cell into the next round's list; then take in `next`.
template <class C, class R>
void contract_step(sac::Engine& rt, C* next, C* c, typename R::value_type acc, unsigned round,
                   R r, RList<typename R::value_type>* dst) {
  using V = typename R::value_type;
  const bool block_ends = !next || ends_block(c->id, round);
  if (block_ends) {
    RCell<V>* o = rt.alloc<RCell<V>>(std::tuple(c, r), c->id);
    rt.write(o->value, acc);
    rt.write(*dst, o);
    if (!next) {
      rt.write(o->next, static_cast<RCell<V>*>(nullptr));
      return;
    }
    dst = &o->next;
  }
  with_value(rt, next, r, [=](sac::Engine& rt2, const V& y) {
    const V v = block_ends ? y : r.combine(acc, y);
    rt2.memo_read(next->next, sac::fn<contract_step<C, R>>(next, v, round, r, dst));
  });
}

}  // namespace detail

/// Writes to *dst the combination of the values of src's elements (inside the computation).
template <class C, class R>
void reduce(sac::Engine& rt, const sac::Mod<C*>& src, R r, sac::Mod<typename R::value_type>* dst) {
  rt.memo_read(src, sac::fn<detail::round_first<C, R>>(&src, 0u, r, dst));
}

}  // namespace sacapps::lists
