// hpu_mesh_feed.hpp (private) — the self-adjusting hpu mesh's output: its live triangles in
// blocks, and the change feed.
//
// Purpose: the program (hpu_cells_program.hpp) emits the final mesh vertex by vertex: the
// triangles whose (x, y)-smallest corner is one vertex form one block, a keyless allocation
// of the step that found them (none when there are none). Change propagation destroys the
// blocks of the steps it re-runs or discards and makes new ones, so the feed falls out of
// the trace: each block's birth logs +1 per triangle and its destruction −1, and the net
// count of a triangle over an update is its change (a block re-made unchanged nets 0).
// Invariants (check_invariants): every live block is on the live list once; the live count
// is the sum of the live blocks' sizes; after an update every triangle nets −1, 0 or +1.
// Complexity: O(t) per block made or destroyed; take_change O(e log e) for e logged. A
// block's triangles come from the feed's pool (std::pmr::unsynchronized_pool_resource), not
// from a heap allocation per block.
// Paper: Acar & Hudson, Section 4 (the output as the trace's allocations).
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory_resource>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "dynmesh/errors.hpp"
#include "dynmesh/mesh.hpp"

namespace dynmesh::detail {

class HpuMeshFeed;

/// One leaf's triangles (canonical). Made with Engine::make, so its lifetime is the step's.
class HpuTriBlock {
 public:
  HpuTriBlock(HpuMeshFeed* feed, std::span<const Triangle> tris);
  ~HpuTriBlock();
  HpuTriBlock(const HpuTriBlock&) = delete;
  HpuTriBlock& operator=(const HpuTriBlock&) = delete;
  std::span<const Triangle> triangles() const noexcept { return tris_; }

 private:
  friend class HpuMeshFeed;
  HpuMeshFeed* feed_;
  std::pmr::vector<Triangle> tris_;  // from the feed's pool
  HpuTriBlock* prev_ = nullptr;
  HpuTriBlock* next_ = nullptr;
};

class HpuMeshFeed {
 public:
  HpuMeshFeed() = default;
  HpuMeshFeed(const HpuMeshFeed&) = delete;
  HpuMeshFeed& operator=(const HpuMeshFeed&) = delete;

  /// The live triangles, canonical and sorted. O(t log t).
  std::vector<Triangle> triangles() const {
    std::vector<Triangle> out;
    out.reserve(live_);
    for (const HpuTriBlock* b = head_; b; b = b->next_) out.insert(out.end(), b->tris_.begin(), b->tris_.end());
    std::sort(out.begin(), out.end());
    return out;
  }
  std::size_t live_count() const noexcept { return live_; }
  /// Bytes held by the live blocks outside the trace records (their triangle arrays).
  std::size_t bytes() const noexcept { return live_ * sizeof(Triangle); }

  /// The change since the last call: removed and added triangles, each sorted.
  MeshChange take_change() {
    std::sort(events_.begin(), events_.end());
    MeshChange out;
    for (std::size_t i = 0; i < events_.size();) {
      std::size_t j = i;
      int net = 0;
      for (; j < events_.size() && events_[j].first == events_[i].first; ++j) net += events_[j].second;
      if (net > 1 || net < -1) throw InvariantError("dynmesh: HpuMeshFeed: a triangle made or removed twice");
      if (net > 0) out.added.push_back(events_[i].first);
      else if (net < 0) out.removed.push_back(events_[i].first);
      i = j;
    }
    events_.clear();
    return out;
  }
  void clear_change() noexcept { events_.clear(); }
  /// For the checker's negative test only: one live triangle too many.
  void corrupt_live_count_for_testing() noexcept { ++live_; }
  /// Call before the engine is destroyed: the blocks it destroys then log nothing.
  void close() noexcept { closing_ = true; }

  /// Throws InvariantError naming the first broken rule (see the header).
  void check_invariants() const {
    std::size_t n = 0, k = 0;
    for (const HpuTriBlock* b = head_; b; b = b->next_) {
      if (b->next_ && b->next_->prev_ != b) throw InvariantError("dynmesh: HpuMeshFeed: a broken live list");
      n += b->tris_.size();
      ++k;
    }
    if (n != live_ || k != blocks_)
      throw InvariantError("dynmesh: HpuMeshFeed: the live count is " + std::to_string(live_) + ", the blocks hold " +
                           std::to_string(n));
  }

 private:
  friend class HpuTriBlock;
  void born(HpuTriBlock* b) {
    b->next_ = head_;
    if (head_) head_->prev_ = b;
    head_ = b;
    live_ += b->tris_.size();
    ++blocks_;
    for (const Triangle& t : b->tris_) events_.emplace_back(t, +1);
  }
  void died(HpuTriBlock* b) noexcept {
    if (b->prev_) b->prev_->next_ = b->next_;
    else head_ = b->next_;
    if (b->next_) b->next_->prev_ = b->prev_;
    live_ -= b->tris_.size();
    --blocks_;
    if (closing_) return;
    try {
      for (const Triangle& t : b->tris_) events_.emplace_back(t, -1);
    } catch (...) {
      // Out of memory while logging (a destructor must not throw): this update's feed
      // loses these removals; the live list, and so triangles(), stays right.
    }
  }

  // The live blocks' triangle arrays come from it: the blocks die with the engine's trace,
  // so the feed must outlive the engine (its owner declares it, in HpuCellsState, before
  // the engine).
  std::pmr::unsynchronized_pool_resource pool_;
  HpuTriBlock* head_ = nullptr;
  std::size_t live_ = 0, blocks_ = 0;
  bool closing_ = false;
  std::vector<std::pair<Triangle, int>> events_;
};

inline HpuTriBlock::HpuTriBlock(HpuMeshFeed* feed, std::span<const Triangle> tris)
    : feed_(feed), tris_(tris.begin(), tris.end(), &feed->pool_) {
  feed_->born(this);
}
inline HpuTriBlock::~HpuTriBlock() { feed_->died(this); }

}  // namespace dynmesh::detail
