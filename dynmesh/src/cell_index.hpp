// cell_index.hpp (private) — an open-addressing index of objects that carry their own cell.
//
// Purpose: the quadtree directory's table (quadtree_core.hpp). It stores only pointers: the
// key is read from the object (T::key, a PackedCell), so an entry is 8 bytes instead of the
// key and a pointer (8·d + 8 in a CellTable<d, T*>), and the key is not held twice. Probing
// reads the object, which a lookup is about to use anyway. Linear probing, power-of-two
// capacity, load factor ≤ 1/2, backward-shift deletion, CellTable's locality-preserving home
// slots (cell_home).
// Invariants (check_invariants()): every entry is found by probing from its own key's home
// without crossing an empty slot (an object whose key changed is caught here); no key is
// indexed twice; size() is the number of entries.
// Iteration order depends on hash values and history: callers must not let results depend
// on it.
// Complexity: expected O(1) per find/insert/erase; for_each and check_invariants O(capacity).
// Paper: none (engineering).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "dynmesh/detail/cell_table.hpp"
#include "dynmesh/errors.hpp"

namespace dynmesh::detail {

template <std::size_t d, class T>
class CellIndex {
 public:
  std::size_t size() const noexcept { return size_; }
  /// Bytes of the slot array at its capacity.
  std::size_t bytes() const noexcept { return slots_.capacity() * sizeof(T*); }

  T* find(const CellId<d>& cell) const noexcept {
    if (size_ == 0) return nullptr;
    const PackedCell<d> key = pack_cell<d>(cell);
    for (std::size_t i = cell_home<d>(key, mask_); slots_[i]; i = (i + 1) & mask_)
      if (same_cell<d>(slots_[i]->key, key)) return slots_[i];
    return nullptr;
  }

  /// Adds t, whose key must not be indexed yet.
  void insert(T* t) {
    if (2 * (size_ + 1) > slots_.size()) rehash(slots_.empty() ? 16 : 2 * slots_.size());
    place(t);
    ++size_;
  }

  /// Removes the object indexed under cell; returns whether there was one.
  bool erase(const CellId<d>& cell) noexcept {
    if (size_ == 0) return false;
    const PackedCell<d> key = pack_cell<d>(cell);
    std::size_t i = cell_home<d>(key, mask_);
    while (slots_[i] && !same_cell<d>(slots_[i]->key, key)) i = (i + 1) & mask_;
    if (!slots_[i]) return false;
    // Backward shift: move later members of the cluster into the hole unless their home slot
    // lies cyclically in (hole, j].
    std::size_t hole = i, j = i;
    for (;;) {
      j = (j + 1) & mask_;
      if (!slots_[j]) break;
      const std::size_t h = cell_home<d>(slots_[j]->key, mask_);
      const bool stays = hole <= j ? (hole < h && h <= j) : (hole < h || h <= j);
      if (!stays) {
        slots_[hole] = slots_[j];
        hole = j;
      }
    }
    slots_[hole] = nullptr;
    --size_;
    return true;
  }

  /// f(T*) for every entry, in table order.
  template <class F>
  void for_each(F&& f) const {
    for (T* t : slots_)
      if (t) f(t);
  }

  /// Throws InvariantError naming the first broken rule (see the header). O(capacity).
  void check_invariants() const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < slots_.size(); ++i) {
      if (!slots_[i]) continue;
      ++n;
      // Probing for its key from its home must reach slot i first.
      const PackedCell<d>& key = slots_[i]->key;
      std::size_t j = cell_home<d>(key, mask_);
      while (j != i && slots_[j] && !same_cell<d>(slots_[j]->key, key)) j = (j + 1) & mask_;
      if (j != i)
        throw InvariantError(slots_[j] ? "dynmesh: cell index: a cell indexed twice: " + to_string(unpack_cell<d>(key))
                                       : "dynmesh: cell index: an entry not reachable from its cell's home: " +
                                             to_string(unpack_cell<d>(key)));
    }
    if (n != size_) throw InvariantError("dynmesh: cell index: size() is not the number of entries");
  }

 private:
  void place(T* t) {
    std::size_t i = cell_home<d>(t->key, mask_);
    while (slots_[i]) i = (i + 1) & mask_;
    slots_[i] = t;
  }

  void rehash(std::size_t cap) {
    std::vector<T*> old = std::move(slots_);
    slots_.assign(cap, nullptr);
    mask_ = cap - 1;
    for (T* t : old)
      if (t) place(t);
  }

  std::vector<T*> slots_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

}  // namespace dynmesh::detail
