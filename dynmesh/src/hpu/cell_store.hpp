// cell_store.hpp (private) — the vertices of the self-adjusting hpu mesh by cell, as
// modifiables: the store its questions read (cell_view.hpp) and its insertions write.
//
// Purpose: the bucket tree of bucket_tree.hpp (a point-region quadtree of the box's dyadic
// cells, at most kCapacity vertices per leaf) with one modifiable per cell, named by its
// (level, x, y) in a directory outside the trace. A cell's value at a time is its state then:
// absent (an ancestor is a leaf), a leaf with its vertices, or split. Two parts write it:
//   - the mutator (InputCells) sets the base values: the bucket tree of the run's first
//     vertices (the box's corners, the inputs and their side midpoints), which is a function
//     of that set. An edit changes the base values of O(1) cells (the leaf that gains or
//     loses the point, and the cells a split or a merge makes or drops);
//   - the computation inserts each Steiner vertex at its time (cell_view.hpp's insertion
//     step): it reads the leaf that holds the vertex then and writes that leaf's next value,
//     or splits it (the children first, then the parent), so every later question sees it.
// A leaf's vertices are sorted by (x, y), so a value is a function of the cell's vertex set
// and an equal set is a cut-off write.
//
// Invariants (InputCells::check_invariants, which runs CellDirectory's): a node's parent
// and child links are the directory's lookups of those keys; one CellView at a time keeps
// its marks on the nodes (claim_marks); the base values form the bucket tree of the first
// vertices (every vertex in the leaf whose cell holds its exact grid position, a leaf over
// capacity only at the finest level, a split cell over capacity in its subtree); the newest
// values after a run form the bucket tree of all vertices (the tests compare them with
// BucketTree). A directory entry is never removed while the engine lives.
// Complexity: InputCells::insert/erase O(depth + kCapacity) plus O(kCapacity) base values
// set; a directory lookup O(1) expected.
// Paper: Acar & Hudson, Section 4 (modifiables, and the mutator's changes); Har-Peled &
// Üngör (2005) for answering the refinement's questions from a quadtree's cells.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <limits>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include <sac/engine.hpp>
#include <sac/mod.hpp>
#include <sac/splitmix64.hpp>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"
#include "hpu/bucket_tree.hpp"
#include "hpu/hpu_geometry.hpp"

namespace dynmesh::detail {

/// A mesh vertex: its coordinates, never changed. The mutator owns the first vertices; a
/// Steiner vertex is a keyed allocation of the step that inserts it, keyed by its position.
struct CellVertex {
  explicit CellVertex(const Point<2>& x) : p(x) {}
  CellVertex(const CellVertex&) = delete;
  CellVertex& operator=(const CellVertex&) = delete;
  Point<2> p;
};

/// A cell's value at a time. The default (T{}) is "absent".
struct CellState {
  static constexpr std::size_t kCapacity = BucketTree::kCapacity;
  enum Kind : std::uint8_t { Absent = 0, Leaf = 1, Split = 2 };
  Kind kind = Absent;
  std::uint8_t count = 0;  // a leaf's vertices
  std::array<const CellVertex*, kCapacity> items{};
  friend bool operator==(const CellState&, const CellState&) = default;

  /// A leaf of `vs` (at most kCapacity), sorted by (x, y).
  template <class It>
  static CellState leaf(It first, It last) {
    CellState s;
    s.kind = Leaf;
    for (; first != last; ++first) s.items[s.count++] = *first;
    std::sort(s.items.begin(), s.items.begin() + s.count,
              [](const CellVertex* a, const CellVertex* b) { return xy_less(a->p, b->p); });
    return s;
  }
  static CellState split() {
    CellState s;
    s.kind = Split;
    return s;
  }
};

/// A dyadic cell of the box: level ℓ, and x, y in [0, 2^ℓ).
struct CellKey {
  int level = 0;
  std::uint64_t ix = 0, iy = 0;
  friend bool operator==(const CellKey&, const CellKey&) = default;
  CellKey parent() const noexcept { return CellKey{level - 1, ix >> 1, iy >> 1}; }
  CellKey child(unsigned k) const noexcept { return CellKey{level + 1, 2 * ix + (k & 1), 2 * iy + (k >> 1)}; }
  /// Does this cell contain (or equal) c?
  bool contains(const CellKey& c) const noexcept {
    if (c.level < level) return false;
    const int s = c.level - level;
    return (c.ix >> s) == ix && (c.iy >> s) == iy;
  }
  /// A hash_combine of (level, ix, iy), not splitmix64: it only chooses buckets, and it is
  /// one multiply shorter than sac::mix64 because every cell lookup of a question pays it.
  std::uint64_t hash() const noexcept {
    std::uint64_t h = static_cast<std::uint64_t>(level) * sac::kGoldenGamma;
    h ^= ix + 0xbf58476d1ce4e5b9ULL + (h << 6) + (h >> 2);
    h ^= iy + 0x94d049bb133111ebULL + (h << 6) + (h >> 2);
    h ^= h >> 31;
    return h * 0xd6e8feb86659fd93ULL;
  }
};

struct CellKeyHash {
  std::size_t operator()(const CellKey& k) const noexcept { return static_cast<std::size_t>(k.hash()); }
};

/// What the running step's CellView knows of a cell (cell_view.hpp), kept on the cell's node
/// so that a search finds it without a lookup. Valid while gen is the view's generation.
enum class CellTag : std::uint8_t { Unknown, Leaf, Split, Absent };
struct CellMark {
  std::uint32_t gen = 0;
  CellTag tag = CellTag::Unknown;  // Unknown: not looked at; else its state now, read or peeked
  bool read = false;               // a round of the step read it (or read a cell below it)
  bool pending = false;            // a search used it unread
  bool all = false;                // the step used every vertex of it
  // The box whose vertices the step's searches used, when not all (x0 > x1: none).
  double bx0 = std::numeric_limits<double>::infinity(), by0 = std::numeric_limits<double>::infinity();
  double bx1 = -std::numeric_limits<double>::infinity(), by1 = -std::numeric_limits<double>::infinity();
  const CellState* state = nullptr;
};

/// One cell's modifiable, linked to its parent's and children's nodes when they exist.
struct CellNode {
  explicit CellNode(const CellKey& k) : key(k) {}
  CellNode(const CellNode&) = delete;
  CellNode& operator=(const CellNode&) = delete;
  CellKey key;
  sac::Mod<CellState> state;
  CellNode* parent = nullptr;          // find(key.parent())
  std::array<CellNode*, 4> child{};    // find(key.child(c)), null when never made
  CellMark mark;                       // the one CellView's scratch
};

/// The cells by key, outside the trace: each is made on first use, with the default value
/// (absent), and lives as long as the directory.
class CellDirectory {
 public:
  explicit CellDirectory(const Box<2>& box) : grid_(box), box_(box), table_(1024) {}
  CellDirectory(const CellDirectory&) = delete;
  CellDirectory& operator=(const CellDirectory&) = delete;

  /// The node whose state is m (a read's slot names its cell by its state).
  static CellNode* node_of(const sac::Mod<CellState>& m) noexcept {
    static_assert(std::is_standard_layout_v<CellNode>);
    return reinterpret_cast<CellNode*>(reinterpret_cast<std::uintptr_t>(&m) - offsetof(CellNode, state));
  }
  /// The cell's node, made (with the default value) if new. Mutator or computation.
  CellNode* node(sac::Engine& rt, const CellKey& k) {
    const std::uint64_t h = k.hash();
    Entry* x = &table_[probe(k, h)];
    if (x->node) return x->node;
    CellNode* n = &nodes_.emplace_back(k);
    rt.init_default(n->state);
    *x = Entry{h, n};
    if (2 * nodes_.size() > table_.size()) grow();
    if (k.level > 0)
      if (CellNode* p = find(k.parent())) {
        n->parent = p;
        p->child[child_index(k)] = n;
      }
    if (k.level < BucketTree::kMaxLevel)
      for (unsigned c = 0; c < 4; ++c)
        if (CellNode* ch = find(k.child(c))) {
          n->child[c] = ch;
          ch->parent = n;
        }
    return n;
  }
  /// Which child of its parent k is (CellKey::child's numbering).
  static unsigned child_index(const CellKey& k) noexcept {
    return static_cast<unsigned>((k.ix & 1) | ((k.iy & 1) << 1));
  }
  /// The nodes' marks belong to one CellView at a time, from its construction to its
  /// destruction: InvariantError for a second, whose marks would mix with the first's. A
  /// later view starts from clean marks (its generations count from the start again).
  void claim_marks(const void* view) {
    if (mark_owner_) throw InvariantError("dynmesh: CellDirectory: a second CellView on the same cells");
    if (marks_used_) clear_marks();
    mark_owner_ = view;
    marks_used_ = true;
  }
  void release_marks(const void* view) noexcept {
    if (mark_owner_ == view) mark_owner_ = nullptr;
  }
  /// Forgets every view mark (a view's generation counter wrapped).
  void clear_marks() {
    for (CellNode& n : nodes_) n.mark = CellMark{};
  }
  /// Throws InvariantError unless every node's links are the lookups they stand for, and
  /// every node below the root has its parent.
  void check_invariants() const {
    for (const CellNode& n : nodes_) {
      const CellKey& k = n.key;
      if (find(k) != &n) throw InvariantError("dynmesh: CellDirectory: a node its key does not find");
      if (k.level > 0 && (!n.parent || n.parent != find(k.parent())))
        throw InvariantError("dynmesh: CellDirectory: a node without its parent's link");
      for (unsigned c = 0; c < 4; ++c)
        if (n.child[c] != (k.level < BucketTree::kMaxLevel ? find(k.child(c)) : nullptr))
          throw InvariantError("dynmesh: CellDirectory: a child link that is not the child's node");
    }
  }
  /// The cell's node if it was ever made, else null. O(1) expected: the questions ask it for
  /// every cell they look at, so it is an open-addressing table whose entries carry the
  /// key's hash (a miss or a collision costs no visit to a node).
  CellNode* find(const CellKey& k) const { return table_[probe(k, k.hash())].node; }

  /// The exact grid position of x (bucket_tree.hpp's).
  std::array<std::uint64_t, 2> position(const Point<2>& x) const noexcept { return grid_.position(x); }
  /// The cell of level ℓ holding grid position q.
  static CellKey cell_at(const std::array<std::uint64_t, 2>& q, int level) noexcept {
    const int s = BucketTree::kMaxLevel - level;
    return CellKey{level, q[0] >> s, q[1] >> s};
  }
  /// The widening of cells against the rounding of point location (BucketTree's).
  double margin_for(const Point<2>& c, double r) const noexcept { return grid_.margin_for(c, r); }
  const Box<2>& box() const noexcept { return box_; }
  /// Bytes held outside the trace (nodes and the map).
  std::size_t bytes() const noexcept {
    return nodes_.size() * sizeof(CellNode) + table_.size() * sizeof(Entry);
  }

  /// The newest values' non-empty leaves (the bucket tree after the last run or
  /// propagation), in (level, x, y) order, each vertex given as index_of(v), sorted: the
  /// form of BucketTree::leaves(), for tests to compare.
  template <class IndexOf>
  std::vector<BucketLeaf> leaves(IndexOf index_of) const {
    std::vector<BucketLeaf> out;
    collect(CellKey{}, index_of, out);
    std::sort(out.begin(), out.end(), [](const BucketLeaf& a, const BucketLeaf& b) {
      if (a.level != b.level) return a.level < b.level;
      return a.ix != b.ix ? a.ix < b.ix : a.iy < b.iy;
    });
    return out;
  }

 private:
  template <class IndexOf>
  void collect(const CellKey& k, IndexOf& index_of, std::vector<BucketLeaf>& out) const {
    const CellNode* n = find(k);
    if (!n) return;
    const CellState& s = n->state.get();
    if (s.kind == CellState::Split) {
      for (unsigned c = 0; c < 4; ++c) collect(k.child(c), index_of, out);
      return;
    }
    if (s.kind != CellState::Leaf || s.count == 0) return;
    BucketLeaf leaf{k.level, k.ix, k.iy, {}};
    for (std::size_t i = 0; i < s.count; ++i) leaf.items.push_back(index_of(s.items[i]));
    std::sort(leaf.items.begin(), leaf.items.end());
    out.push_back(std::move(leaf));
  }

  struct Entry {
    std::uint64_t hash = 0;
    CellNode* node = nullptr;  // null: free (nodes are never removed)
  };

  /// The index of k's entry: its node's, or the free one where it would go (linear probing).
  std::size_t probe(const CellKey& k, std::uint64_t h) const {
    const std::size_t mask = table_.size() - 1;
    for (std::size_t i = h & mask;; i = (i + 1) & mask) {
      const Entry& x = table_[i];
      if (!x.node || (x.hash == h && x.node->key == k)) return i;
    }
  }
  void grow() {
    std::vector<Entry> old(table_.size() * 2);
    old.swap(table_);
    const std::size_t mask = table_.size() - 1;
    for (const Entry& x : old) {
      if (!x.node) continue;
      std::size_t i = x.hash & mask;
      while (table_[i].node) i = (i + 1) & mask;
      table_[i] = x;
    }
  }

  BucketTree grid_;  // only its position() and margin_for() are used
  Box<2> box_;
  std::vector<Entry> table_;  // a power of two, at most half full
  std::deque<CellNode> nodes_;
  const void* mark_owner_ = nullptr;  // the CellView whose marks the nodes hold
  bool marks_used_ = false;           // some view has held them
};

/// The mutator's part: the bucket tree of the first vertices, kept as the cells' base
/// values. insert/erase change the tree and set the base values that changed.
class InputCells {
 public:
  explicit InputCells(CellDirectory& dir) : dir_(&dir) {}
  InputCells(const InputCells&) = delete;
  InputCells& operator=(const InputCells&) = delete;

  /// Adds v (not present, and no other vertex at its position).
  void insert(sac::Engine& rt, const CellVertex* v) {
    const auto q = dir_->position(v->p);
    CellKey k{};
    for (;;) {
      Cell& c = cells_[k];
      ++c.count;
      if (!c.split) break;
      k = CellDirectory::cell_at(q, k.level + 1);
    }
    cells_[k].items.push_back(v);
    touched_.push_back(k);
    // Split while the leaf overflows (all of them may fall into one child).
    while (cells_[k].items.size() > CellState::kCapacity && k.level < BucketTree::kMaxLevel) {
      Cell& c = cells_[k];
      std::vector<const CellVertex*> items = std::move(c.items);
      c.items.clear();
      c.split = true;
      for (unsigned ch = 0; ch < 4; ++ch) {
        cells_[k.child(ch)];  // an empty leaf at least: a split cell has its four children
        touched_.push_back(k.child(ch));
      }
      for (const CellVertex* w : items) {
        Cell& d = cells_[CellDirectory::cell_at(dir_->position(w->p), k.level + 1)];
        d.items.push_back(w);
        ++d.count;
      }
      k = CellDirectory::cell_at(q, k.level + 1);
    }
    flush(rt);
  }

  /// Removes v (present).
  void erase(sac::Engine& rt, const CellVertex* v) {
    const auto q = dir_->position(v->p);
    CellKey k{};
    CellKey merge_at{-1, 0, 0};  // the highest split cell left at capacity or below
    for (;;) {
      Cell& c = cells_[k];
      --c.count;
      if (!c.split) break;
      if (merge_at.level < 0 && c.count <= CellState::kCapacity) merge_at = k;
      k = CellDirectory::cell_at(q, k.level + 1);
    }
    auto& items = cells_[k].items;
    const auto it = std::find(items.begin(), items.end(), v);
    if (it == items.end()) throw InvariantError("dynmesh: InputCells: erasing a vertex it does not hold");
    items.erase(it);
    touched_.push_back(k);
    if (merge_at.level >= 0) {
      std::vector<const CellVertex*> all;
      drop_below(merge_at, all);
      Cell& m = cells_[merge_at];
      m.split = false;
      m.items = std::move(all);
      touched_.push_back(merge_at);
    }
    flush(rt);
  }

  std::size_t size() const noexcept {
    const auto it = cells_.find(CellKey{});
    return it == cells_.end() ? 0 : it->second.count;
  }
  std::size_t bytes() const noexcept { return cells_.size() * (sizeof(Cell) + sizeof(CellKey) + 3 * sizeof(void*)); }

  /// The base values against the tree's definition (see the header); throws InvariantError.
  void check_invariants() const {
    dir_->check_invariants();
    std::size_t total = 0;
    check(CellKey{}, total);
    if (total != size()) throw InvariantError("dynmesh: InputCells: the root counts another number of vertices");
  }

 private:
  struct Cell {
    bool split = false;
    std::size_t count = 0;                 // vertices in the subtree
    std::vector<const CellVertex*> items;  // a leaf's
  };

  void drop_below(const CellKey& k, std::vector<const CellVertex*>& out) {
    for (unsigned ch = 0; ch < 4; ++ch) {
      const CellKey c = k.child(ch);
      const auto it = cells_.find(c);
      if (it == cells_.end()) continue;
      if (it->second.split) drop_below(c, out);
      else out.insert(out.end(), it->second.items.begin(), it->second.items.end());
      cells_.erase(c);
      touched_.push_back(c);
    }
  }

  /// The base value of every touched cell from the tree (a cell not in the map is absent).
  void flush(sac::Engine& rt) {
    for (const CellKey& k : touched_) {
      const auto it = cells_.find(k);
      CellState s;
      if (it != cells_.end()) {
        if (it->second.split) s = CellState::split();
        else s = CellState::leaf(it->second.items.begin(), it->second.items.end());
      }
      CellNode* n = dir_->find(k);
      if (!n && s.kind == CellState::Absent) continue;  // never made, and absent anyway
      if (!n) n = dir_->node(rt, k);
      rt.set(n->state, s);
    }
    touched_.clear();
  }

  void check(const CellKey& k, std::size_t& total) const {
    const auto fail = [&](const std::string& what) {
      throw InvariantError("dynmesh: InputCells: cell at level " + std::to_string(k.level) + ": " + what);
    };
    const auto it = cells_.find(k);
    if (it == cells_.end()) return;
    const Cell& c = it->second;
    const CellNode* n = dir_->find(k);
    if (!n) fail("a cell of the tree without a directory entry");
    std::size_t sub = 0;
    if (c.split) {
      if (!c.items.empty()) fail("a split cell holds vertices");
      for (unsigned ch = 0; ch < 4; ++ch) check(k.child(ch), sub);
      if (sub <= CellState::kCapacity) fail("a split cell at capacity or below");
    } else {
      if (c.items.size() > CellState::kCapacity && k.level < BucketTree::kMaxLevel) fail("a leaf over capacity");
      for (const CellVertex* w : c.items)
        if (!k.contains(CellDirectory::cell_at(dir_->position(w->p), BucketTree::kMaxLevel)))
          fail("a vertex outside its leaf's cell");
      sub = c.items.size();
    }
    if (sub != c.count) fail("a count that is not its subtree's");
    total += sub;
  }

  CellDirectory* dir_;
  std::unordered_map<CellKey, Cell, CellKeyHash> cells_;
  std::vector<CellKey> touched_;
};

}  // namespace dynmesh::detail
