// sacapps/minimum.hpp — self-adjusting minimum of a list, and its conventional twin.
//
// Purpose: result = the minimum of a modifiable list of integers (INT64_MAX for the empty
// list), kept up to date under insertions, deletions and replacements. It is the randomized
// list contraction of sacapps/contraction.hpp instantiated with (min, INT64_MAX); see there for
// how the rounds are built and why an update touches O(1) cells per round.
// Follows Acar's thesis (CMU 2005) and the CEAL benchmark "minimum" of Hammer, Acar and
// Chen, "CEAL: a C-based language for self-adjusting computation", PLDI 2009.
// Invariants: after run() or propagate(), *result == min of the current input.
// Complexity: from scratch O(n) expected; per update O(log n) expected trace distance.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>

#include <sac/sac.hpp>

#include "sacapps/list.hpp"
#include "sacapps/heap_list.hpp"
#include "sacapps/contraction.hpp"

namespace sacapps::minimum {

using Value = std::int64_t;

struct Min {
  using value_type = Value;
  Value identity() const { return std::numeric_limits<Value>::max(); }
  Value leaf(const Cell<Value>& c) const { return c.value; }
  Value combine(Value a, Value b) const { return std::min(a, b); }
  bool operator==(const Min&) const = default;
  std::size_t hash() const { return 0x6d696eu; }
};

/// Self-adjusting minimum (call inside the computation): writes min(in) into *result.
inline void minimum_list(sac::Engine& rt, const List<Value>& in, sac::Mod<Value>* result) {
  lists::reduce(rt, in, Min{}, result);
}

/// Conventional twin: one walk over a plain linked list.
inline Value minimum_conventional(const heap::Cell<Value>* in) {
  Value m = Min{}.identity();
  for (; in; in = in->next) m = std::min(m, in->value);
  return m;
}

}  // namespace sacapps::minimum
