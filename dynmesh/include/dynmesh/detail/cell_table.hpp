// dynmesh/detail/cell_table.hpp — open-addressing hash map keyed by CellId.
//
// Purpose: the per-level occupied-cell and split-cell tables of the static quadtree and of the
// invariant checker. One flat array of slots, linear probing, power-of-two capacity, load
// factor ≤ 1/2, backward-shift deletion (no tombstones), locality-preserving home slots (see
// cell_home()). Keys are stored packed (PackedCell: the d index words with the level in the
// top byte of the first word), so a set slot is 8·d bytes. Not a public API: it is installed only because public class templates hold
// one.
// Invariants: an empty slot has first word ~0 (level 255 does not exist); every stored key is
// found by probing from its home slot without crossing an empty slot; size() == number of
// non-empty slots.
// Iteration order depends on hash values and insertion history, so callers must not let
// results depend on it (they sort, or only test membership).
// Complexity: expected O(1) per find/insert/erase; for_each O(capacity).
// Paper: none (engineering).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "dynmesh/cell.hpp"

namespace dynmesh::detail {

struct NoValue {};

/// A CellId packed in d words: the indices, with the level in the top byte of the first
/// word (indices are < 2^52). ~0 in the first word is no cell (level 255 does not exist).
template <std::size_t d>
using PackedCell = std::array<std::uint64_t, d>;

inline constexpr std::uint64_t kNoCell = ~std::uint64_t{0};
inline constexpr int kPackedLevelShift = 56;

template <std::size_t d>
constexpr PackedCell<d> pack_cell(const CellId<d>& c) noexcept {
  PackedCell<d> k = c.index;
  k[0] |= static_cast<std::uint64_t>(c.level) << kPackedLevelShift;
  return k;
}

template <std::size_t d>
constexpr CellId<d> unpack_cell(const PackedCell<d>& k) noexcept {
  CellId<d> c;
  c.level = static_cast<int>(k[0] >> kPackedLevelShift);
  c.index = k;
  c.index[0] &= (std::uint64_t{1} << kPackedLevelShift) - 1;
  return c;
}

template <std::size_t d>
constexpr bool same_cell(const PackedCell<d>& a, const PackedCell<d>& b) noexcept {
  bool eq = a[0] == b[0];
  for (std::size_t k = 1; k < d; ++k) eq &= a[k] == b[k];
  return eq;
}

/// Locality-preserving home slot in a table of mask + 1 slots: the cells of one aligned
/// block of 4^d cells of a level share a scattered base (a hash of the level and the block)
/// and occupy consecutive slots after it, so spatially coherent sequences of operations
/// touch few cache lines. The callers process cells in Morton or (level, i, j, k) order
/// where it matters.
template <std::size_t d>
std::size_t cell_home(const PackedCell<d>& k, std::size_t mask) noexcept {
  constexpr int kBlockBits = 2;  // blocks of 4 cells per axis
  constexpr std::uint64_t kBlockMask = (std::uint64_t{1} << kBlockBits) - 1;
  std::uint64_t h = k[d - 1] >> kBlockBits;
  std::uint64_t low = k[d - 1] & kBlockMask;
  for (std::size_t a = d - 1; a-- > 0;) {
    h = CellHash::mix(h) ^ (k[a] >> kBlockBits);  // k[0]'s level bits stay in the block key
    low = (low << kBlockBits) | (k[a] & kBlockMask);
  }
  return static_cast<std::size_t>((CellHash::mix(h) << (kBlockBits * d)) | low) & mask;
}

template <std::size_t d, class V = NoValue>
class CellTable {
 public:
  CellTable() = default;
  explicit CellTable(std::size_t expected) { reserve(expected); }

  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }

  /// Makes room for `n` keys without rehashing.
  void reserve(std::size_t n) {
    std::size_t cap = 16;
    while (cap < 2 * n) cap <<= 1;
    if (cap > slots_.size()) rehash(cap);
  }

  void clear() noexcept {
    for (auto& s : slots_) s.key[0] = kEmpty;
    size_ = 0;
  }

  /// Inserts key with value `init` if absent. Returns the value slot and whether it was new.
  /// The pointer is invalidated by the next insertion.
  std::pair<V*, bool> try_emplace(const CellId<d>& cell, const V& init = V{}) {
    if (2 * (size_ + 1) > slots_.size()) rehash(slots_.empty() ? 16 : 2 * slots_.size());
    const Key key = pack(cell);
    std::size_t i = home(key);
    while (slots_[i].key[0] != kEmpty) {
      if (same(slots_[i].key, key)) return {&slots_[i].value, false};
      i = (i + 1) & mask_;
    }
    slots_[i].key = key;
    slots_[i].value = init;
    ++size_;
    return {&slots_[i].value, true};
  }

  bool insert(const CellId<d>& cell) { return try_emplace(cell).second; }

  V* find(const CellId<d>& cell) noexcept {
    return const_cast<V*>(static_cast<const CellTable&>(*this).find(cell));
  }
  const V* find(const CellId<d>& cell) const noexcept {
    if (size_ == 0) return nullptr;
    const Key key = pack(cell);
    std::size_t i = home(key);
    while (slots_[i].key[0] != kEmpty) {
      if (same(slots_[i].key, key)) return &slots_[i].value;
      i = (i + 1) & mask_;
    }
    return nullptr;
  }
  bool contains(const CellId<d>& cell) const noexcept { return find(cell) != nullptr; }

  /// Removes the key if present; returns whether it was.
  bool erase(const CellId<d>& cell) noexcept {
    if (size_ == 0) return false;
    const Key key = pack(cell);
    std::size_t i = home(key);
    while (slots_[i].key[0] != kEmpty && !same(slots_[i].key, key)) i = (i + 1) & mask_;
    if (slots_[i].key[0] == kEmpty) return false;
    // Backward shift: move later members of the cluster into the hole unless their home slot
    // lies cyclically in (hole, j].
    std::size_t hole = i, j = i;
    for (;;) {
      j = (j + 1) & mask_;
      if (slots_[j].key[0] == kEmpty) break;
      const std::size_t h = home(slots_[j].key);
      const bool stays = hole <= j ? (hole < h && h <= j) : (hole < h || h <= j);
      if (!stays) {
        slots_[hole] = slots_[j];
        hole = j;
      }
    }
    slots_[hole].key[0] = kEmpty;
    --size_;
    return true;
  }

  /// f(cell, value) for every entry, in table order (see the header note on determinism).
  template <class F>
  void for_each(F&& f) const {
    for (const auto& s : slots_)
      if (s.key[0] != kEmpty) f(unpack(s.key), s.value);
  }

 private:
  using Key = PackedCell<d>;
  static constexpr std::uint64_t kEmpty = kNoCell;

  struct Slot {
    Key key{kEmpty};
    [[no_unique_address]] V value{};
  };

  static bool same(const Key& a, const Key& b) noexcept { return same_cell<d>(a, b); }
  static Key pack(const CellId<d>& c) noexcept { return pack_cell<d>(c); }
  static CellId<d> unpack(const Key& k) noexcept { return unpack_cell<d>(k); }
  std::size_t home(const Key& k) const noexcept { return cell_home<d>(k, mask_); }

  void rehash(std::size_t cap) {
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(cap, Slot{});
    mask_ = cap - 1;
    for (const auto& s : old) {
      if (s.key[0] == kEmpty) continue;
      std::size_t i = home(s.key);
      while (slots_[i].key[0] != kEmpty) i = (i + 1) & mask_;
      slots_[i] = s;
    }
  }

  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

template <std::size_t d>
using CellSet = CellTable<d, NoValue>;

}  // namespace dynmesh::detail
