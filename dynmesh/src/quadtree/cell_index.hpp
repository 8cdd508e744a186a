// cell_index.hpp (private) — an open-addressing index of objects that carry their own cell.
//
// Purpose: the quadtree directory's table (quadtree_core.hpp). It stores only pointers: the
// key is read from the object (T::key, a PackedCell), so an entry is 8 bytes instead of the
// key and a pointer (8·d + 8 in a CellTable<d, T*>), and the key is not held twice. An
// entry's top 16 bits, which no user-space pointer uses on x86-64 or AArch64, hold a tag
// hashed from its key, so probing reads an object only when the tag matches; that lets the
// table fill to 3/4 (a sparser table is a visible part of the trace). Linear probing,
// power-of-two capacity, backward-shift deletion, CellTable's locality-preserving home slots
// (cell_home).
// Invariants (check_invariants()): every entry is found by probing from its own key's home
// without crossing an empty slot (an object whose key changed is caught here); its tag is
// its key's; no key is indexed twice; size() is the number of entries; load ≤ 3/4.
// Iteration order depends on hash values and history: callers must not let results depend
// on it.
// Complexity: expected O(1) per find/insert/erase; for_each and check_invariants O(capacity).
// Paper: none (engineering).
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

#include "dynmesh/detail/cell_table.hpp"
#include "dynmesh/errors.hpp"

namespace dynmesh::detail {

template <std::size_t d, class T>
class CellIndex {
  static_assert(sizeof(T*) == 8, "the tags live in a pointer's top 16 bits");
  using Entry = std::uintptr_t;  // the object's address | its key's tag; 0 when empty
  static constexpr int kTagShift = 48;
  static constexpr Entry kAddress = (Entry{1} << kTagShift) - 1;

 public:
  std::size_t size() const noexcept { return size_; }
  /// Bytes of the slot array at its capacity.
  std::size_t bytes() const noexcept { return slots_.capacity() * sizeof(Entry); }

  T* find(const CellId<d>& cell) const noexcept {
    if (size_ == 0) return nullptr;
    const PackedCell<d> key = pack_cell<d>(cell);
    const Entry tag = tag_of(key);
    for (std::size_t i = cell_home<d>(key, mask_); slots_[i]; i = (i + 1) & mask_)
      if ((slots_[i] & ~kAddress) == tag && same_cell<d>(object(slots_[i])->key, key)) return object(slots_[i]);
    return nullptr;
  }

  /// Adds t, whose key must not be indexed yet.
  void insert(T* t) {
    if (reinterpret_cast<Entry>(t) & ~kAddress)
      throw std::length_error("dynmesh: cell index: an object address above 2^48");
    if (4 * (size_ + 1) > 3 * slots_.size()) rehash(slots_.empty() ? 16 : 2 * slots_.size());
    place(t);
    ++size_;
  }

  /// Removes the object indexed under cell; returns whether there was one.
  bool erase(const CellId<d>& cell) noexcept {
    if (size_ == 0) return false;
    const PackedCell<d> key = pack_cell<d>(cell);
    const Entry tag = tag_of(key);
    std::size_t i = cell_home<d>(key, mask_);
    while (slots_[i] && !((slots_[i] & ~kAddress) == tag && same_cell<d>(object(slots_[i])->key, key)))
      i = (i + 1) & mask_;
    if (!slots_[i]) return false;
    // Backward shift: move later members of the cluster into the hole unless their home slot
    // lies cyclically in (hole, j].
    std::size_t hole = i, j = i;
    for (;;) {
      j = (j + 1) & mask_;
      if (!slots_[j]) break;
      const std::size_t h = cell_home<d>(object(slots_[j])->key, mask_);
      const bool stays = hole <= j ? (hole < h && h <= j) : (hole < h || h <= j);
      if (!stays) {
        slots_[hole] = slots_[j];
        hole = j;
      }
    }
    slots_[hole] = 0;
    --size_;
    return true;
  }

  /// f(T*) for every entry, in table order.
  template <class F>
  void for_each(F&& f) const {
    for (Entry e : slots_)
      if (e) f(object(e));
  }

  /// Throws InvariantError naming the first broken rule (see the header). O(capacity).
  void check_invariants() const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < slots_.size(); ++i) {
      if (!slots_[i]) continue;
      ++n;
      const PackedCell<d>& key = object(slots_[i])->key;
      if ((slots_[i] & ~kAddress) != tag_of(key))
        throw InvariantError("dynmesh: cell index: an entry whose tag is not its cell's: " +
                             to_string(unpack_cell<d>(key)));
      // Probing for its key from its home must reach slot i first.
      std::size_t j = cell_home<d>(key, mask_);
      while (j != i && slots_[j] && !same_cell<d>(object(slots_[j])->key, key)) j = (j + 1) & mask_;
      if (j != i)
        throw InvariantError(slots_[j] ? "dynmesh: cell index: a cell indexed twice: " + to_string(unpack_cell<d>(key))
                                       : "dynmesh: cell index: an entry not reachable from its cell's home: " +
                                             to_string(unpack_cell<d>(key)));
    }
    if (n != size_) throw InvariantError("dynmesh: cell index: size() is not the number of entries");
    if (4 * size_ > 3 * slots_.size()) throw InvariantError("dynmesh: cell index: load above 3/4");
  }

 private:
  static T* object(Entry e) noexcept { return reinterpret_cast<T*>(e & kAddress); }
  /// 16 bits of the key, hashed apart from cell_home's bits (which come from the same key).
  static Entry tag_of(const PackedCell<d>& key) noexcept {
    std::uint64_t h = 0x2545f4914f6cdd1dULL;
    for (std::uint64_t w : key) h = CellHash::mix(h ^ w);
    return static_cast<Entry>(h >> kTagShift) << kTagShift;
  }

  void place(T* t) {
    std::size_t i = cell_home<d>(t->key, mask_);
    while (slots_[i]) i = (i + 1) & mask_;
    slots_[i] = reinterpret_cast<Entry>(t) | tag_of(t->key);
  }

  void rehash(std::size_t cap) {
    std::vector<Entry> old = std::move(slots_);
    slots_.assign(cap, 0);
    mask_ = cap - 1;
    for (Entry e : old)
      if (e) place(object(e));
  }

  std::vector<Entry> slots_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

}  // namespace dynmesh::detail
