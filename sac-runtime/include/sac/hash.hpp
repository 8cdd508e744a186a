// sac/hash.hpp — hashing of memo keys and allocation keys.
//
// Purpose: keys of memo(), memo_read() and alloc() are hashed with sac::Hash<K>. Built in:
// integers, enums, pointers, floating point (by bit pattern), std::pair, std::tuple, and any
// type with a `std::size_t hash() const` member (sac::Fn closures have one).
// Hash values only choose buckets; matches are decided by operator==, and among equal keys
// by trace time, so results never depend on pointer values (docs/DESIGN.md, "Determinism").
// Invariants: a == b implies Hash(a) == Hash(b). Complexity: O(size of the key).
// Paper: docs/DESIGN.md, "Memoization and keyed allocation".
#pragma once

#include <bit>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <type_traits>
#include <utility>

#include "sac/splitmix64.hpp"

namespace sac {

inline std::uint64_t hash_combine(std::uint64_t seed, std::uint64_t h) {
  return mix64(seed ^ (h + kGoldenGamma + (seed << 6) + (seed >> 2)));
}

template <class K, class = void>
struct Hash;

/// Locality-preserving hash: keys that differ only in their low `shift + 8` bits land in one
/// block of 256 consecutive buckets; blocks are scattered. Building a table from keys that
/// arrive in address (or counting) order then touches memory sequentially, which is what
/// makes keyed allocation cheap in from-scratch runs.
inline std::uint64_t local_hash(std::uint64_t k, unsigned shift) {
  const std::uint64_t x = k >> shift;
  return (mix64(x >> 8) << 8) | (x & 0xff);
}

template <class K>
  requires(std::is_integral_v<K> || std::is_enum_v<K> || std::is_pointer_v<K>)
struct Hash<K> {
  std::size_t operator()(const K& k) const {
    if constexpr (std::is_pointer_v<K>)
      return local_hash(static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(k)), 4);
    else
      return local_hash(static_cast<std::uint64_t>(k), 0);
  }
};

template <class K>
  requires std::is_floating_point_v<K>
struct Hash<K> {
  std::size_t operator()(const K& k) const {
    K z = k == K(0) ? K(0) : k;  // +0 and -0 compare equal, so they must hash equal
    if constexpr (sizeof(K) == 8) return mix64(std::bit_cast<std::uint64_t>(z));
    else if constexpr (sizeof(K) == 4) return mix64(std::bit_cast<std::uint32_t>(z));
    else return mix64(static_cast<std::uint64_t>(static_cast<double>(z)));
  }
};

template <class K>
  requires requires(const K& k) {
    { k.hash() } -> std::convertible_to<std::size_t>;
  }
struct Hash<K> {
  std::size_t operator()(const K& k) const { return k.hash(); }
};

template <class A, class B>
struct Hash<std::pair<A, B>> {
  std::size_t operator()(const std::pair<A, B>& p) const {
    // The first component keeps its locality; the second perturbs the block.
    const std::uint64_t a = Hash<A>{}(p.first);
    return a ^ (mix64(Hash<B>{}(p.second)) & ~std::uint64_t{0xff});
  }
};

template <class... Ts>
struct Hash<std::tuple<Ts...>> {
  std::size_t operator()(const std::tuple<Ts...>& t) const {
    std::uint64_t h = 0x51ed27a5ULL;
    std::apply([&](const Ts&... x) { ((h = hash_combine(h, Hash<Ts>{}(x))), ...); }, t);
    return h;
  }
};

template <class K>
concept Hashable = requires(const K& k) {
  { Hash<K>{}(k) } -> std::convertible_to<std::size_t>;
};

}  // namespace sac
