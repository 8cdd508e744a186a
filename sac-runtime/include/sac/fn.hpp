// sac/fn.hpp — sac::fn<f>(args...): a comparable, hashable closure for memoized calls.
//
// Purpose: memo() and memo_read() match a call against the old trace by comparing closures,
// and C++ lambdas cannot be compared. fn<f>(a, b) stores f (a function known at compile time)
// and the argument values; calling it with leading arguments x... calls f(x..., a, b).
// Two Fn values are equal when their argument tuples are equal.
//   rt.memo_read(list, sac::fn<map_step>(dst));   // map_step(Engine&, Cell*, Mod<Cell*>*)
// Invariants: equality and hash depend on the stored arguments only.
// Complexity: call, compare and hash are O(number of arguments).
#pragma once

#include <functional>
#include <tuple>
#include <type_traits>
#include <utility>

#include "sac/hash.hpp"

namespace sac {

template <auto F, class... Args>
struct Fn {
  std::tuple<Args...> args;

  template <class... X>
  decltype(auto) operator()(X&&... x) const {
    return std::apply([&](const Args&... a) -> decltype(auto) {
      return std::invoke(F, std::forward<X>(x)..., a...);
    }, args);
  }

  bool operator==(const Fn& o) const { return args == o.args; }
  std::size_t hash() const {
    return hash_combine(reinterpret_cast<std::uintptr_t>(&Fn::tag), Hash<std::tuple<Args...>>{}(args));
  }

 private:
  static constexpr char tag = 0;
};

template <auto F, class... A>
Fn<F, std::decay_t<A>...> fn(A&&... a) {
  return Fn<F, std::decay_t<A>...>{std::tuple<std::decay_t<A>...>(std::forward<A>(a)...)};
}

}  // namespace sac
