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
  /// The canonical mesh of the live triangles, the same as make_mesh(triangles()) without
  /// its copies: the corners of each block once (its triangles share their first corner, the
  /// vertex whose step made it), sorted into the vertices, then each block in the vertices'
  /// order, its corners found by a galloping search forward from its first (a triangle's other
  /// corners follow its first in (x, y) order). About 40 bytes a triangle besides the mesh,
  /// against about 130. O(t log t).
  Mesh mesh() const;
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
  /// Off: blocks made or destroyed log nothing (the change is not kept; the live list is).
  /// For a from-scratch run, whose change nobody asks: its log would be a triangle's 56
  /// bytes for every triangle of the mesh, at the peak of the build.
  void set_logging(bool on) noexcept { logging_ = on; }
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
    if (!logging_) return;
    for (const Triangle& t : b->tris_) events_.emplace_back(t, +1);
  }
  void died(HpuTriBlock* b) noexcept {
    if (b->prev_) b->prev_->next_ = b->next_;
    else head_ = b->next_;
    if (b->next_) b->next_->prev_ = b->prev_;
    live_ -= b->tris_.size();
    --blocks_;
    if (closing_ || !logging_) return;
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
  bool logging_ = true;
  std::vector<std::pair<Triangle, int>> events_;
};

inline Mesh HpuMeshFeed::mesh() const {
  const auto same = [](const Point<2>& a, const Point<2>& b) { return !xy_less(a, b) && !xy_less(b, a); };
  Mesh out;
  std::vector<const HpuTriBlock*> blocks;
  blocks.reserve(blocks_);
  {
    std::vector<Point<2>> corners;
    corners.reserve(2 * live_ + blocks_);
    for (const HpuTriBlock* b = head_; b; b = b->next_) {
      if (b->tris_.empty()) continue;
      blocks.push_back(b);
      const Point<2>* first = nullptr;
      for (const Triangle& t : b->tris_) {
        if (!first || !same(*first, t.v[0])) corners.push_back(*(first = &t.v[0]));
        corners.push_back(t.v[1]);
        corners.push_back(t.v[2]);
      }
    }
    std::sort(corners.begin(), corners.end(), xy_less);
    corners.erase(std::unique(corners.begin(), corners.end(), same), corners.end());
    out.vertices.assign(corners.begin(), corners.end());
  }
  const std::vector<Point<2>>& v = out.vertices;
  // The index of p, at or after `from` (p is a vertex, not before v[from]): doubling steps,
  // then a binary search in the last one.
  const auto find_from = [&](std::size_t from, const Point<2>& p) {
    std::size_t lo = from, step = 1;
    while (lo + step < v.size() && xy_less(v[lo + step], p)) {
      lo += step;
      step *= 2;
    }
    const auto hi = v.begin() + static_cast<std::ptrdiff_t>(std::min(lo + step + 1, v.size()));
    const auto it = std::lower_bound(v.begin() + static_cast<std::ptrdiff_t>(lo), hi, p, xy_less);
    if (it == v.end() || !same(*it, p)) throw InvariantError("dynmesh: HpuMeshFeed: a corner is not a vertex");
    return static_cast<std::uint32_t>(it - v.begin());
  };
  std::sort(blocks.begin(), blocks.end(),
            [](const HpuTriBlock* a, const HpuTriBlock* b) { return xy_less(a->tris_[0].v[0], b->tris_[0].v[0]); });
  out.triangles.reserve(live_);
  std::uint32_t last = 0;
  for (const HpuTriBlock* b : blocks)
    for (const Triangle& t : b->tris_) {
      if (xy_less(t.v[1], t.v[0]) || xy_less(t.v[2], t.v[0]))
        throw InvariantError("dynmesh: HpuMeshFeed: a triangle that is not canonical");
      // Blocks in order of their first corners, so the first corner's index only grows.
      const std::uint32_t i0 = xy_less(t.v[0], v[last]) ? find_from(0, t.v[0]) : find_from(last, t.v[0]);
      last = i0;
      out.triangles.push_back({i0, find_from(i0, t.v[1]), find_from(i0, t.v[2])});
    }
  std::sort(out.triangles.begin(), out.triangles.end());
  return out;
}

inline HpuTriBlock::HpuTriBlock(HpuMeshFeed* feed, std::span<const Triangle> tris)
    : feed_(feed), tris_(tris.begin(), tris.end(), &feed->pool_) {
  feed_->born(this);
}
inline HpuTriBlock::~HpuTriBlock() { feed_->died(this); }

}  // namespace dynmesh::detail
