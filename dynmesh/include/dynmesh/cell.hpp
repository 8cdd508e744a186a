// dynmesh/cell.hpp — quadtree/octree cells on the exact 2^52 grid.
//
// Purpose: the cell of docs/DESIGN.md, "The quadtree contract": a cell at level l (0..52) with
// integer index i (each coordinate in [0, 2^l)) covers [o + i·L/2^l, o + (i+1)·L/2^l)^d.
// In integer positions (point.hpp) it covers the q with q >> (52 − l) == i, that is the
// half-open block [i·2^(52−l), (i+1)·2^(52−l)) per axis. Everything here is integer
// arithmetic on indices; no floating point is involved after point location.
//
//   CellId<d>              level + index; ordered by (level, i, j, k), the `.cells` order.
//   parent/child/children  the 2^d-ary tree structure.
//   contains               a located point, or a descendant cell.
//   touches(a, b)          closed boxes intersect (faces, edges and vertices count), any levels.
//   for_each_neighbour     N(c) \ {c}: the up to 3^d − 1 same-level cells around c, in the box.
//   neighbourhood(c)       N(c) ∩ box, c included (the block whose points make c crowded).
//   for_each_coarser_touching / coarser_touching / coarser_touching_at
//                          the level m−1 cells that touch a level-m cell: its parent and the
//                          parent's neighbours on the sides the cell lies on (up to 2^d).
//   CellHash               hash for unordered containers and detail::CellTable.
//
// Invariants: valid(c) ⇔ 0 ≤ level ≤ 52 and every index < 2^level. All functions except
// valid() require valid cells (and level ≥ 1 for parent and coarser-touching, level < 52 for
// child); cells outside the box are never produced.
// Complexity: O(d) per cell operation; neighbour enumerations O(3^d) or O(2^d).
// Paper: Acar & Hudson, Section 2 (cells, neighbours "through vertices", Figure 3).
#pragma once

#include <array>
#include <compare>
#include <cstddef>
#include <cstdint>
#include <string>

#include "dynmesh/point.hpp"
#include "sac/splitmix64.hpp"

namespace dynmesh {

template <std::size_t d>
  requires SupportedDim<d>
struct CellId {
  int level = 0;
  std::array<std::uint64_t, d> index{};

  static constexpr CellId root() noexcept { return CellId{}; }

  friend constexpr bool operator==(const CellId& a, const CellId& b) noexcept {
    if (a.level != b.level) return false;
    for (std::size_t k = 0; k < d; ++k)
      if (a.index[k] != b.index[k]) return false;
    return true;
  }
  /// (level, i, j, k) lexicographic: the order of `.cells` files.
  /// The `.hash()` member sac::Hash looks for, so that a cell can key a keyed allocation
  /// or a memoized call (duck-typed: this header needs nothing from sac/).
  constexpr std::size_t hash() const noexcept {
    std::uint64_t h = sac::mix64(static_cast<std::uint64_t>(level) + sac::kGoldenGamma);
    for (std::size_t k = 0; k < d; ++k) h = sac::mix64(h ^ index[k]);
    return static_cast<std::size_t>(h);
  }

  friend constexpr std::strong_ordering operator<=>(const CellId& a, const CellId& b) noexcept {
    if (a.level != b.level) return a.level <=> b.level;
    for (std::size_t k = 0; k < d; ++k)
      if (a.index[k] != b.index[k]) return a.index[k] <=> b.index[k];
    return std::strong_ordering::equal;
  }
};

/// 2^d and 3^d.
template <std::size_t d>
inline constexpr int kChildren = 1 << d;
template <std::size_t d>
inline constexpr int kNeighbourhood = d == 2 ? 9 : 27;

/// A fixed-capacity list of cells (no allocation), for neighbourhoods.
template <std::size_t d, int Capacity>
class CellList {
 public:
  void push_back(const CellId<d>& c) noexcept { items_[size_++] = c; }
  int size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  const CellId<d>& operator[](int i) const noexcept { return items_[static_cast<std::size_t>(i)]; }
  const CellId<d>* begin() const noexcept { return items_.data(); }
  const CellId<d>* end() const noexcept { return items_.data() + size_; }

 private:
  std::array<CellId<d>, Capacity> items_{};
  int size_ = 0;
};

/// Number of index values at `level`: 2^level.
constexpr std::uint64_t cells_per_axis(int level) noexcept { return std::uint64_t{1} << level; }

template <std::size_t d>
constexpr bool valid(const CellId<d>& c) noexcept {
  if (c.level < 0 || c.level > kMaxLevel) return false;
  for (std::size_t a = 0; a < d; ++a)
    if (c.index[a] >= cells_per_axis(c.level)) return false;
  return true;
}

/// The cell of level `level` containing the located point q: q >> (52 − level).
template <std::size_t d>
constexpr CellId<d> cell_of(const Position<d>& q, int level) noexcept {
  CellId<d> c;
  c.level = level;
  for (std::size_t a = 0; a < d; ++a) c.index[a] = q[a] >> (kMaxLevel - level);
  return c;
}

template <std::size_t d>
constexpr CellId<d> parent(const CellId<d>& c) noexcept {
  CellId<d> p;
  p.level = c.level - 1;
  for (std::size_t a = 0; a < d; ++a) p.index[a] = c.index[a] >> 1;
  return p;
}

/// The ancestor of c at `level` (≤ c.level); c itself when level == c.level.
template <std::size_t d>
constexpr CellId<d> ancestor(const CellId<d>& c, int level) noexcept {
  CellId<d> p;
  p.level = level;
  for (std::size_t a = 0; a < d; ++a) p.index[a] = c.index[a] >> (c.level - level);
  return p;
}

/// Child number `which` (0 ≤ which < 2^d): bit a of `which` selects the upper half on axis a.
template <std::size_t d>
constexpr CellId<d> child(const CellId<d>& c, unsigned which) noexcept {
  CellId<d> k;
  k.level = c.level + 1;
  for (std::size_t a = 0; a < d; ++a) k.index[a] = (c.index[a] << 1) | ((which >> a) & 1u);
  return k;
}

template <std::size_t d>
constexpr std::array<CellId<d>, kChildren<d>> children(const CellId<d>& c) noexcept {
  std::array<CellId<d>, kChildren<d>> ks{};
  for (unsigned w = 0; w < static_cast<unsigned>(kChildren<d>); ++w) ks[w] = child(c, w);
  return ks;
}

/// Does c contain the located point q?
template <std::size_t d>
constexpr bool contains(const CellId<d>& c, const Position<d>& q) noexcept {
  for (std::size_t a = 0; a < d; ++a)
    if ((q[a] >> (kMaxLevel - c.level)) != c.index[a]) return false;
  return true;
}

/// Does `outer` contain `inner` (inner is outer or a descendant of it)?
template <std::size_t d>
constexpr bool contains(const CellId<d>& outer, const CellId<d>& inner) noexcept {
  if (inner.level < outer.level) return false;
  for (std::size_t a = 0; a < d; ++a)
    if ((inner.index[a] >> (inner.level - outer.level)) != outer.index[a]) return false;
  return true;
}

/// Do the closed boxes of a and b intersect? Cells of any levels; contact through a face,
/// an edge or a vertex counts, and a cell touches itself and its ancestors.
template <std::size_t d>
constexpr bool touches(const CellId<d>& a, const CellId<d>& b) noexcept {
  // Compare in units of the finer level: the coarser cell spans [i·2^s, (i+1)·2^s].
  const int fine = a.level > b.level ? a.level : b.level;
  const int sa = fine - a.level, sb = fine - b.level;
  for (std::size_t k = 0; k < d; ++k) {
    const std::uint64_t alo = a.index[k] << sa, ahi = (a.index[k] + 1) << sa;
    const std::uint64_t blo = b.index[k] << sb, bhi = (b.index[k] + 1) << sb;
    if (alo > bhi || blo > ahi) return false;
  }
  return true;
}

/// Calls f(nb) for each cell of N(c) other than c that lies in the box (up to 3^d − 1 cells),
/// in a fixed order (offsets −1, 0, +1 per axis, axis 0 fastest).
template <std::size_t d, class F>
constexpr void for_each_neighbour(const CellId<d>& c, F&& f) {
  const std::uint64_t n = cells_per_axis(c.level);
  for (int code = 0; code < kNeighbourhood<d>; ++code) {
    if (code == (kNeighbourhood<d> - 1) / 2) continue;  // the all-zero offset: c itself
    CellId<d> nb;
    nb.level = c.level;
    bool inside = true;
    int rest = code;
    for (std::size_t a = 0; a < d; ++a) {
      const int off = rest % 3 - 1;
      rest /= 3;
      if (off < 0) {
        if (c.index[a] == 0) inside = false;
        nb.index[a] = c.index[a] - 1;
      } else if (off > 0) {
        if (c.index[a] + 1 >= n) inside = false;
        nb.index[a] = c.index[a] + 1;
      } else {
        nb.index[a] = c.index[a];
      }
    }
    if (inside) f(nb);
  }
}

/// N(c) ∩ box: c and its same-level neighbours (3^d when c is away from the box boundary).
template <std::size_t d>
constexpr CellList<d, kNeighbourhood<d>> neighbourhood(const CellId<d>& c) {
  CellList<d, kNeighbourhood<d>> out;
  out.push_back(c);
  for_each_neighbour(c, [&](const CellId<d>& nb) { out.push_back(nb); });
  return out;
}

/// The cell u of level c.level − 1 that touches c (c.level ≥ 1) selected by `mask`
/// (0 ≤ mask < 2^d): per axis the parent's index P where the mask bit is 0, and where it is
/// 1 the index on the side c lies on, P − 1 (c is a lower child) or P + 1 (c is an upper
/// child). Mask 0 is the parent. False when u would lie outside the box.
template <std::size_t d>
constexpr bool coarser_touching_at(const CellId<d>& c, unsigned mask, CellId<d>& u) {
  u = parent(c);
  const std::uint64_t n = cells_per_axis(u.level);
  for (std::size_t a = 0; a < d; ++a) {
    if (!((mask >> a) & 1u)) continue;
    if (c.index[a] & 1u) {
      if (u.index[a] + 1 >= n) return false;
      ++u.index[a];
    } else {
      if (u.index[a] == 0) return false;
      --u.index[a];
    }
  }
  return true;
}

/// Calls f(u) for each cell u of level c.level − 1 that touches c (c.level ≥ 1), by mask
/// (coarser_touching_at): the parent itself first.
template <std::size_t d, class F>
constexpr void for_each_coarser_touching(const CellId<d>& c, F&& f) {
  CellId<d> u;
  for (unsigned mask = 0; mask < static_cast<unsigned>(kChildren<d>); ++mask)
    if (coarser_touching_at(c, mask, u)) f(u);
}

template <std::size_t d>
constexpr CellList<d, kChildren<d>> coarser_touching(const CellId<d>& c) {
  CellList<d, kChildren<d>> out;
  for_each_coarser_touching(c, [&](const CellId<d>& u) { out.push_back(u); });
  return out;
}

struct CellHash {
  template <std::size_t d>
  std::size_t operator()(const CellId<d>& c) const noexcept {
    std::uint64_t h = sac::kGoldenGamma * static_cast<std::uint64_t>(c.level + 1);
    for (std::size_t a = 0; a < d; ++a) h = mix(h ^ (c.index[a] + 0x632be59bd9b4e019ULL * static_cast<std::uint64_t>(a + 1)));
    return static_cast<std::size_t>(h);
  }
  static constexpr std::uint64_t mix(std::uint64_t x) noexcept { return sac::mix64(x); }
};

/// "level:(i,j[,k])", for messages.
template <std::size_t d>
std::string to_string(const CellId<d>& c) {
  std::string s = std::to_string(c.level) + ":(";
  for (std::size_t a = 0; a < d; ++a) {
    if (a) s += ',';
    s += std::to_string(c.index[a]);
  }
  return s + ")";
}

}  // namespace dynmesh
