// sac/fn.hpp — sac::fn<f>(args...): a comparable, hashable closure for memoized calls.
//
// Purpose: memo() and memo_read() match a call against the old trace by comparing closures,
// and C++ lambdas cannot be compared. fn<f>(a, b) stores f (a function known at compile time)
// and the argument values; calling it with leading arguments x... calls f(x..., a, b).
// Two Fn values are equal when their argument tuples are equal.
//   rt.memo_read(list, sac::fn<map_step>(dst));   // map_step(Engine&, Cell*, Mod<Cell*>*)
// When f is a plain function, an argument whose parameter (the trailing parameters of f
// take the arguments) is a number, an enum or a pointer is stored as that parameter's type:
// fn<f>(0) and fn<f>(0L), or fn<f>(p) with T* p and with const T* p, are then the same
// closure and match. (Stored as the arguments' own types, they never matched: the results
// stayed right, but every memo lookup missed.) Other arguments are stored as their decayed
// type, so a parameter that is a view (std::span, std::string_view) still stores the
// owning argument.
// Invariants: equality and hash depend on the stored arguments only; fn<f>(a...) and
// fn<f>(b...) with equal values after that conversion are equal.
// Complexity: call, compare and hash are O(number of arguments).
// Paper: docs/DESIGN.md, "Memoization and keyed allocation".
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

namespace detail {

/// The parameter types of a plain function pointer (unknown otherwise).
template <class F>
struct FnParams {
  static constexpr bool known = false;
};
template <class R, class... P>
struct FnParams<R (*)(P...)> {
  static constexpr bool known = true;
  using type = std::tuple<P...>;
};
template <class R, class... P>
struct FnParams<R (*)(P...) noexcept> : FnParams<R (*)(P...)> {};

/// What an argument of type A bound to parameter P is stored as.
template <class P, class A>
using StoredArg = std::conditional_t<std::is_arithmetic_v<std::decay_t<P>> || std::is_enum_v<std::decay_t<P>> ||
                                         std::is_pointer_v<std::decay_t<P>>,
                                     std::decay_t<P>, std::decay_t<A>>;

template <auto F, class... A>
struct FnStorage {
  using type = Fn<F, std::decay_t<A>...>;
};

template <auto F, class... A>
  requires(FnParams<decltype(F)>::known &&
           std::tuple_size_v<typename FnParams<decltype(F)>::type> >= sizeof...(A))
struct FnStorage<F, A...> {
  using Params = typename FnParams<decltype(F)>::type;
  static constexpr std::size_t kFirst = std::tuple_size_v<Params> - sizeof...(A);
  template <std::size_t... I>
  static auto pick(std::index_sequence<I...>)
      -> Fn<F, StoredArg<std::tuple_element_t<kFirst + I, Params>, A>...>;
  using type = decltype(pick(std::index_sequence_for<A...>{}));
};

template <class T>
struct FnArgs;
template <auto F, class... S>
struct FnArgs<Fn<F, S...>> {
  using tuple = std::tuple<S...>;
};

}  // namespace detail

template <auto F, class... A>
typename detail::FnStorage<F, A...>::type fn(A&&... a) {
  using R = typename detail::FnStorage<F, A...>::type;
  return R{typename detail::FnArgs<R>::tuple(std::forward<A>(a)...)};
}

}  // namespace sac
