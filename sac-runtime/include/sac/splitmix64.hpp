// sac/splitmix64.hpp — the one statement of splitmix64 (Steele, Lea and Flood, 2014).
//
// Purpose: every hash and seed scrambler in this project mixes bits with this one function
// and this one constant, so there is a single place to read them.
//   kGoldenGamma – 2^64/φ rounded to odd: splitmix64's increment, and the odd multiplier
//                  the hashes use to spread a small integer (a level, a seed) over 64 bits;
//   mix64(x)     – splitmix64's finaliser, a bijection on 64 bits with full avalanche;
//   splitmix64(s)– one step of the generator: advance the state s, return mixed bits.
// Invariants: these are bit-stable. Hash values only choose buckets, but seeds scrambled
// here choose the points of the test and benchmark distributions, so a change to these
// functions changes those point sets. Complexity: O(1).
// Paper: none (G. L. Steele, D. Lea, C. H. Flood, "Fast splittable pseudorandom number
// generators", OOPSLA 2014).
#pragma once

#include <cstdint>

namespace sac {

inline constexpr std::uint64_t kGoldenGamma = 0x9e3779b97f4a7c15ULL;

constexpr std::uint64_t mix64(std::uint64_t x) noexcept {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

constexpr std::uint64_t splitmix64(std::uint64_t& state) noexcept {
  state += kGoldenGamma;
  return mix64(state);
}

}  // namespace sac
