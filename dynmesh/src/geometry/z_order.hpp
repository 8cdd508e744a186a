// z_order.hpp (private) — the Z-order (Morton) code of two 32-bit grid coordinates.
//
// Purpose: one interleaving for the places that sort 2D points along a space-filling curve
// (the mesh checker's vertex tree, the hpu mesh's insertion order).
// Invariants: bit 2i of the code is bit i of x, bit 2i+1 is bit i of y; so the code is
// monotone in x for fixed y and in y for fixed x.
// Complexity: O(1).
// Paper: Morton (1966).
#pragma once

#include <cstdint>

namespace dynmesh::detail {

/// x's bits spread to the even positions of a 64-bit word.
constexpr std::uint64_t spread_bits(std::uint32_t v) noexcept {
  std::uint64_t x = v;
  x = (x | (x << 16)) & 0x0000'ffff'0000'ffffULL;
  x = (x | (x << 8)) & 0x00ff'00ff'00ff'00ffULL;
  x = (x | (x << 4)) & 0x0f0f'0f0f'0f0f'0f0fULL;
  x = (x | (x << 2)) & 0x3333'3333'3333'3333ULL;
  x = (x | (x << 1)) & 0x5555'5555'5555'5555ULL;
  return x;
}

constexpr std::uint64_t z_order(std::uint32_t x, std::uint32_t y) noexcept {
  return spread_bits(x) | (spread_bits(y) << 1);
}

}  // namespace dynmesh::detail
