// steiner_vertices.hpp (private) — the hpu program's Steiner vertices, one object per point,
// outside the trace.
//
// Purpose: a step that depends on a cell compares the cell's vertices by identity
// (cell_interest.hpp, same_inside), so a Steiner vertex that the program makes again at the same
// point must be the same object, or every step that reads it re-runs, and their outputs
// (pairs, entries, off-centers) are new objects in turn. A keyed allocation in the trace gives
// the old object back only inside the re-executed read's window, so an off-center whose try
// re-ran elsewhere would be a new object, and every step that read the old one would re-run.
// Here a point maps to one CellVertex while any trace record
// holds it (SteinerRef, a keyed allocation, holds one reference), and a vertex left without
// references is freed only by collect(), which the mutator calls after a propagation, so a
// vertex released and made again within one propagation is the same object.
// Invariants (check_invariants): the table maps each point to the vertex at it; a vertex's
// references are what acquire() gave minus what release() took, never below zero; every idle
// vertex (no references, not yet collected) is in the idle list (twice when it was released,
// acquired and released again since the last collect()).
// Complexity: acquire/release O(1) expected (open addressing on the point's bits);
// collect O(idle).
// Paper: Acar & Hudson, Section 4: keyed allocation, here with the key's identity kept for
// the whole propagation rather than within a window.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <type_traits>
#include <vector>

#include <sac/hash.hpp>

#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"
#include "hpu/cell_store.hpp"

namespace dynmesh::detail {

class SteinerVertices {
 public:
  SteinerVertices() : table_(kFirstTable, kEmpty) {}
  SteinerVertices(const SteinerVertices&) = delete;
  SteinerVertices& operator=(const SteinerVertices&) = delete;

  /// The vertex at p, made if there is none; one more reference to it.
  const CellVertex* acquire(const Point<2>& p) {
    std::size_t i = find(p);
    if (table_[i] == kEmpty) {
      const std::uint32_t s = make(p);
      table_[i] = s;
      if (2 * ++live_ > table_.size()) grow();
      ++slots_[s].refs;
      return &slots_[s].v;
    }
    Slot& x = slots_[table_[i]];
    ++x.refs;
    return &x.v;
  }

  /// One reference fewer to v; with none left it waits for collect().
  void release(const CellVertex* v) noexcept {
    Slot& x = slot_of(v);
    if (--x.refs == 0) idle_.push_back(x.self);
  }

  /// Frees the vertices left without references (after a propagation: no trace record
  /// holds them then).
  void collect() {
    for (const std::uint32_t s : idle_) {
      Slot& x = slots_[s];
      if (x.refs != 0 || x.free) continue;  // acquired again, or listed twice
      erase(x.v.p);
      x.free = true;
      x.next_free = free_;
      free_ = s;
      --live_;
    }
    idle_.clear();
  }

  std::size_t size() const noexcept { return live_; }
  std::size_t bytes() const noexcept {
    return slots_.size() * sizeof(Slot) + table_.size() * sizeof(std::uint32_t) + idle_.capacity() * sizeof(std::uint32_t);
  }

  void check_invariants() const {
    std::vector<bool> listed(slots_.size(), false);
    for (const std::uint32_t s : idle_) listed[s] = true;
    std::size_t in_table = 0;
    for (std::size_t i = 0; i < table_.size(); ++i) {
      if (table_[i] == kEmpty) continue;
      ++in_table;
      const Slot& x = slots_[table_[i]];
      if (x.free) throw InvariantError("dynmesh: SteinerVertices: a freed vertex in the table");
      if (find(x.v.p) != i) throw InvariantError("dynmesh: SteinerVertices: a vertex not where its point hashes");
      if (x.refs < 0) throw InvariantError("dynmesh: SteinerVertices: released more often than acquired");
      if (x.refs == 0 && !listed[table_[i]])
        throw InvariantError("dynmesh: SteinerVertices: a vertex without references that collect() would miss");
    }
    if (in_table != live_) throw InvariantError("dynmesh: SteinerVertices: the live count disagrees with the table");
  }

 private:
  struct Slot {
    Slot(const Point<2>& p, std::uint32_t i) : v(p), self(i) {}
    CellVertex v;
    std::int32_t refs = 0;
    bool free = false;
    std::uint32_t self;  // its index in slots_
    std::uint32_t next_free = 0;
  };
  // slot_of() finds a slot from its vertex's address, which standard layout makes the slot's.
  static_assert(std::is_standard_layout_v<Slot>);
  static constexpr std::uint32_t kEmpty = 0xffffffffu;
  static constexpr std::size_t kFirstTable = 1024;

  // Points are equal as doubles, as the trace's keys compare them (so -0.0 is 0.0), and are
  // hashed as the trace hashes its keys' doubles.
  static std::uint64_t hash(const Point<2>& p) noexcept {
    return sac::hash_combine(sac::Hash<double>{}(p[0]), sac::Hash<double>{}(p[1]));
  }
  static bool same(const Point<2>& a, const Point<2>& b) noexcept { return a[0] == b[0] && a[1] == b[1]; }
  /// p's place in the table: its vertex's, or the empty one where it would go.
  std::size_t find(const Point<2>& p) const noexcept {
    const std::size_t mask = table_.size() - 1;
    for (std::size_t i = hash(p) & mask;; i = (i + 1) & mask)
      if (table_[i] == kEmpty || same(slots_[table_[i]].v.p, p)) return i;
  }
  /// Linear probing without tombstones: the entries after the hole move back into it.
  void erase(const Point<2>& p) noexcept {
    const std::size_t mask = table_.size() - 1;
    std::size_t i = find(p);
    table_[i] = kEmpty;
    for (std::size_t j = (i + 1) & mask; table_[j] != kEmpty; j = (j + 1) & mask) {
      const std::size_t home = hash(slots_[table_[j]].v.p) & mask;
      // j's entry may fill the hole at i unless its home lies cyclically in (i, j].
      if (((j - home) & mask) >= ((j - i) & mask)) {
        table_[i] = table_[j];
        table_[j] = kEmpty;
        i = j;
      }
    }
  }
  void grow() {
    std::vector<std::uint32_t> old(table_.size() * 2, kEmpty);
    old.swap(table_);
    for (const std::uint32_t s : old)
      if (s != kEmpty) table_[find(slots_[s].v.p)] = s;
  }
  std::uint32_t make(const Point<2>& p) {
    if (free_ != kEmpty) {
      const std::uint32_t s = free_;
      Slot& x = slots_[s];
      free_ = x.next_free;
      x.v.p = p;
      x.refs = 0;
      x.free = false;
      return s;
    }
    const auto s = static_cast<std::uint32_t>(slots_.size());
    slots_.emplace_back(p, s);
    return s;
  }
  // A CellVertex is the first member of its Slot (standard layout), so its address is the
  // slot's; the slot names its own index, through which the pool hands it out writable.
  Slot& slot_of(const CellVertex* v) noexcept { return slots_[reinterpret_cast<const Slot*>(v)->self]; }

  std::deque<Slot> slots_;           // stable addresses
  std::vector<std::uint32_t> table_;  // slot indices by point, open addressing
  std::vector<std::uint32_t> idle_;   // released to no references since the last collect()
  std::uint32_t free_ = kEmpty;       // freed slots, linked by next_free
  std::size_t live_ = 0;
};

/// A reference to the Steiner vertex at a point, held by the trace: a keyed allocation
/// (by the point), so a re-execution inside its window gets the same reference back, and
/// one elsewhere makes another reference to the same vertex.
struct SteinerRef {
  SteinerRef(SteinerVertices* pool, const Point<2>& p) : pool_(pool), v(pool->acquire(p)) {}
  SteinerRef(const SteinerRef&) = delete;
  SteinerRef& operator=(const SteinerRef&) = delete;
  ~SteinerRef() { pool_->release(v); }

 private:
  SteinerVertices* pool_;

 public:
  const CellVertex* v;
};

}  // namespace dynmesh::detail
