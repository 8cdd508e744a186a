// block_feed.hpp (private) — a mesh held as blocks of simplices, one keyless trace allocation
// per block, and the change feed their lives give.
//
// Purpose: the quadtree mesh (2D) and the octree mesh (3D) make each unit of their output (a
// leaf's triangles; a split cell's leaf children's tetrahedra) as one FeedBlock, a keyless
// allocation of the running program holding only the shape the simplices are computed from.
// Its constructor and destructor tell the BlockFeed: what a propagation creates and undoes
// is exactly the change of the mesh. A Shape names its Grid and Simplex and has a free
// function emit_simplices(const Grid&, const Shape&, std::vector<Simplex>&) found by ADL.
// Invariants: the live blocks are exactly the blocks of the current trace; a block made and
// undone within one update leaves no trace in the feed; take_change() gives sorted, disjoint
// removed and added lists (a block re-made with an equal shape is no change).
// Complexity: O(1) per block made or undone; take_change O(k log k) for k simplices changed.
// Paper: Acar & Hudson, Section 4 (the output's change is what propagation re-runs).
#pragma once

#include <algorithm>
#include <cstddef>
#include <iterator>
#include <vector>

namespace dynmesh::detail {

template <class Shape>
struct FeedBlock;

template <class Shape>
struct BlockFeed {
  using Grid = typename Shape::Grid;
  using Simplex = typename Shape::Simplex;

  explicit BlockFeed(const Grid& g) : grid(g) {}
  Grid grid;
  FeedBlock<Shape>* live = nullptr;         // every live block, doubly linked
  std::vector<FeedBlock<Shape>*> created;   // blocks made in this update (null once undone)
  std::vector<Simplex> removed;             // simplices of the blocks undone in this update
  std::size_t live_count = 0;
  bool closing = false;                     // the engine is being destroyed: log nothing

  /// Forgets what the run so far made (after the build: its blocks are the mesh, no change).
  void settle() {
    for (FeedBlock<Shape>* b : created)
      if (b) b->slot = FeedBlock<Shape>::kOld;
    created.clear();
    removed.clear();
  }

  /// The change of the update just propagated: the simplices of the blocks it undid, less
  /// those of the blocks it made. `Change` has sorted vectors `removed` and `added`.
  template <class Change>
  void take_change(Change& change) {
    std::vector<Simplex> added;
    for (FeedBlock<Shape>* b : created) {
      if (!b) continue;
      emit_simplices(grid, b->shape, added);
      b->slot = FeedBlock<Shape>::kOld;
    }
    created.clear();
    std::vector<Simplex> gone = std::move(removed);
    removed.clear();
    std::sort(added.begin(), added.end());
    std::sort(gone.begin(), gone.end());
    change.removed.clear();
    change.added.clear();
    std::set_difference(gone.begin(), gone.end(), added.begin(), added.end(), std::back_inserter(change.removed));
    std::set_difference(added.begin(), added.end(), gone.begin(), gone.end(), std::back_inserter(change.added));
  }

  /// Every live simplex, sorted.
  std::vector<Simplex> simplices() const {
    std::vector<Simplex> out;
    for (const FeedBlock<Shape>* b = live; b; b = b->next) emit_simplices(grid, b->shape, out);
    std::sort(out.begin(), out.end());
    return out;
  }
  std::size_t num_simplices() const {
    std::size_t k = 0;
    std::vector<Simplex> scratch;
    for (const FeedBlock<Shape>* b = live; b; b = b->next) {
      scratch.clear();
      emit_simplices(grid, b->shape, scratch);
      k += scratch.size();
    }
    return k;
  }
};

template <class Shape>
struct FeedBlock {
  FeedBlock(BlockFeed<Shape>* l, const Shape& s) : log(l), shape(s) {
    next = log->live;
    if (next) next->prev = this;
    log->live = this;
    ++log->live_count;
    slot = log->created.size();
    log->created.push_back(this);
  }
  ~FeedBlock() {
    if (log->closing) return;
    if (prev) prev->next = next;
    else log->live = next;
    if (next) next->prev = prev;
    --log->live_count;
    if (slot != kOld) log->created[slot] = nullptr;  // made and undone in one update
    else emit_simplices(log->grid, shape, log->removed);
  }
  FeedBlock(const FeedBlock&) = delete;
  FeedBlock& operator=(const FeedBlock&) = delete;

  static constexpr std::size_t kOld = ~std::size_t{0};
  BlockFeed<Shape>* log;
  Shape shape;
  FeedBlock* prev = nullptr;
  FeedBlock* next = nullptr;
  std::size_t slot;  // index in log->created, or kOld
};

}  // namespace dynmesh::detail
