// morton.hpp (private) — the Morton (Z) index of a cell of the partition level and back.
//
// Purpose: MpiQuadtree orders its root cells along the Z curve, so that a rank's contiguous
// run of them is a compact region, and a cell's 2^d children are the contiguous indices
// m·2^d .. m·2^d + 2^d − 1 (coarser levels aggregate by division).
// Invariants: morton(from_morton(m, l)) == m for m < 2^(d·l); bit d·b + a of the index is
// bit b of the cell's index on axis a.
// Complexity: O(d·level), level ≤ 10 here.
// Paper: Morton (1966); p4est orders its quadrants the same way.
#pragma once

#include <cstddef>
#include <cstdint>

#include "dynmesh/cell.hpp"

namespace dynmesh::detail {

template <std::size_t d>
constexpr std::uint64_t morton(const CellId<d>& c) noexcept {
  std::uint64_t m = 0;
  for (int b = 0; b < c.level; ++b)
    for (std::size_t a = 0; a < d; ++a) m |= ((c.index[a] >> b) & 1u) << (d * static_cast<std::size_t>(b) + a);
  return m;
}

template <std::size_t d>
constexpr CellId<d> from_morton(std::uint64_t m, int level) noexcept {
  CellId<d> c;
  c.level = level;
  for (int b = 0; b < level; ++b)
    for (std::size_t a = 0; a < d; ++a) c.index[a] |= ((m >> (d * static_cast<std::size_t>(b) + a)) & 1u) << b;
  return c;
}

}  // namespace dynmesh::detail
