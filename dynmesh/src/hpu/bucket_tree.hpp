// bucket_tree.hpp (private) — the mesh vertices by cell: a point-region quadtree whose leaves
// hold at most kCapacity vertices each.
//
// Purpose: the store that the hpu mesh's questions are answered from (cell_refiner.cpp).
// A question of size class j is a disc of radius O(2^j) around a pair; it reads the leaves
// that meet the disc (or, for a search that narrows, those that can still improve its
// answer) and runs exact predicates on their vertices, so the vertices far from the
// question are never looked at, however they are triangulated.
// Cells are the quadtree's dyadic cells of the box, located by the exact integer position
// of the mesh contract (q = ⌊(x − o)·2^52/L⌋, clamped to the grid so that the box's far
// sides fall in the last cells).
//
// Invariants (check_invariants()): a leaf holds at most kCapacity vertices unless it is at
// the finest level; a split cell holds more than kCapacity vertices in its subtree, so the
// tree is a function of the vertex set (not of the insertion order); every vertex lies in
// the leaf whose cell contains its position, exactly once.
// Complexity: insert O(depth + kCapacity); a query O(cells met + depth).
// Paper: Har-Peled & Üngör (2005), whose queries are local in a graded mesh; docs/HPU_ON_CELLS.md,
// "Where the vertices live".
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh::detail {

/// One non-empty leaf: its cell and its vertices (sorted), to compare trees.
struct BucketLeaf {
  int level;
  std::uint64_t ix, iy;
  std::vector<std::uint32_t> items;
  friend bool operator==(const BucketLeaf&, const BucketLeaf&) = default;
};

/// A grid index (below 2^53) as a double, exactly: by the signed conversion, one instruction
/// on x86-64, where the unsigned one is a sequence (the searches convert cell indices to
/// boxes all the time).
inline double grid_double(std::uint64_t i) noexcept { return static_cast<double>(static_cast<std::int64_t>(i)); }

class BucketTree {
 public:
  using Vid = std::uint32_t;
  static constexpr std::size_t kCapacity = 8;
  static constexpr int kMaxLevel = 52;

  explicit BucketTree(const Box<2>& box) : box_(box), scale_(box.scale()) {
    nodes_.emplace_back();
    for (int l = 0; l <= kMaxLevel; ++l) width_[static_cast<std::size_t>(l)] = std::ldexp(box_.side, -l);
  }

  /// The squared distance from c to the box [x0, x1] × [y0, y1] (0 inside): what every
  /// search's keep() test of a cell against a disc needs.
  static double box_distance2(const Point<2>& c, double x0, double y0, double x1, double y1) noexcept {
    const double dx = c[0] < x0 ? x0 - c[0] : c[0] > x1 ? c[0] - x1 : 0.0;
    const double dy = c[1] < y0 ? y0 - c[1] : c[1] > y1 ? c[1] - y1 : 0.0;
    return dx * dx + dy * dy;
  }

  /// The clamped grid position of x (monotone in each coordinate).
  std::array<std::uint64_t, 2> position(const Point<2>& x) const noexcept {
    std::array<std::uint64_t, 2> q{};
    // ⌊u⌋ clamped to [0, 2^52): the conversion truncates, which is the floor for u > 0
    // (std::floor is a call on the baseline x86-64 target, and this runs for every search),
    // by the signed conversion, as grid_double().
    for (unsigned a = 0; a < 2; ++a) {
      const double u = (x[a] - box_.origin[a]) * scale_;
      q[a] = !(u > 0) ? 0 : u >= 0x1p52 ? (std::uint64_t{1} << 52) - 1 : static_cast<std::uint64_t>(static_cast<std::int64_t>(u));
    }
    return q;
  }

  /// Adds vertex v at p. The caller keeps the points: pts[v] must already be p (a split
  /// re-locates every vertex of the leaf, v included).
  void insert(Vid v, const Point<2>& p, std::span<const Point<2>> pts) {
    const auto q = position(p);
    std::uint32_t n = 0;
    int level = 0;
    for (;;) {
      ++nodes_[n].count;
      if (nodes_[n].child == kLeaf) break;
      n = nodes_[n].child + quadrant(q, level);
      ++level;
    }
    nodes_[n].items.push_back(v);
    ++size_;
    while (nodes_[n].items.size() > kCapacity && level < kMaxLevel) {
      // Split: the items move to the four children, and the one holding them all splits on.
      const auto first = static_cast<std::uint32_t>(nodes_.size());
      nodes_.resize(nodes_.size() + 4);
      std::vector<Vid> items = std::move(nodes_[n].items);
      nodes_[n].items.clear();
      nodes_[n].child = first;
      for (const Vid w : items) {
        Node& c = nodes_[first + quadrant(position(pts[w]), level)];
        c.items.push_back(w);
        ++c.count;
      }
      n = first + quadrant(q, level);
      ++level;
    }
  }

  /// Calls f(v) for every vertex whose position lies in the closed rectangle of the positions
  /// of lo and hi (so every vertex x with lo ≤ x ≤ hi, and possibly a few more).
  template <class F>
  void visit(const Point<2>& lo, const Point<2>& hi, F&& f) const {
    const auto a = position(lo), b = position(hi);
    visit_node(0, 0, 0, 0, a, b, f);
  }

  /// Calls stop = f(v) for the vertices of every leaf whose cell meets the disc (c, r) (cells
  /// are tested in doubles, widened by a margin, so no vertex in the disc is missed), until
  /// f returns true.
  template <class F>
  void visit_disc(const Point<2>& c, double r, F&& f) const {
    // Point location rounds (x − o)·2^52/L: allow for a few ulps of the coordinates.
    const double margin = margin_for(c, r);
    const double r2 = (r + margin) * (r + margin);
    search(
        c, margin,
        [&](double x0, double y0, double x1, double y1) { return box_distance2(c, x0, y0, x1, y1) <= r2; },
        f);
  }

  /// A pruned search: visits the leaves whose cell (widened by `margin`) `keep(x0, y0, x1, y1)`
  /// accepts, nearest to `focus` first, calling stop = f(v) on their vertices. keep() is asked
  /// again before every cell, so a search that narrows as it finds (a nearest-neighbour or a
  /// lowest-circle search) reads only the cells that can still improve its answer.
  template <class Keep, class F>
  void search(const Point<2>& focus, double margin, Keep&& keep, F&& f) const {
    bool stop = false;
    search_node(0, 0, 0, 0, focus, margin, keep, f, stop);
  }

  /// search() with the cell-store interface of cell_questions.hpp (a static tree needs no
  /// scale: it reads from the root).
  template <class Keep, class F>
  void search(const Point<2>& focus, double /*scale*/, double margin, Keep&& keep, F&& f) const {
    search(focus, margin, keep, f);
  }
  /// search() of the cells that cover [focus ± R] (the cell-store interface): a static tree
  /// searches from the root, which covers them.
  template <class Keep, class F>
  void search_from(const Point<2>& focus, double /*R*/, double margin, Keep&& keep, F&& f) const {
    search(focus, margin, keep, f);
  }
  /// search() for a keep() that accepts no cell farther than radius() from focus (the
  /// cell-store interface): the same on a static tree.
  template <class Keep, class F, class Radius>
  void search_near(const Point<2>& focus, double /*scale*/, double margin, Keep&& keep, F&& f,
                   Radius&& /*radius*/) const {
    search(focus, margin, keep, f);
  }
  /// search() for a keep() bounded by the disc (focus, radius): the same on a static tree.
  template <class Keep, class F>
  void search_within(const Point<2>& focus, double /*radius*/, double /*scale*/, double margin, Keep&& keep,
                     F&& f) const {
    search(focus, margin, keep, f);
  }

  /// After a search(): what its answer depended on (the cell-store interface; a static tree
  /// records no dependencies).
  void used_within(const Point<2>& /*c*/, double /*r*/) const noexcept {}
  void used_all() const noexcept {}
  void used_box(double /*x0*/, double /*y0*/, double /*x1*/, double /*y1*/) const noexcept {}

  /// The widening of cells that keeps every vertex of a cell inside it despite the rounding
  /// of point location, for a query of radius r around c. position() is off by less than
  /// 2^-51·(|x| + |origin|) in coordinates (the difference, the scale and their product
  /// each round once); the absolute term is at least 16 times that (as small as that allows:
  /// see cellq::ulp_room), and the relative one covers the vertices' distance from c.
  double margin_for(const Point<2>& c, double r) const noexcept {
    const double mag = std::max({std::abs(c[0]), std::abs(c[1]), std::abs(box_.origin[0]), std::abs(box_.origin[1])});
    return r * 0x1p-30 + (mag + box_.side) * 0x1p-46;
  }

  std::size_t size() const noexcept { return size_; }

  /// The non-empty leaves, in (level, x, y) order, each with its vertices sorted.
  std::vector<BucketLeaf> leaves() const {
    std::vector<BucketLeaf> out;
    leaves_of(0, 0, 0, 0, out);
    std::sort(out.begin(), out.end(), [](const BucketLeaf& a, const BucketLeaf& b) {
      if (a.level != b.level) return a.level < b.level;
      return a.ix != b.ix ? a.ix < b.ix : a.iy < b.iy;
    });
    return out;
  }
  /// While set, every vertex a query hands out adds digest(v) to *sum (an order-free record
  /// of what a step looked at, for the locality experiment of cell_refiner.hpp).
  /// `leaves`, when given, receives the id of every leaf read (repeats included).
  void watch(std::uint64_t* sum, std::uint64_t (*digest)(const void* ctx, Vid v), const void* ctx,
             std::vector<std::uint32_t>* leaves = nullptr) const noexcept {
    watch_leaves_ = leaves;
    watch_sum_ = sum;
    watch_digest_ = digest;
    watch_ctx_ = ctx;
  }
  /// Leaves met by all queries so far (the events a self-adjusting version would read).
  std::size_t leaves_read() const noexcept { return leaves_read_; }

  /// Throws InvariantError naming the first broken rule (see the header).
  void check_invariants(std::span<const Point<2>> pts) const {
    std::vector<std::uint8_t> seen(pts.size(), 0);
    std::size_t total = check_node(0, 0, 0, 0, pts, seen);
    if (total != size_) throw InvariantError("dynmesh: BucketTree: the root counts " + std::to_string(total) +
                                             " vertices, the tree " + std::to_string(size_));
  }

 private:
  static constexpr std::uint32_t kLeaf = 0;  // node 0 is the root, never a child

  struct Node {
    std::uint32_t child = kLeaf;  // the first of four children, or kLeaf
    std::uint32_t count = 0;      // vertices in the subtree
    std::vector<Vid> items;       // a leaf's vertices
  };

  static unsigned quadrant(const std::array<std::uint64_t, 2>& q, int level) noexcept {
    const int s = kMaxLevel - 1 - level;
    return static_cast<unsigned>(((q[0] >> s) & 1) | (((q[1] >> s) & 1) << 1));
  }

  template <class F>
  void visit_node(std::uint32_t n, int level, std::uint64_t ix, std::uint64_t iy, const std::array<std::uint64_t, 2>& a,
                  const std::array<std::uint64_t, 2>& b, F& f) const {
    const Node& N = nodes_[n];
    if (N.count == 0) return;
    const int s = kMaxLevel - level;
    const std::uint64_t x0 = ix << s, y0 = iy << s;
    const std::uint64_t x1 = x0 + ((std::uint64_t{1} << s) - 1), y1 = y0 + ((std::uint64_t{1} << s) - 1);
    if (x1 < a[0] || x0 > b[0] || y1 < a[1] || y0 > b[1]) return;
    if (N.child == kLeaf) {
      ++leaves_read_;
      if (watch_leaves_) watch_leaves_->push_back(n);
      for (const Vid v : N.items) {
        if (watch_sum_) *watch_sum_ += watch_digest_(watch_ctx_, v);
        f(v);
      }
      return;
    }
    for (unsigned k = 0; k < 4; ++k)
      visit_node(N.child + k, level + 1, 2 * ix + (k & 1), 2 * iy + (k >> 1), a, b, f);
  }

  void leaves_of(std::uint32_t n, int level, std::uint64_t ix, std::uint64_t iy, std::vector<BucketLeaf>& out) const {
    const Node& N = nodes_[n];
    if (N.count == 0) return;
    if (N.child == kLeaf) {
      out.push_back(BucketLeaf{level, ix, iy, N.items});
      std::sort(out.back().items.begin(), out.back().items.end());
      return;
    }
    for (unsigned k = 0; k < 4; ++k) leaves_of(N.child + k, level + 1, 2 * ix + (k & 1), 2 * iy + (k >> 1), out);
  }

  template <class Keep, class F>
  void search_node(std::uint32_t n, int level, std::uint64_t ix, std::uint64_t iy, const Point<2>& focus, double margin,
                   Keep& keep, F& f, bool& stop) const {
    const Node& N = nodes_[n];
    if (N.count == 0 || stop) return;
    const double w = width_[static_cast<std::size_t>(level)];
    const double x0 = box_.origin[0] + grid_double(ix) * w - margin, x1 = x0 + w + 2 * margin;
    const double y0 = box_.origin[1] + grid_double(iy) * w - margin, y1 = y0 + w + 2 * margin;
    if (!keep(x0, y0, x1, y1)) return;
    if (N.child == kLeaf) {
      ++leaves_read_;
      if (watch_leaves_) watch_leaves_->push_back(n);
      for (const Vid v : N.items) {
        if (watch_sum_) *watch_sum_ += watch_digest_(watch_ctx_, v);
        if (f(v)) {
          stop = true;
          return;
        }
      }
      return;
    }
    // Children nearest to the focus first (by their centres' distance).
    std::array<std::pair<double, unsigned>, 4> order;
    for (unsigned k = 0; k < 4; ++k) {
      const double cx = box_.origin[0] + (grid_double(2 * ix + (k & 1)) + 0.5) * 0.5 * w;
      const double cy = box_.origin[1] + (grid_double(2 * iy + (k >> 1)) + 0.5) * 0.5 * w;
      order[k] = {(cx - focus[0]) * (cx - focus[0]) + (cy - focus[1]) * (cy - focus[1]), k};
    }
    // The order std::sort gives (the keys are distinct), by a five-exchange network: the
    // sort's call was a tenth of the refiner's time.
    const auto exchange = [&](unsigned a, unsigned b) {
      if (order[b] < order[a]) std::swap(order[a], order[b]);
    };
    exchange(0, 1), exchange(2, 3), exchange(0, 2), exchange(1, 3), exchange(1, 2);
    for (const auto& [d2, k] : order) {
      if (stop) return;
      search_node(N.child + k, level + 1, 2 * ix + (k & 1), 2 * iy + (k >> 1), focus, margin, keep, f, stop);
    }
  }

  std::size_t check_node(std::uint32_t n, int level, std::uint64_t ix, std::uint64_t iy, std::span<const Point<2>> pts,
                         std::vector<std::uint8_t>& seen) const {
    const auto fail = [&](const std::string& what) {
      throw InvariantError("dynmesh: BucketTree: cell at level " + std::to_string(level) + ": " + what);
    };
    const Node& N = nodes_[n];
    std::size_t total = 0;
    if (N.child == kLeaf) {
      if (N.items.size() > kCapacity && level < kMaxLevel) fail("a leaf over capacity");
      for (const Vid v : N.items) {
        if (v >= pts.size() || seen[v]) fail("a vertex stored twice or unknown");
        seen[v] = 1;
        const auto q = position(pts[v]);
        const int s = kMaxLevel - level;
        if ((q[0] >> s) != ix || (q[1] >> s) != iy) fail("a vertex outside its leaf's cell");
      }
      total = N.items.size();
    } else {
      if (!N.items.empty()) fail("a split cell holds vertices");
      for (unsigned k = 0; k < 4; ++k)
        total += check_node(N.child + k, level + 1, 2 * ix + (k & 1), 2 * iy + (k >> 1), pts, seen);
      if (total <= kCapacity) fail("a split cell with " + std::to_string(total) + " vertices (at most the capacity)");
    }
    if (total != N.count) fail("a count that is not its subtree's");
    return total;
  }

  Box<2> box_;
  double scale_;
  std::array<double, kMaxLevel + 1> width_{};  // the side of a cell at each level
  std::vector<Node> nodes_;
  std::size_t size_ = 0;
  mutable std::size_t leaves_read_ = 0;
  mutable std::uint64_t* watch_sum_ = nullptr;
  mutable std::vector<std::uint32_t>* watch_leaves_ = nullptr;
  mutable std::uint64_t (*watch_digest_)(const void*, Vid) = nullptr;
  mutable const void* watch_ctx_ = nullptr;
};

}  // namespace dynmesh::detail
