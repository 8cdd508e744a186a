// hpu_mesh_feed.hpp (private) — the self-adjusting hpu mesh's output: its live triangles in
// blocks, and the change feed.
//
// Purpose: the program (hpu_cells_program.hpp) emits the final mesh vertex by vertex: the
// triangles whose (x, y)-smallest corner is one vertex form one block, a keyless allocation
// of the step that found them (none when there are none). Change propagation destroys the
// blocks of the steps it re-runs or discards and makes new ones, so the feed falls out of
// the trace: each block's birth logs +1 per triangle and its destruction −1, and the net
// count of a triangle over an update is its change (a block re-made unchanged nets 0).
// A block holds its vertex and, per triangle, the other two corners' vertices, inline: 16
// bytes a triangle where its points would take 48, and no allocation of its own. The
// vertices outlive it: a vertex leaves the mesh only when the cells that held it change,
// which re-runs the steps that read them and so destroys their blocks in the same
// propagation, and its object is freed only after that propagation (HpuCellsState::release).
// Invariants (check_invariants): every live block is on the live list once; the live count
// is the sum of the live blocks' sizes; a block's corners are (x, y)-greater than its vertex
// (it is their canonical first corner); after an update every triangle nets −1, 0 or +1.
// Complexity: O(t) per block made or destroyed; take_change O(e log e) for e logged.
// Paper: Acar & Hudson, Section 4 (the output as the trace's allocations).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <sac/engine.hpp>

#include "dynmesh/errors.hpp"
#include "dynmesh/mesh.hpp"
#include "hpu/cell_store.hpp"

namespace dynmesh::detail {

class HpuMeshFeed;

/// A block's other two corners of one triangle: (vertex, b, c) counter-clockwise.
using HpuCorners = std::array<const CellVertex*, 2>;

/// What every block starts with; its triangles follow it (HpuTriBlockOf<K>).
struct HpuTriBlockHead {
  HpuMeshFeed* feed;
  const CellVertex* vertex;  // every triangle's first corner
  HpuTriBlockHead* prev;
  HpuTriBlockHead* next;
  std::uint32_t n;  // triangles
  std::span<const HpuCorners> corners() const noexcept;
  Triangle triangle(std::size_t i) const noexcept {
    const HpuCorners& c = corners()[i];
    return Triangle{{vertex->p, c[0]->p, c[1]->p}};
  }
};

/// A block of up to K triangles. Made with Engine::make, so its lifetime is the step's.
template <std::size_t K>
struct HpuTriBlockOf {
  HpuTriBlockOf(HpuMeshFeed* feed, const CellVertex* v, std::span<const HpuCorners> tris);
  ~HpuTriBlockOf();
  HpuTriBlockOf(const HpuTriBlockOf&) = delete;
  HpuTriBlockOf& operator=(const HpuTriBlockOf&) = delete;
  HpuTriBlockHead head;
  std::array<HpuCorners, K> tris;
};

inline std::span<const HpuCorners> HpuTriBlockHead::corners() const noexcept {
  // Every HpuTriBlockOf<K> is standard layout with its array at the same offset.
  const char* base = reinterpret_cast<const char*>(this) + offsetof(HpuTriBlockOf<1>, tris);
  return {reinterpret_cast<const HpuCorners*>(base), n};
}

/// The block capacities: at most a third more room than triangles.
inline constexpr std::size_t kBlockClasses[] = {1, 2, 3, 4, 6, 8, 12, 16};

class HpuMeshFeed {
 public:
  HpuMeshFeed() = default;
  HpuMeshFeed(const HpuMeshFeed&) = delete;
  HpuMeshFeed& operator=(const HpuMeshFeed&) = delete;

  /// Makes the blocks of vertex v's triangles (v, b, c), in the running step (blocks of up to
  /// the largest class; a vertex has fewer in a quality mesh).
  void make(sac::Engine& rt, const CellVertex* v, std::span<const HpuCorners> tris) {
    constexpr std::size_t kMost = kBlockClasses[std::size(kBlockClasses) - 1];
    while (!tris.empty()) {
      const std::span<const HpuCorners> part = tris.first(std::min(tris.size(), kMost));
      make_of(rt, v, part);
      tris = tris.subspan(part.size());
    }
  }

  /// The live triangles, canonical and sorted. O(t log t).
  std::vector<Triangle> triangles() const {
    std::vector<Triangle> out;
    out.reserve(live_);
    for (const HpuTriBlockHead* b = head_; b; b = b->next)
      for (std::size_t i = 0; i < b->n; ++i) out.push_back(b->triangle(i));
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
    for (const HpuTriBlockHead* b = head_; b; b = b->next) {
      if (b->next && b->next->prev != b) throw InvariantError("dynmesh: HpuMeshFeed: a broken live list");
      for (const HpuCorners& c : b->corners())
        if (!xy_less(b->vertex->p, c[0]->p) || !xy_less(b->vertex->p, c[1]->p))
          throw InvariantError("dynmesh: HpuMeshFeed: a block's triangle does not start at its vertex");
      n += b->n;
      ++k;
    }
    if (n != live_ || k != blocks_)
      throw InvariantError("dynmesh: HpuMeshFeed: the live count is " + std::to_string(live_) + ", the blocks hold " +
                           std::to_string(n));
  }

 private:
  template <std::size_t K>
  friend struct HpuTriBlockOf;

  template <std::size_t I = 0>
  void make_of(sac::Engine& rt, const CellVertex* v, std::span<const HpuCorners> tris) {
    constexpr std::size_t K = kBlockClasses[I];
    if constexpr (I + 1 < std::size(kBlockClasses)) {
      if (tris.size() > K) return make_of<I + 1>(rt, v, tris);
    }
    static_assert(std::is_standard_layout_v<HpuTriBlockOf<K>>);
    static_assert(offsetof(HpuTriBlockOf<K>, tris) == offsetof(HpuTriBlockOf<1>, tris));
    rt.make<HpuTriBlockOf<K>>(this, v, tris);
  }

  void born(HpuTriBlockHead* b) {
    // Room for the log first: a block is linked only once nothing can throw.
    if (logging_) events_.reserve(events_.size() + b->n);
    b->next = head_;
    if (head_) head_->prev = b;
    head_ = b;
    live_ += b->n;
    ++blocks_;
    if (!logging_) return;
    for (std::size_t i = 0; i < b->n; ++i) events_.emplace_back(b->triangle(i), +1);
  }
  void died(HpuTriBlockHead* b) noexcept {
    if (b->prev) b->prev->next = b->next;
    else head_ = b->next;
    if (b->next) b->next->prev = b->prev;
    live_ -= b->n;
    --blocks_;
    if (closing_ || !logging_) return;
    try {
      for (std::size_t i = 0; i < b->n; ++i) events_.emplace_back(b->triangle(i), -1);
    } catch (...) {
      // Out of memory while logging (a destructor must not throw): this update's feed
      // loses these removals; the live list, and so triangles(), stays right.
    }
  }

  HpuTriBlockHead* head_ = nullptr;
  std::size_t live_ = 0, blocks_ = 0;
  bool closing_ = false;
  bool logging_ = true;
  std::vector<std::pair<Triangle, int>> events_;
};

template <std::size_t K>
HpuTriBlockOf<K>::HpuTriBlockOf(HpuMeshFeed* feed, const CellVertex* v, std::span<const HpuCorners> t)
    : head{feed, v, nullptr, nullptr, static_cast<std::uint32_t>(t.size())} {
  std::copy(t.begin(), t.end(), tris.begin());
  feed->born(&head);
}
template <std::size_t K>
HpuTriBlockOf<K>::~HpuTriBlockOf() {
  head.feed->died(&head);
}

inline Mesh HpuMeshFeed::mesh() const {
  const auto same = [](const Point<2>& a, const Point<2>& b) { return !xy_less(a, b) && !xy_less(b, a); };
  Mesh out;
  std::vector<const HpuTriBlockHead*> blocks;
  blocks.reserve(blocks_);
  {
    std::vector<Point<2>> corners;
    corners.reserve(2 * live_ + blocks_);
    for (const HpuTriBlockHead* b = head_; b; b = b->next) {
      if (b->n == 0) continue;
      blocks.push_back(b);
      corners.push_back(b->vertex->p);
      for (const HpuCorners& c : b->corners()) {
        corners.push_back(c[0]->p);
        corners.push_back(c[1]->p);
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
  std::sort(blocks.begin(), blocks.end(), [](const HpuTriBlockHead* a, const HpuTriBlockHead* b) {
    return xy_less(a->vertex->p, b->vertex->p);
  });
  out.triangles.reserve(live_);
  std::uint32_t last = 0;
  for (const HpuTriBlockHead* b : blocks) {
    // Blocks in order of their vertices, so the first corner's index only grows (a vertex
    // split over two blocks comes twice).
    const Point<2>& p = b->vertex->p;
    const std::uint32_t i0 = xy_less(p, v[last]) ? find_from(0, p) : find_from(last, p);
    last = i0;
    for (const HpuCorners& c : b->corners()) {
      if (!xy_less(p, c[0]->p) || !xy_less(p, c[1]->p))
        throw InvariantError("dynmesh: HpuMeshFeed: a triangle that is not canonical");
      out.triangles.push_back({i0, find_from(i0, c[0]->p), find_from(i0, c[1]->p)});
    }
  }
  std::sort(out.triangles.begin(), out.triangles.end());
  return out;
}

}  // namespace dynmesh::detail
