// block_feed.hpp (private) — a mesh held as blocks of simplices, one keyless trace allocation
// per block, and the change feed their lives give.
//
// Purpose: the quadtree mesh (2D) and the octree mesh (3D) make each unit of their output (a
// leaf's triangles; a split cell's leaf children's tetrahedra) as one FeedBlock, a keyless
// allocation of the running program holding only the shape the simplices are computed from.
// Its constructor and destructor tell the BlockFeed: what a propagation creates and undoes
// is exactly the change of the mesh. A Shape names its Grid and Simplex, is equality
// comparable, has key() (the cell it is made for: a re-made block has the same key) and free
// functions found by ADL: emit_simplices(const Grid&, const Shape&, std::vector<Simplex>&),
// and emit_difference(grid, before, after, removed, added), which appends at least the
// simplices of `before` not in `after` to `removed` and those of `after` not in `before` to
// `added` (a shape may append everything; take_change subtracts the common ones).
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
  std::vector<Shape> removed;               // shapes of the blocks undone in this update
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
  /// those of the blocks it made. `Change` has sorted vectors `removed` and `added`. A block
  /// re-made for the same cell is compared with its old shape first: an equal shape is no
  /// change, and a different one emits only what its shape says may differ.
  template <class Change>
  void take_change(Change& change) {
    std::vector<Shape> made;
    for (FeedBlock<Shape>* b : created) {
      if (!b) continue;
      made.push_back(b->shape);
      b->slot = FeedBlock<Shape>::kOld;
    }
    created.clear();
    std::vector<Shape> gone = std::move(removed);
    removed.clear();
    const auto by_key = [](const Shape& a, const Shape& b) { return a.key() < b.key(); };
    std::sort(made.begin(), made.end(), by_key);
    std::sort(gone.begin(), gone.end(), by_key);
    std::vector<Simplex> minus, plus;
    std::size_t i = 0, j = 0;
    while (i < gone.size() || j < made.size()) {
      if (j == made.size() || (i < gone.size() && gone[i].key() < made[j].key())) {
        emit_simplices(grid, gone[i++], minus);
      } else if (i == gone.size() || made[j].key() < gone[i].key()) {
        emit_simplices(grid, made[j++], plus);
      } else {
        if (!(gone[i] == made[j])) emit_difference(grid, gone[i], made[j], minus, plus);
        ++i, ++j;
      }
    }
    std::sort(minus.begin(), minus.end());
    std::sort(plus.begin(), plus.end());
    change.removed.clear();
    change.added.clear();
    std::set_difference(minus.begin(), minus.end(), plus.begin(), plus.end(), std::back_inserter(change.removed));
    std::set_difference(plus.begin(), plus.end(), minus.begin(), minus.end(), std::back_inserter(change.added));
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
    else log->removed.push_back(shape);
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
