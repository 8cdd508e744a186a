// sacapps/sum.hpp — self-adjusting sum of a list, and its conventional twin.
//
// Purpose: result = the sum of a modifiable list of integers (0 for the empty list), kept up
// to date under insertions, deletions and replacements. It is the randomized list
// contraction of sacapps/contraction.hpp instantiated with (+, 0); see there for how the rounds
// are built and why an update touches O(1) cells per round. Integer addition is exact and
// associative, so the contraction's result equals the conventional left fold bit for bit
// (the benchmark's values are below 2^31, far from overflow).
// Follows Acar's thesis (CMU 2005) and the CEAL benchmark "sum" of Hammer, Acar and Chen,
// "CEAL: a C-based language for self-adjusting computation", PLDI 2009.
// Invariants: after run() or propagate(), *result == sum of the current input.
// Complexity: from scratch O(n) expected; per update O(log n) expected trace distance.
#pragma once

#include <cstdint>

#include <sac/sac.hpp>

#include "sacapps/list.hpp"
#include "sacapps/heap_list.hpp"
#include "sacapps/contraction.hpp"

namespace sacapps::sum {

using Value = std::int64_t;

struct Plus {
  using value_type = Value;
  Value identity() const { return 0; }
  Value leaf(const Cell<Value>& c) const { return c.value; }
  Value combine(Value a, Value b) const { return a + b; }
  bool operator==(const Plus&) const = default;
  std::size_t hash() const { return 0x73756du; }
};

/// Self-adjusting sum (call inside the computation): writes sum(in) into *result.
inline void sum_list(sac::Engine& rt, const List<Value>& in, sac::Mod<Value>* result) {
  lists::reduce(rt, in, Plus{}, result);
}

/// Conventional twin: one walk over a plain linked list.
inline Value sum_conventional(const heap::Cell<Value>* in) {
  Value s = 0;
  for (; in; in = in->next) s += in->value;
  return s;
}

}  // namespace sacapps::sum
