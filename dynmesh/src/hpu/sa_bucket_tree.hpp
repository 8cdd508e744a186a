// sa_bucket_tree.hpp (private) — BucketTree (bucket_tree.hpp) as state on sac-runtime: the
// store of the cell-based self-adjusting hpu program (docs/HPU_ON_CELLS.md, stage 2).
//
// Purpose: each node of the point-region quadtree is a modifiable whose versions are its
// states over time (a leaf's vertices, or "split" with its four children), and inserting a
// vertex is a step of the computation: it reads the states down to the leaf that holds the
// vertex's position at that time and writes the leaf's next state (splitting it when it
// overflows). A later step that reads a node sees the vertices inserted before it, and
// change propagation keeps that true: undoing an insertion undoes its writes, and the steps
// that read what it wrote run again.
// Invariants: after run() and after every propagate(), the newest states form the
// BucketTree of the vertices inserted (a function of that set, whatever the order:
// tests/dynmesh/sa_bucket_tree_test.cpp compares them after every update); a split node's
// children are allocated by its split, keyed by the cell, and written before the parent's
// split state (so no read sees a child that has no version).
// Complexity: an insertion O(depth) reads and O(1) writes (O(depth) when one point forces
// a chain of splits); an update re-runs the insertions whose reads it changed.
// Paper: Acar & Hudson, Section 4 (dynamizing by change propagation); Acar, Ahmed & Blume
// (2008) for keyed allocation.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <tuple>
#include <vector>

#include <sac/engine.hpp>
#include <sac/fn.hpp>
#include <sac/mod.hpp>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"
#include "hpu/bucket_tree.hpp"

namespace dynmesh::detail {

struct SaBucketChildren;

/// A node's value at a time: a leaf's vertices (at most kCapacity) or "split".
struct SaBucketState {
  static constexpr std::uint8_t kSplit = 0xff;
  std::uint8_t count = 0;  // a leaf's vertices, or kSplit
  std::array<std::uint32_t, BucketTree::kCapacity> items{};
  SaBucketChildren* children = nullptr;  // when split
  friend bool operator==(const SaBucketState&, const SaBucketState&) = default;
};

struct SaBucketNode {
  SaBucketNode() = default;
  SaBucketNode(const SaBucketNode&) = delete;
  SaBucketNode& operator=(const SaBucketNode&) = delete;
  sac::Mod<SaBucketState> state;
};

struct SaBucketChildren {
  std::array<SaBucketNode, 4> node;
};

class SaBucketTree {
 public:
  /// No split below this level: more than kCapacity vertices in a finest cell throw (the
  /// mesh's resolution rules keep vertices farther apart).
  static constexpr int kMaxSplitLevel = BucketTree::kMaxLevel;

  /// The mutator's part: the box and the vertices' coordinates by id (pts must outlive the
  /// tree and hold every id ever inserted). Sets the root's state, an empty leaf.
  SaBucketTree(sac::Engine& e, const Box<2>& box, std::span<const Point<2>> pts) : grid_(box), pts_(pts) {
    e.set(root_.state, SaBucketState{});
  }
  SaBucketTree(const SaBucketTree&) = delete;
  SaBucketTree& operator=(const SaBucketTree&) = delete;

  /// Inside a computation: inserts vertex v at the current time.
  static void insert(sac::Engine& e, SaBucketTree* t, std::uint32_t v) {
    e.read(t->root_.state, sac::fn<&step>(t, &t->root_, v, 0, std::uint64_t{0}, std::uint64_t{0}));
  }

  /// The mutator's view: the leaves of the newest states, in (level, x, y) order.
  std::vector<BucketLeaf> leaves() const {
    std::vector<BucketLeaf> out;
    collect(root_, 0, 0, 0, out);
    std::sort(out.begin(), out.end(), [](const BucketLeaf& a, const BucketLeaf& b) {
      if (a.level != b.level) return a.level < b.level;
      return a.ix != b.ix ? a.ix < b.ix : a.iy < b.iy;
    });
    return out;
  }

 private:
  static unsigned quadrant(const std::array<std::uint64_t, 2>& q, int level) noexcept {
    const int s = BucketTree::kMaxLevel - 1 - level;
    return static_cast<unsigned>(((q[0] >> s) & 1) | (((q[1] >> s) & 1) << 1));
  }

  /// One level of an insertion: n's state at this time is s.
  static void step(sac::Engine& e, const SaBucketState& s, SaBucketTree* t, SaBucketNode* n, std::uint32_t v,
                   int level, std::uint64_t ix, std::uint64_t iy) {
    const auto q = t->grid_.position(t->pts_[v]);
    if (s.count == SaBucketState::kSplit) {
      const unsigned k = quadrant(q, level);
      SaBucketNode* c = &s.children->node[k];
      e.read(c->state, sac::fn<&step>(t, c, v, level + 1, 2 * ix + (k & 1), 2 * iy + (k >> 1)));
      return;
    }
    std::vector<std::uint32_t> items(s.items.begin(), s.items.begin() + s.count);
    items.push_back(v);
    place(e, t, n, items, level, ix, iy);
  }

  /// Writes n's state holding `items` (n's cell), splitting while they overflow.
  static void place(sac::Engine& e, SaBucketTree* t, SaBucketNode* n, const std::vector<std::uint32_t>& items,
                    int level, std::uint64_t ix, std::uint64_t iy) {
    if (items.size() <= BucketTree::kCapacity) {
      SaBucketState s;
      s.count = static_cast<std::uint8_t>(items.size());
      std::copy(items.begin(), items.end(), s.items.begin());
      e.write(n->state, s);
      return;
    }
    if (level >= kMaxSplitLevel) throw InvariantError("dynmesh: SaBucketTree: vertices closer than the finest cell");
    auto* ch = e.alloc<SaBucketChildren>(std::tuple{static_cast<const SaBucketTree*>(t), level, ix, iy});
    std::array<std::vector<std::uint32_t>, 4> part;
    for (const std::uint32_t w : items) part[quadrant(t->grid_.position(t->pts_[w]), level)].push_back(w);
    for (unsigned k = 0; k < 4; ++k)
      place(e, t, &ch->node[k], part[k], level + 1, 2 * ix + (k & 1), 2 * iy + (k >> 1));
    SaBucketState s;
    s.count = SaBucketState::kSplit;
    s.children = ch;
    e.write(n->state, s);
  }

  static void collect(const SaBucketNode& n, int level, std::uint64_t ix, std::uint64_t iy,
                      std::vector<BucketLeaf>& out) {
    const SaBucketState& s = n.state.get();
    if (s.count == SaBucketState::kSplit) {
      for (unsigned k = 0; k < 4; ++k)
        collect(s.children->node[k], level + 1, 2 * ix + (k & 1), 2 * iy + (k >> 1), out);
      return;
    }
    if (s.count == 0) return;
    BucketLeaf leaf{level, ix, iy, std::vector<std::uint32_t>(s.items.begin(), s.items.begin() + s.count)};
    std::sort(leaf.items.begin(), leaf.items.end());
    out.push_back(std::move(leaf));
  }

  BucketTree grid_;  // only its position() (point location) is used
  std::span<const Point<2>> pts_;
  SaBucketNode root_;
};

}  // namespace dynmesh::detail
