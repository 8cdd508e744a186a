// sacapps/reduce.hpp — self-adjusting reduction of a list by randomized list contraction.
//
// Purpose: result = combine of all elements of a modifiable list under an associative
// operation with an identity (a Monoid; blocks are combined in list order, so commutativity
// is not needed), kept up to date under insertions, deletions and replacements in O(log n)
// expected trace distance. A left fold would be
// O(n) per update (every partial result after the change differs); contraction instead
// builds a short tower of ever shorter lists.
//
// Round r walks the round-r list (round 0 is the input) and cuts it into blocks: a cell ends
// its block when its coin for round r comes up heads (or when it is the last cell). Each
// block becomes one cell of the round-(r+1) list holding the block's combined value and the
// id of the cell that ended it. Coins are sac::mix64(id ^ salt(r)): a function of the cell's
// stable id and the round only, never of addresses or history, so a from-scratch run and a
// propagated run contract identically. Rounds repeat until one cell is left; its value is
// the result (the identity for an empty input).
//
// The stability argument: a change touches O(1) blocks of its round, hence O(1) cells of the
// next round, and so on through the O(log n) rounds. In the code: output cells are keyed by
// (id, round, value) — their contents are immutable, so the value must be part of the key —
// and each step recurses with memo_read(c->next, fn<contract>(acc, last, dst, round)); after
// the block that a change touched (and the next one, whose destination may have moved) the
// step's arguments are those of the old trace again and the memo match cuts propagation off.
// The whole round is a memo() call so that a re-executed round driver reuses it.
//
// Follows Acar's thesis (CMU 2005), the randomized "reduce"/"combine" of lists, and the
// CEAL benchmarks "minimum" and "sum" of Hammer, Acar and Chen, "CEAL: a C-based language for
// self-adjusting computation", PLDI 2009.
// Invariants: after run() or propagate(), *result == fold of the current input; the round-r
// list is a function of the round-(r-1) list (ids, values) alone.
// Complexity: from scratch O(n) expected (the lists halve in expectation each round);
// per update O(log n) expected trace distance.
#pragma once

#include <concepts>
#include <cstdint>
#include <tuple>
#include <utility>

#include <sac/sac.hpp>

#include "sacapps/list.hpp"

namespace sacapps::reduce {

/// An associative operation with an identity element.
template <class M>
concept Monoid = requires(typename M::value_type a, typename M::value_type b) {
  { M::identity() } -> std::convertible_to<typename M::value_type>;
  { M::combine(a, b) } -> std::convertible_to<typename M::value_type>;
};

/// The coin of the cell with this id in this round: true = the cell ends its block.
inline bool ends_block(std::uint64_t id, std::uint32_t round) {
  const std::uint64_t salt = sac::mix64(0x5ac5eed0ULL + round);
  return (sac::mix64(id ^ salt) & 1) != 0;
}

/// One step of round `round` at cell c. The open block holds the cells from the last block
/// end up to c (exclusive): `last` is its last cell (null when no block is open) and `acc`
/// its combined value (the identity when none is open). *dst receives the next cell of the
/// round-(round+1) list.
template <Monoid M>
void contract(sac::Engine& rt, Cell<typename M::value_type>* c, typename M::value_type acc,
              Cell<typename M::value_type>* last, List<typename M::value_type>* dst,
              std::uint32_t round) {
  using V = typename M::value_type;
  using C = Cell<V>;
  if (!c) {  // end of the list: the open block, if any, is the last cell of the next round
    if (!last) {
      rt.write(*dst, static_cast<C*>(nullptr));
      return;
    }
    C* out = rt.alloc<C>(std::tuple{last->id, round, acc}, acc, last->id);
    rt.write(*dst, out);
    rt.write(out->next, static_cast<C*>(nullptr));
    return;
  }
  const V sum = last ? M::combine(acc, c->value) : c->value;
  if (ends_block(c->id, round)) {
    C* out = rt.alloc<C>(std::tuple{c->id, round, sum}, sum, c->id);
    rt.write(*dst, out);
    rt.memo_read(c->next, sac::fn<&contract<M>>(M::identity(), static_cast<C*>(nullptr),
                                                &out->next, round));
  } else {
    rt.memo_read(c->next, sac::fn<&contract<M>>(sum, c, dst, round));
  }
}

/// Contracts the round-`round` list starting at `first` into *next.
template <Monoid M>
void contract_round(sac::Engine& rt, Cell<typename M::value_type>* first,
                    List<typename M::value_type>* next, std::uint32_t round) {
  contract<M>(rt, first, M::identity(), nullptr, next, round);
}

template <Monoid M>
void reduce_from(sac::Engine& rt, Cell<typename M::value_type>* first,
                 sac::Mod<typename M::value_type>* result, std::uint32_t round);

/// The round-`round` list starts with first, second: done if second is null, else contract
/// this round into the next round's list and reduce that.
template <Monoid M>
void reduce_pair(sac::Engine& rt, Cell<typename M::value_type>* second,
                 Cell<typename M::value_type>* first, sac::Mod<typename M::value_type>* result,
                 std::uint32_t round) {
  using V = typename M::value_type;
  if (!second) {
    rt.write(*result, first->value);
    return;
  }
  List<V>* next = rt.alloc<List<V>>(std::pair{result, round + 1});
  rt.memo(sac::fn<&contract_round<M>>(first, next, round));
  rt.memo_read(*next, sac::fn<&reduce_from<M>>(result, round + 1));
}

/// Reduces the round-`round` list whose first cell is `first` into *result.
template <Monoid M>
void reduce_from(sac::Engine& rt, Cell<typename M::value_type>* first,
                 sac::Mod<typename M::value_type>* result, std::uint32_t round) {
  if (!first) {
    rt.write(*result, M::identity());
    return;
  }
  rt.memo_read(first->next, sac::fn<&reduce_pair<M>>(first, result, round));
}

/// Self-adjusting reduction (call inside the computation): writes the fold of in to *result.
template <Monoid M>
void reduce_list(sac::Engine& rt, const List<typename M::value_type>& in,
                 sac::Mod<typename M::value_type>* result) {
  rt.memo_read(in, sac::fn<&reduce_from<M>>(result, std::uint32_t{0}));
}

}  // namespace sacapps::reduce
