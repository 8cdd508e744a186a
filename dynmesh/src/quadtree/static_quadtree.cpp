// static_quadtree.cpp — T* by definition (crowded cells, then the grading closure), and the
// tree checker. See dynmesh/static_quadtree.hpp for the contract and the argument that the
// single bottom-up closure pass is the least fixed point.
#include "dynmesh/static_quadtree.hpp"

#include "dynmesh/detail/touching_leaves.hpp"

#include <algorithm>
#include <bit>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <utility>

#include "dynmesh/errors.hpp"

namespace dynmesh {
namespace {

using detail::CellSet;
using detail::CellTable;

template <std::size_t d>
bool position_valid(const Position<d>& q) noexcept {
  for (std::size_t a = 0; a < d; ++a)
    if (q[a] >= kResolution) return false;
  return true;
}

template <std::size_t d>
std::string position_string(const Position<d>& q) {
  std::string s = "[";
  for (std::size_t a = 0; a < d; ++a) {
    if (a) s += ", ";
    s += std::to_string(q[a]);
  }
  return s + "]";
}

/// Morton (Z-order) comparison of integer vectors (Chan's most-significant-differing-bit
/// trick): the axis whose XOR has the highest set bit decides; axis 0 wins ties.
template <std::size_t d>
bool morton_less(const std::array<std::uint64_t, d>& a, const std::array<std::uint64_t, d>& b) noexcept {
  std::size_t best = 0;
  std::uint64_t best_diff = a[0] ^ b[0];
  for (std::size_t k = 1; k < d; ++k) {
    const std::uint64_t diff = a[k] ^ b[k];
    if (best_diff < diff && best_diff < (best_diff ^ diff)) {
      best = k;
      best_diff = diff;
    }
  }
  return a[best] < b[best];
}

/// The points sorted in Morton order: the points of any cell form one contiguous run, so
/// "how many points does cell c hold" is two binary searches, at any level.
template <std::size_t d>
class MortonIndex {
 public:
  explicit MortonIndex(std::vector<Position<d>> pts) : sorted_(std::move(pts)) {
    std::sort(sorted_.begin(), sorted_.end(), [](const Position<d>& a, const Position<d>& b) {
      return morton_less<d>(a, b);
    });
  }

  std::size_t count(const CellId<d>& c) const {
    const auto lo = lower(c);
    const int s = kMaxLevel - c.level;
    const auto hi = std::upper_bound(lo, sorted_.end(), c, [s](const CellId<d>& cc, const Position<d>& p) {
      return morton_less<d>(cc.index, shifted(p, s));
    });
    return static_cast<std::size_t>(hi - lo);
  }

  bool any(const CellId<d>& c) const {
    const auto it = lower(c);
    return it != sorted_.end() && contains(c, *it);
  }

  /// docs/DESIGN.md, "The quadtree contract": c holds two or more points, or exactly one while N(c) holds another.
  bool crowded(const CellId<d>& c) const {
    const std::size_t k = count(c);
    if (k != 1) return k >= 2;
    return neighbours_occupied(c);
  }

  /// Does some cell of N(c) other than c hold a point?
  bool neighbours_occupied(const CellId<d>& c) const {
    bool found = false;
    for_each_neighbour(c, [&](const CellId<d>& nb) {
      if (!found && any(nb)) found = true;
    });
    return found;
  }

 private:
  static std::array<std::uint64_t, d> shifted(const Position<d>& p, int s) noexcept {
    std::array<std::uint64_t, d> k;
    for (std::size_t a = 0; a < d; ++a) k[a] = p[a] >> s;
    return k;
  }

  typename std::vector<Position<d>>::const_iterator lower(const CellId<d>& c) const {
    const int s = kMaxLevel - c.level;
    return std::lower_bound(sorted_.begin(), sorted_.end(), c, [s](const Position<d>& p, const CellId<d>& cc) {
      return morton_less<d>(shifted(p, s), cc.index);
    });
  }

  std::vector<Position<d>> sorted_;
};

/// The leaf containing q in a tree given by its split set (closed under parent), whose
/// deepest split level is max_split (-1: nothing split). Binary search over levels: along
/// the chain of cells containing q, the split ones form a prefix.
template <std::size_t d, class V>
CellId<d> locate_in(const CellTable<d, V>& split, int max_split, const Position<d>& q) {
  int lo = 0, hi = max_split + 1;  // levels < lo are split; the cell at level hi is not
  while (lo < hi) {
    const int mid = lo + (hi - lo) / 2;
    if (split.contains(cell_of(q, mid)))
      lo = mid + 1;
    else
      hi = mid;
  }
  return cell_of(q, lo);
}

/// The leaf (of the tree given by its split set) that contains the unsplit cell c.
template <std::size_t d, class V>
CellId<d> leaf_of(const CellTable<d, V>& split, const CellId<d>& c) {
  return detail::leaf_containing<d>([&](const CellId<d>& cell) { return split.contains(cell); }, c);
}

/// The leaves touching leaf a, sorted, a excluded, into `out` (`stack` is scratch space).
template <std::size_t d, class V>
void touching_leaves(const CellTable<d, V>& split, const CellId<d>& a, std::vector<CellId<d>>& out,
                     std::vector<CellId<d>>& stack) {
  out.clear();
  detail::for_each_touching_leaf<d>(
      a, [&](const CellId<d>& cell) { return split.contains(cell); }, [](const CellId<d>&) { return true; },
      [&](const CellId<d>& leaf) { out.push_back(leaf); },
      [&](const CellId<d>& leaf, const CellId<d>&) { out.push_back(leaf); }, stack);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

/// The child number of c in its parent: bit a is the low bit of c's index on axis a.
template <std::size_t d>
unsigned child_number(const CellId<d>& c) noexcept {
  unsigned w = 0;
  for (std::size_t a = 0; a < d; ++a) w |= static_cast<unsigned>(c.index[a] & 1u) << a;
  return w;
}

/// Appends the unsplit children of `parents` — the split cells of one level, sorted by index,
/// each with its split-children mask — in (i, j, k) order, without sorting the children: on
/// each axis, a run of parents with equal index yields children 2P then 2P + 1 on that axis.
template <std::size_t d>
void emit_unsplit_children(std::span<const std::pair<CellId<d>, std::uint8_t>> parents, std::vector<Leaf<d>>& out) {
  auto rec = [&](auto&& self, std::size_t lo, std::size_t hi, std::size_t axis, unsigned which) -> void {
    if (axis == d) {  // all indices equal: exactly one parent
      const auto& [p, mask] = parents[lo];
      if (!((mask >> which) & 1u)) out.push_back(Leaf<d>{child(p, which), 0});
      return;
    }
    for (std::size_t run = lo; run < hi;) {
      std::size_t end = run + 1;
      while (end < hi && parents[end].first.index[axis] == parents[run].first.index[axis]) ++end;
      self(self, run, end, axis + 1, which);
      self(self, run, end, axis + 1, which | (1u << axis));
      run = end;
    }
  };
  rec(rec, 0, parents.size(), 0, 0);
}

}  // namespace

// ---------------------------------------------------------------------------------------
// StaticQuadtree

template <std::size_t d>
  requires SupportedDim<d>
StaticQuadtree<d>::StaticQuadtree(std::span<const Position<d>> points) : points_(points.begin(), points.end()) {
  const std::size_t n = points_.size();
  if (n >= std::numeric_limits<std::uint32_t>::max())
    throw InputError(InputError::Kind::Count, "too many points (" + std::to_string(n) + ")");
  for (std::size_t i = 0; i < n; ++i)
    if (!position_valid<d>(points_[i]))
      throw InputError(InputError::Kind::OutsideBox,
                       "point " + std::to_string(i) + " has a position outside [0, 2^52): " +
                           position_string<d>(points_[i]))
          .with_points({i});

  // --- Crowded cells, by level from the root. -------------------------------------------
  // active = the points whose cell at the previous level is crowded. A point whose level-l
  // cell is not crowded has no other point within one cell per axis at level l, hence none at
  // any deeper level either; and every point within one cell of an active point's cell at
  // level l+1 was itself active at level l. So hashing the active points suffices.
  std::vector<std::vector<CellId<d>>> crowded(kMaxLevel + 1);
  std::vector<std::uint32_t> active;
  if (n >= 2) {
    crowded[0].push_back(CellId<d>::root());
    active.resize(n);
    std::iota(active.begin(), active.end(), std::uint32_t{0});
    // Morton order: every later pass then walks space coherently, which the tables' locality-
    // preserving hashing turns into cache hits. (The result does not depend on this order.)
    std::sort(active.begin(), active.end(), [&](std::uint32_t a, std::uint32_t b) {
      return morton_less<d>(points_[a], points_[b]);
    });
  }
  struct Occupancy {
    std::uint32_t count = 0;
    std::uint32_t first = 0;
    std::uint32_t second = 0;
    std::int8_t crowded = -1;  // -1 not yet decided
  };
  for (int l = 1; l <= kMaxLevel && !active.empty(); ++l) {
    CellTable<d, Occupancy> occ(active.size());
    for (const std::uint32_t p : active) {
      Occupancy* o = occ.try_emplace(cell_of(points_[p], l), Occupancy{0, p, p, -1}).first;
      if (o->count == 1) o->second = p;
      ++o->count;
    }
    std::vector<std::uint32_t> next;
    next.reserve(active.size());
    for (const std::uint32_t p : active) {
      const CellId<d> c = cell_of(points_[p], l);
      Occupancy* o = occ.find(c);
      if (o->crowded < 0) {
        bool cr = o->count >= 2;
        if (!cr)
          for_each_neighbour(c, [&](const CellId<d>& nb) {
            if (!cr && occ.contains(nb)) cr = true;
          });
        o->crowded = cr ? 1 : 0;
        if (cr) crowded[static_cast<std::size_t>(l)].push_back(c);
      }
      if (o->crowded) next.push_back(p);
    }
    if (l == kMaxLevel && !next.empty()) {
      // A level-52 cell holds one integer position: two points in it are duplicates, and a
      // point with another within one grid unit per axis would need a level-53 split.
      for (const CellId<d>& c : crowded[kMaxLevel]) {
        const Occupancy* o = occ.find(c);
        if (o->count >= 2)
          throw InputError(InputError::Kind::Duplicate,
                           "points " + std::to_string(o->first) + " and " + std::to_string(o->second) +
                               " have the same located position " + position_string<d>(points_[o->first]) +
                               " (duplicate point)")
              .with_points({o->first, o->second});
      }
      // Only positions are known here: s < 2·sqrt(d)·L/2^52 bounds the spread from below.
      const std::string spread_floor = d == 2 ? "50.5" : "50.2";
      const CellId<d> c = crowded[kMaxLevel].front();
      const Occupancy* o = occ.find(c);
      std::uint32_t other = o->first;
      for_each_neighbour(c, [&](const CellId<d>& nb) {
        if (other != o->first) return;
        if (const Occupancy* q = occ.find(nb)) other = q->first;
      });
      throw InputError(InputError::Kind::Resolution,
                       "points " + std::to_string(std::min(o->first, other)) + " and " +
                           std::to_string(std::max(o->first, other)) +
                           " are within one grid unit of each other (positions " +
                           position_string<d>(points_[o->first]) + " and " + position_string<d>(points_[other]) +
                           "): a level-52 cell would have to split; the spread L/s exceeds 2^" +
                           spread_floor + " (s < 2·sqrt(d) grid units of L/2^52), beyond the resolution of 2^52")
          .with_points({std::min(o->first, other), std::max(o->first, other)});
    }
    active.swap(next);
  }

  // --- Closure: S_m = crowded_m ∪ {level-m cells touching a cell of S_{m+1}}. -------------
  int maxc = -1;
  std::size_t total_crowded = 0;
  for (int l = 0; l <= kMaxLevel; ++l) {
    if (!crowded[static_cast<std::size_t>(l)].empty()) maxc = l;
    total_crowded += crowded[static_cast<std::size_t>(l)].size();
  }
  max_split_level_ = maxc;
  split_.reserve(2 * total_crowded);
  std::vector<std::vector<CellId<d>>> by_level(static_cast<std::size_t>(maxc + 1));
  for (int m = maxc; m >= 0; --m) {
    auto& here = by_level[static_cast<std::size_t>(m)];
    for (const CellId<d>& c : crowded[static_cast<std::size_t>(m)])
      if (split_.try_emplace(c, 0).second) here.push_back(c);
    if (m < maxc)
      for (const CellId<d>& t : by_level[static_cast<std::size_t>(m + 1)]) {
        const unsigned which = child_number(t);
        bool is_parent = true;  // for_each_coarser_touching yields the parent first
        for_each_coarser_touching(t, [&](const CellId<d>& u) {
          const auto [mask, fresh] = split_.try_emplace(u, 0);
          if (is_parent) *mask = static_cast<std::uint8_t>(*mask | (1u << which));
          is_parent = false;
          if (fresh) here.push_back(u);
        });
      }
  }

  // --- Leaves: the unsplit children of split cells (the root alone if nothing is split), ----
  // emitted directly in (level, i, j, k) order from the split cells sorted per level.
  if (split_.empty()) {
    leaves_.push_back(Leaf<d>{CellId<d>::root(), 0});
  } else {
    leaves_.reserve(split_.size() * (kChildren<d> - 1) + 1);
    std::vector<std::pair<CellId<d>, std::uint8_t>> parents;
    for (auto& level : by_level) {
      std::sort(level.begin(), level.end());
      parents.clear();
      for (const CellId<d>& s : level) parents.emplace_back(s, *split_.find(s));
      emit_unsplit_children<d>(parents, leaves_);
    }
  }
  for (const Position<d>& q : points_) ++leaves_[leaf_index(locate(q))].npoints;
  depth_ = leaves_.back().cell.level;
}

template <std::size_t d>
  requires SupportedDim<d>
StaticQuadtree<d> StaticQuadtree<d>::from_points(const Box<d>& box, std::span<const Point<d>> points) {
  validate_box(box);
  std::vector<Position<d>> q;
  q.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    try {
      q.push_back(dynmesh::locate(box, points[i]));
    } catch (InputError& e) {
      throw InputError(e.kind(), "point " + std::to_string(i) + " " + to_string<d>(points[i]) + ": " + e.text())
          .with_points({i});
    }
  }
  return StaticQuadtree(q);
}

template <std::size_t d>
  requires SupportedDim<d>
std::vector<CellId<d>> StaticQuadtree<d>::split_cells() const {
  std::vector<CellId<d>> out;
  out.reserve(split_.size());
  split_.for_each([&](const CellId<d>& c, const std::uint8_t&) { out.push_back(c); });
  std::sort(out.begin(), out.end());
  return out;
}

template <std::size_t d>
  requires SupportedDim<d>
bool StaticQuadtree<d>::is_leaf(const CellId<d>& c) const noexcept {
  return valid(c) && !split_.contains(c) && (c.level == 0 || split_.contains(parent(c)));
}

template <std::size_t d>
  requires SupportedDim<d>
std::size_t StaticQuadtree<d>::leaf_index(const CellId<d>& c) const {
  const auto it = std::lower_bound(leaves_.begin(), leaves_.end(), c,
                                   [](const Leaf<d>& leaf, const CellId<d>& cell) { return leaf.cell < cell; });
  if (it == leaves_.end() || it->cell != c)
    throw std::invalid_argument("dynmesh: cell " + to_string<d>(c) + " is not a leaf of this tree");
  return static_cast<std::size_t>(it - leaves_.begin());
}

template <std::size_t d>
  requires SupportedDim<d>
CellId<d> StaticQuadtree<d>::locate(const Position<d>& q) const {
  if (!position_valid<d>(q))
    throw InputError(InputError::Kind::OutsideBox, "position outside [0, 2^52): " + position_string<d>(q));
  return locate_in(split_, max_split_level_, q);
}

template <std::size_t d>
  requires SupportedDim<d>
std::vector<CellId<d>> StaticQuadtree<d>::neighbours(const CellId<d>& c) const {
  (void)leaf_index(c);  // throws unless c is a leaf
  std::vector<CellId<d>> out, stack;
  touching_leaves(split_, c, out, stack);
  return out;
}

template <std::size_t d>
  requires SupportedDim<d>
void StaticQuadtree<d>::check_invariants() const {
  // The stored split set must be exactly the proper ancestors of the leaves...
  const std::size_t expected_leaves = split_.size() * (kChildren<d> - 1) + 1;
  if (leaves_.size() != expected_leaves)
    throw InvariantError("StaticQuadtree: " + std::to_string(leaves_.size()) + " leaves for " +
                         std::to_string(split_.size()) + " split cells (expected " +
                         std::to_string(expected_leaves) + ")");
  for (std::size_t i = 0; i < leaves_.size(); ++i) {
    const CellId<d>& c = leaves_[i].cell;
    if (!is_leaf(c)) throw InvariantError("StaticQuadtree: leaf " + to_string<d>(c) + " disagrees with the split set");
    if (i > 0 && !(leaves_[i - 1].cell < c)) throw InvariantError("StaticQuadtree: leaves are not sorted");
  }
  // ... and the leaves must be those of T* (which check_tree decides from scratch).
  require_valid_tree<d>(points_, leaves_);
}

// ---------------------------------------------------------------------------------------
// check_tree

const char* to_string(ViolationKind kind) noexcept {
  switch (kind) {
    case ViolationKind::BadCell: return "bad-cell";
    case ViolationKind::DuplicateLeaf: return "duplicate-leaf";
    case ViolationKind::Overlap: return "overlap";
    case ViolationKind::Gap: return "gap";
    case ViolationKind::BadPoint: return "bad-point";
    case ViolationKind::Overfull: return "overfull";
    case ViolationKind::CountMismatch: return "count-mismatch";
    case ViolationKind::TouchingOccupied: return "touching-occupied";
    case ViolationKind::Grading: return "grading";
    case ViolationKind::CrowdedLeaf: return "crowded-leaf";
    case ViolationKind::UnjustifiedSplit: return "unjustified-split";
  }
  return "unknown";
}

template <std::size_t d>
bool CheckReport<d>::has(ViolationKind kind) const noexcept {
  return count(kind) > 0;
}

template <std::size_t d>
std::size_t CheckReport<d>::count(ViolationKind kind) const noexcept {
  return static_cast<std::size_t>(std::count_if(violations.begin(), violations.end(),
                                                [kind](const Violation<d>& v) { return v.kind == kind; }));
}

template <std::size_t d>
std::string CheckReport<d>::summary() const {
  if (violations.empty()) return "ok";
  std::string s;
  for (const auto& v : violations) {
    if (!s.empty()) s += '\n';
    s += to_string(v.kind);
    s += ": ";
    s += v.message;
  }
  if (truncated) s += "\n... more violations not shown";
  return s;
}

namespace {

/// One run of check_tree: the leaves and points under check, what the phases learn about
/// them, and the report. Each phase reads what the ones before it built.
template <std::size_t d>
class TreeCheck {
 public:
  TreeCheck(std::span<const Position<d>> points, std::span<const Leaf<d>> leaves, std::size_t max_violations,
            int split_below)
      : points_(points), leaves_(leaves), max_violations_(max_violations), split_below_(split_below),
        nl_(leaves.size()) {}

  CheckReport<d> report;

  // --- Tiling. -------------------------------------------------------------------------------

  /// Every leaf is a cell of the box (false: some is not, and it is reported).
  bool leaves_are_cells() {
    bool ok = true;
    for (const Leaf<d>& leaf : leaves_)
      if (!valid(leaf.cell)) {
        ok = false;
        add(ViolationKind::BadCell, leaf.cell, leaf.cell, "leaf " + to_string<d>(leaf.cell) + " is not a cell of the box");
      }
    return ok;
  }

  /// order_[k] = index of the k-th leaf in (level, i, j, k) order; the identity when the
  /// leaves come sorted, as every producer in this project delivers them. False: a leaf is
  /// listed twice (reported).
  bool order_leaves() {
    order_.resize(nl_);
    std::iota(order_.begin(), order_.end(), std::uint32_t{0});
    bool sorted = true;
    for (std::size_t i = 1; i < nl_ && sorted; ++i) sorted = leaves_[i - 1].cell < leaves_[i].cell;
    if (sorted) return true;
    std::sort(order_.begin(), order_.end(), [&](std::uint32_t a, std::uint32_t b) {
      return leaves_[a].cell != leaves_[b].cell ? leaves_[a].cell < leaves_[b].cell : a < b;
    });
    bool distinct = true;
    for (std::size_t k = 1; k < nl_; ++k)
      if (cell_at(k - 1) == cell_at(k)) {
        distinct = false;
        add(ViolationKind::DuplicateLeaf, cell_at(k), cell_at(k), "leaf " + to_string<d>(cell_at(k)) + " is listed more than once");
      }
    return distinct;
  }

  /// S = the proper ancestors of the leaves, per level in a deterministic order. The value
  /// of a split cell holds the mask of its children present in S ∪ L (bits 0..2^d−1) and
  /// kForced, set by check_grading when a deeper split forces this one (rules 2 and 3).
  void build_split_set() {
    split_.reserve(nl_ / (kChildren<d> - 1) + 1);
    split_by_level_.assign(kMaxLevel + 1, {});
    for (std::size_t k = 0; k < nl_; ++k) {
      const CellId<d>& c = cell_at(k);
      // Siblings along the last axis are adjacent in the order: the previous iteration has
      // already inserted the parent, so only the bit is missing.
      if (k > 0 && c.level > 0 && cell_at(k - 1).level == c.level && parent(cell_at(k - 1)) == parent(c)) {
        std::uint16_t* mask = split_.find(parent(c));
        *mask = static_cast<std::uint16_t>(*mask | (1u << child_number(c)));
        continue;
      }
      attach(c);
    }
    for (int l = 0; l <= kMaxLevel; ++l) {
      const auto& level = split_by_level_[static_cast<std::size_t>(l)];
      if (!level.empty()) max_split_ = l;
      for (const CellId<d>& s : level) edges_ += static_cast<std::size_t>(std::popcount(*split_.find(s)));
    }
  }

  /// The leaves neither overlap nor leave a gap (false: they do, reported).
  bool leaves_tile_the_box() {
    // Every element of S ∪ L but the root hangs below exactly one split cell, so the number
    // of registered edges is |S ∪ L| − 1: it falls short of |S| + |L| − 1 exactly when some
    // leaf is also a split cell (contains another leaf), and short of 2^d·|S| exactly when
    // some child of a split cell is missing (the leaves do not tile the box).
    bool ok = true;
    if (edges_ != split_.size() + nl_ - 1) {
      ok = false;
      for (std::size_t k = 0; k < nl_; ++k)
        if (split_.contains(cell_at(k)))
          add(ViolationKind::Overlap, cell_at(k), cell_at(k), "leaf " + to_string<d>(cell_at(k)) + " contains other leaves");
    }
    if (edges_ != split_.size() * kChildren<d>) {
      ok = false;
      for (const auto& level : split_by_level_)
        for (const CellId<d>& s : level) {
          const unsigned mask = *split_.find(s);
          for (unsigned w = 0; w < static_cast<unsigned>(kChildren<d>); ++w)
            if (!((mask >> w) & 1u))
              add(ViolationKind::Gap, child(s, w), s,
                  "cell " + to_string<d>(child(s, w)) + " (child of split cell " + to_string<d>(s) +
                      ") is neither a leaf nor split: the leaves do not tile the box");
        }
    }
    return ok;
  }

  // --- Occupancy. ----------------------------------------------------------------------------

  /// Locates every point in its leaf (reporting points outside the grid), then checks that
  /// no leaf holds two points and every leaf's npoints is right. Builds the Morton index of
  /// the valid points for the phases below.
  void check_occupancy() {
    occupied_.reserve(std::min(points_.size(), nl_));
    std::vector<Position<d>> valid_points;
    valid_points.reserve(points_.size());
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const Position<d>& q = points_[i];
      if (!position_valid<d>(q)) {
        add(ViolationKind::BadPoint, CellId<d>::root(), CellId<d>::root(),
            "point " + std::to_string(i) + " has a position outside [0, 2^52): " + position_string<d>(q));
        continue;
      }
      valid_points.push_back(q);
      const CellId<d> c = locate_in(split_, max_split_, q);
      const auto [o, fresh] = occupied_.try_emplace(c, Occupied{0, 0, static_cast<std::uint32_t>(i)});
      if (fresh) o->position = static_cast<std::uint32_t>(find_leaf(c));
      ++o->count;
    }
    occupied_list_.reserve(occupied_.size());
    occupied_.for_each([&](const CellId<d>&, const Occupied& o) { occupied_list_.emplace_back(o.position, o.count); });
    std::sort(occupied_list_.begin(), occupied_list_.end());
    for (const auto& [k, cnt] : occupied_list_)
      if (cnt > 1)
        add(ViolationKind::Overfull, cell_at(k), cell_at(k),
            "leaf " + to_string<d>(cell_at(k)) + " holds " + std::to_string(cnt) + " points (at most 1 allowed)");
    for (std::size_t k = 0, j = 0; k < nl_; ++k) {
      while (j < occupied_list_.size() && occupied_list_[j].first < k) ++j;
      const std::uint32_t cnt = j < occupied_list_.size() && occupied_list_[j].first == k ? occupied_list_[j].second : 0;
      if (cnt != leaves_[order_[k]].npoints)
        add(ViolationKind::CountMismatch, cell_at(k), cell_at(k),
            "leaf " + to_string<d>(cell_at(k)) + " says npoints = " + std::to_string(leaves_[order_[k]].npoints) +
                " but holds " + std::to_string(cnt));
    }
    index_.emplace(std::move(valid_points));
  }

  // --- The rules. ----------------------------------------------------------------------------

  /// Grading (rule 3): every level m−1 cell touching a split level-m cell is split. Those
  /// cells include the parent of every split cell; they are marked forced, which is what
  /// check_minimality needs.
  void check_grading() {
    CellSet<d> reported;
    for (int m = 1; m <= max_split_; ++m)
      for (const CellId<d>& s : split_by_level_[static_cast<std::size_t>(m)])
        for_each_coarser_touching(s, [&](const CellId<d>& u) {
          if (std::uint16_t* v = split_.find(u)) {
            *v = static_cast<std::uint16_t>(*v | kForced);
            return;
          }
          const CellId<d> b = leaf_of(split_, u);
          if (!reported.insert(b)) return;
          add(ViolationKind::Grading, b, s,
              "leaf " + to_string<d>(b) + " touches split cell " + to_string<d>(s) +
                  ", so it touches leaves two or more levels smaller");
        });
  }

  /// Separation (no two touching leaves both hold points) and crowding (rule 1: no leaf is
  /// crowded), in one pass over the neighbourhood of each occupied leaf a. A same-level
  /// neighbour nb is either split (its points, if any, are found by the Morton index; only
  /// then can a leaf inside it that touches a be occupied) or lies in a leaf b that touches
  /// a, whose first point tells whether nb holds a point.
  void check_separation_and_crowding() {
    std::vector<CellId<d>> touching_occupied, stack;
    for (const auto& [k, cnt] : occupied_list_) {
      const CellId<d>& a = cell_at(k);
      bool crowded = false;
      touching_occupied.clear();
      detail::for_each_touching_leaf<d>(
          a, [&](const CellId<d>& cell) { return split_.contains(cell); },
          [&](const CellId<d>& nb) {  // only a split neighbour with points can hide an occupied leaf
            if (!index_->any(nb)) return false;
            crowded = true;
            return true;
          },
          [&](const CellId<d>& leaf) {
            if (occupied_.contains(leaf)) touching_occupied.push_back(leaf);
          },
          [&](const CellId<d>& b, const CellId<d>& nb) {
            if (const Occupied* o = occupied_.find(b)) {
              touching_occupied.push_back(b);
              if (contains(nb, points_[o->point])) crowded = true;
            }
          },
          stack);
      std::sort(touching_occupied.begin(), touching_occupied.end());
      touching_occupied.erase(std::unique(touching_occupied.begin(), touching_occupied.end()), touching_occupied.end());
      for (const CellId<d>& b : touching_occupied)
        if (a < b)
          add(ViolationKind::TouchingOccupied, a, b,
              "touching leaves " + to_string<d>(a) + " and " + to_string<d>(b) + " both hold points");
      if (crowded && cnt == 1)  // overfull leaves are reported (and crowded) already
        add(ViolationKind::CrowdedLeaf, a, a,
            "leaf " + to_string<d>(a) + " holds a point and its neighbourhood holds another: it is crowded "
            "but not split");
    }
  }

  /// Minimality: every split is crowded, forced by a deeper split, or coarser than
  /// split_below (which also makes every leaf coarser than it wrong).
  void check_minimality() {
    for (const Leaf<d>& leaf : leaves_)
      if (leaf.cell.level < split_below_)
        add(ViolationKind::CrowdedLeaf, leaf.cell, leaf.cell,
            "leaf " + to_string<d>(leaf.cell) + " is coarser than level " + std::to_string(split_below_) +
                ", where every cell is split");
    for (const auto& level : split_by_level_)
      for (const CellId<d>& s : level) {
        if (*split_.find(s) & kForced || s.level < split_below_) continue;
        const std::size_t k = index_->count(s);
        if (k >= 2 || (k == 1 && neighbours_hold_points(s))) continue;
        add(ViolationKind::UnjustifiedSplit, s, s,
            "split cell " + to_string<d>(s) +
                " is not crowded, has no split child and touches no split cell one level smaller");
      }
  }

  /// Records a violation, or only that there were more than max_violations.
  void add(ViolationKind kind, const CellId<d>& cell, const CellId<d>& other, std::string msg) {
    if (report.violations.size() < max_violations_)
      report.violations.push_back(Violation<d>{kind, cell, other, std::move(msg)});
    else
      report.truncated = true;
  }

 private:
  static constexpr std::uint16_t kForced = 1u << 8;
  static constexpr std::size_t kNotALeaf = std::numeric_limits<std::size_t>::max();

  struct Occupied {
    std::uint32_t position = 0;  // in `order_`
    std::uint32_t count = 0;
    std::uint32_t point = 0;  // the first point found in it
  };

  const CellId<d>& cell_at(std::size_t k) const { return leaves_[order_[k]].cell; }

  /// c's position in `order_`, or kNotALeaf.
  std::size_t find_leaf(const CellId<d>& c) const {
    std::size_t lo = 0, hi = nl_;
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (cell_at(mid) < c)
        lo = mid + 1;
      else
        hi = mid;
    }
    return lo < nl_ && cell_at(lo) == c ? lo : kNotALeaf;
  }

  /// Registers the edge c → parent(c), inserting parent(c) and, if it is new, its ancestors.
  void attach(CellId<d> c) {
    while (c.level > 0) {
      const CellId<d> p = parent(c);
      const auto [mask, fresh] = split_.try_emplace(p, 0);
      *mask = static_cast<std::uint16_t>(*mask | (1u << child_number(c)));
      if (!fresh) return;
      split_by_level_[static_cast<std::size_t>(p.level)].push_back(p);
      c = p;
    }
  }

  bool holds_point(const CellId<d>& c) const {
    if (split_.contains(c)) return index_->any(c);
    const Occupied* o = occupied_.find(leaf_of(split_, c));
    return o != nullptr && contains(c, points_[o->point]);
  }

  bool neighbours_hold_points(const CellId<d>& c) const {
    bool found = false;
    for_each_neighbour(c, [&](const CellId<d>& nb) {
      if (!found && holds_point(nb)) found = true;
    });
    return found;
  }

  std::span<const Position<d>> points_;
  std::span<const Leaf<d>> leaves_;
  std::size_t max_violations_;
  int split_below_ = 0;
  std::size_t nl_;
  std::vector<std::uint32_t> order_;
  CellTable<d, std::uint16_t> split_;
  std::vector<std::vector<CellId<d>>> split_by_level_;
  int max_split_ = -1;
  std::size_t edges_ = 0;
  CellTable<d, Occupied> occupied_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> occupied_list_;  // (position, count)
  std::optional<MortonIndex<d>> index_;
};

}  // namespace

template <std::size_t d>
CheckReport<d> check_tree(std::span<const Position<d>> points, std::span<const Leaf<d>> leaves,
                          std::size_t max_violations, int split_below) {
  TreeCheck<d> check(points, leaves, max_violations, split_below);
  if (leaves.empty()) {
    check.add(ViolationKind::Gap, CellId<d>::root(), CellId<d>::root(), "no leaves: the box is not covered");
    return std::move(check.report);
  }
  if (leaves.size() >= std::numeric_limits<std::uint32_t>::max()) throw std::length_error("check_tree: too many leaves");
  // The structure first: the later phases assume a tiling of the box by distinct cells.
  if (!check.leaves_are_cells() || !check.order_leaves()) return std::move(check.report);
  check.build_split_set();
  if (!check.leaves_tile_the_box()) return std::move(check.report);
  check.check_occupancy();
  check.check_grading();
  check.check_separation_and_crowding();
  check.check_minimality();
  return std::move(check.report);
}

template <std::size_t d>
void require_valid_tree(std::span<const Position<d>> points, std::span<const Leaf<d>> leaves, int split_below) {
  const CheckReport<d> rep = check_tree<d>(points, leaves, 64, split_below);
  if (!rep.ok()) throw InvariantError("quadtree contract violated:\n" + rep.summary());
}

template class StaticQuadtree<2>;
template class StaticQuadtree<3>;
template struct CheckReport<2>;
template struct CheckReport<3>;
template CheckReport<2> check_tree<2>(std::span<const Position<2>>, std::span<const Leaf<2>>, std::size_t, int);
template CheckReport<3> check_tree<3>(std::span<const Position<3>>, std::span<const Leaf<3>>, std::size_t, int);
template void require_valid_tree<2>(std::span<const Position<2>>, std::span<const Leaf<2>>, int);
template void require_valid_tree<3>(std::span<const Position<3>>, std::span<const Leaf<3>>, int);

}  // namespace dynmesh
