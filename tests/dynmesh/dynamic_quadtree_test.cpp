// dynamic_quadtree_test.cpp — the self-adjusting quadtree/octree against the static oracle.
//
// Differential after every update (single insertions and deletions, by id and by coordinates,
// and batches through apply()) on every distribution; history independence (an edited tree
// equals a fresh one, including the size of its trace); a stability smoke test of the trace
// distance; bad input leaving the state as it was; the query API; empty and tiny sets; and
// the checkers themselves: a corrupted directory, tree or point index must fail
// check_invariants() (through the test-only DynamicQuadtreeTestAccess).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "dynamic_test_support.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/io.hpp"
#include "dynmesh/static_quadtree.hpp"
#include "quadtree/dynamic_quadtree_state.hpp"  // dynmesh/src: the private state, for the hook below
#include "sac/splitmix64.hpp"

namespace dynmesh {

/// The test-only hook declared in DynamicQuadtree: its program state (engine, directory,
/// input list and indexes), so that the checker tests below can corrupt one part of it.
struct DynamicQuadtreeTestAccess {
  template <std::size_t d>
  static detail::DynamicState<d>& state(DynamicQuadtree<d>& tree) { return *tree.s_; }
};

}  // namespace dynmesh

namespace {

using namespace dynmesh;
using namespace dynmesh_test;
using Kind = InputError::Kind;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Scales a size down for slow (sanitizer, unoptimized) builds.
template <class T>
constexpr T scaled(T n, int slow_divisor = 3) {
  return kSlowBuild ? std::max<T>(n / static_cast<T>(slow_divisor), 8) : n;
}

template <std::size_t d>
std::vector<Point<d>> pick_points(const std::vector<Point<d>>& pool, const std::vector<std::size_t>& idx) {
  std::vector<Point<d>> out;
  out.reserve(idx.size());
  for (const auto i : idx) out.push_back(pool[i]);
  return out;
}

template <std::size_t d>
std::vector<Point<d>> list_of(const DynamicQuadtree<d>& tree) {
  std::vector<Point<d>> out;
  for (const auto& [id, p] : tree.points()) out.push_back(p);
  return out;
}

/// The pool indices of the points with the least and the greatest coordinate on each axis: a
/// set containing them has the same derived box as the pool, so every pool point lies inside.
template <std::size_t d>
std::vector<std::size_t> extremes(const std::vector<Point<d>>& pool) {
  std::set<std::size_t> s;
  for (std::size_t a = 0; a < d; ++a) {
    std::size_t lo = 0, hi = 0;
    for (std::size_t i = 1; i < pool.size(); ++i) {
      if (pool[i][a] < pool[lo][a]) lo = i;
      if (pool[i][a] > pool[hi][a]) hi = i;
    }
    s.insert(lo);
    s.insert(hi);
  }
  return {s.begin(), s.end()};
}

/// The extremes and each other pool index with probability `fraction`, in random order.
template <std::size_t d>
std::vector<std::size_t> random_subset(const std::vector<Point<d>>& pool, double fraction, Rng& rng) {
  std::vector<char> chosen(pool.size(), 0);
  for (const auto i : extremes(pool)) chosen[i] = 1;
  for (std::size_t i = 0; i < pool.size(); ++i)
    if (rng.uniform() < fraction) chosen[i] = 1;
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < pool.size(); ++i)
    if (chosen[i]) out.push_back(i);
  rng.shuffle(out);
  return out;
}

/// Everything the tree promises about its point set and its leaves, against the expected
/// points and the static oracle: size, ids, coordinates, positions, the leaves (exactly),
/// the leaves with their points, the counts, and check_invariants().
template <std::size_t d>
testing::AssertionResult consistent(const DynamicQuadtree<d>& tree, const PointMap<d>& want) {
  const Box<d>& box = tree.box();
  if (tree.size() != want.size())
    return testing::AssertionFailure() << "size() " << tree.size() << ", want " << want.size();
  const auto pts = tree.points();
  PointMap<d> got;
  for (const auto& [id, p] : pts)
    if (!got.emplace(id, p).second) return testing::AssertionFailure() << "points() lists id " << id << " twice";
  if (got != want) {
    std::size_t missing = 0, extra = 0, moved = 0;
    for (const auto& [id, p] : want) {
      const auto it = got.find(id);
      if (it == got.end()) ++missing;
      else if (it->second != p) ++moved;
    }
    for (const auto& [id, p] : got) extra += want.count(id) ? 0 : 1;
    return testing::AssertionFailure() << "points() differ: " << missing << " ids missing, " << extra << " extra, "
                                       << moved << " with other coordinates";
  }
  const auto pos = tree.positions();
  if (pos.size() != pts.size())
    return testing::AssertionFailure() << "positions() has " << pos.size() << " entries, points() " << pts.size();
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (pos[i] != locate(box, pts[i].second))
      return testing::AssertionFailure() << "positions()[" << i << "] is not the location of point " << pts[i].first;
  for (const auto& [id, p] : want) {
    if (!tree.contains(id)) return testing::AssertionFailure() << "contains(" << id << ") is false";
    if (tree.point(id) != p) return testing::AssertionFailure() << "point(" << id << ") is wrong";
    const auto f = tree.find(p);
    if (!f || *f != id) return testing::AssertionFailure() << "find(point " << id << ") is wrong";
  }

  const auto coords = coordinates(want);
  const auto oracle = StaticQuadtree<d>::from_points(box, coords);
  const std::vector<Leaf<d>> want_leaves(oracle.leaves().begin(), oracle.leaves().end());
  const auto leaves = tree.leaves();
  if (auto r = same_leaves<d>(leaves, want_leaves); !r) return r;
  if (tree.num_split() != oracle.num_split())
    return testing::AssertionFailure() << "num_split() " << tree.num_split() << ", oracle " << oracle.num_split();
  if (tree.num_leaves() != leaves.size())
    return testing::AssertionFailure() << "num_leaves() " << tree.num_leaves() << ", leaves() " << leaves.size();

  const auto lwp = tree.leaves_with_points();
  if (lwp.size() != leaves.size())
    return testing::AssertionFailure() << "leaves_with_points() has " << lwp.size() << " leaves, leaves() "
                                       << leaves.size();
  std::set<PointId> seen;
  for (std::size_t i = 0; i < lwp.size(); ++i) {
    if (lwp[i].cell != leaves[i].cell)
      return testing::AssertionFailure() << "leaves_with_points()[" << i << "] is " << to_string(lwp[i].cell)
                                         << ", leaves() has " << to_string(leaves[i].cell);
    if (lwp[i].points.size() != leaves[i].npoints)
      return testing::AssertionFailure() << "leaf " << to_string(lwp[i].cell) << " lists " << lwp[i].points.size()
                                         << " ids, npoints " << leaves[i].npoints;
    for (const auto id : lwp[i].points) {
      if (!seen.insert(id).second) return testing::AssertionFailure() << "id " << id << " in two leaves";
      const auto it = want.find(id);
      if (it == want.end()) return testing::AssertionFailure() << "leaf lists absent id " << id;
      if (!contains(lwp[i].cell, locate(box, it->second)))
        return testing::AssertionFailure() << "id " << id << " listed in " << to_string(lwp[i].cell)
                                           << ", which does not contain it";
    }
  }
  if (seen.size() != want.size())
    return testing::AssertionFailure() << "leaves_with_points() holds " << seen.size() << " ids, want " << want.size();
  return invariants_hold(tree);
}

// --- the differential driver -----------------------------------------------------------------

template <std::size_t d>
struct Scenario {
  Box<d> box;
  std::vector<Point<d>> pool;
  std::vector<std::size_t> initial;  // pool indices, in the tree's input order
};

template <std::size_t d>
Scenario<d> make_scenario(Distribution dist, std::size_t pool_size, std::uint64_t seed, double spread,
                          double fraction) {
  Scenario<d> s;
  s.pool = generate<d>(dist, pool_size, seed, spread);
  Rng rng(seed * sac::kGoldenGamma + 17);
  s.initial = random_subset(s.pool, fraction, rng);
  const auto init = pick_points(s.pool, s.initial);
  s.box = derive_box<d>(init);
  return s;
}

/// Drives a tree with random updates drawn from a pool of points and keeps the expected
/// point set beside it.
template <std::size_t d>
class Driver {
 public:
  explicit Driver(const Scenario<d>& s) : s_(s), tree_(s.box, pick_points(s.pool, s.initial)) {
    std::vector<char> in(s.pool.size(), 0);
    for (std::size_t k = 0; k < s.initial.size(); ++k) {
      const PointId id = k;  // construction: ids 0..n−1 in input order
      want_[id] = s.pool[s.initial[k]];
      pool_of_[id] = s.initial[k];
      present_.push_back(id);
      ever_.insert(id);
      in[s.initial[k]] = 1;
    }
    for (std::size_t i = 0; i < s.pool.size(); ++i)
      if (!in[i]) absent_.push_back(i);
  }

  DynamicQuadtree<d>& tree() { return tree_; }
  const PointMap<d>& want() const { return want_; }
  /// What the last step did.
  const std::string& last() const { return last_; }

  /// One random update: an insertion, an erase by id, an erase by coordinates, or a batch of
  /// 2..6 edits. Fails on a wrong id or an unexpected exception; candidates that the tree
  /// rejects as Duplicate/Resolution are skipped after checking that nothing changed.
  testing::AssertionResult step(Rng& rng) {
    const bool can_insert = !absent_.empty(), can_erase = !present_.empty();
    const std::uint64_t r = rng.below(100);
    try {
      if (can_insert && (!can_erase || r < 35)) return insert(rng);
      if (!can_erase) {
        last_ = "nothing to do";
        return testing::AssertionSuccess();
      }
      if (r < 60) return erase(rng, false);
      if (r < 75) return erase(rng, true);
      return batch(rng);
    } catch (const std::exception& e) {
      return testing::AssertionFailure() << last_ << ": unexpected exception: " << e.what();
    }
  }

 private:
  std::size_t take_absent(Rng& rng) {
    const std::size_t k = rng.below(absent_.size());
    const std::size_t i = absent_[k];
    absent_[k] = absent_.back();
    absent_.pop_back();
    return i;
  }
  PointId take_present(Rng& rng) {
    const std::size_t k = rng.below(present_.size());
    const PointId id = present_[k];
    present_[k] = present_.back();
    present_.pop_back();
    return id;
  }
  testing::AssertionResult added(PointId id, std::size_t i) {
    if (!ever_.insert(id).second) return testing::AssertionFailure() << last_ << ": id " << id << " reused";
    want_[id] = s_.pool[i];
    pool_of_[id] = i;
    present_.push_back(id);
    return testing::AssertionSuccess();
  }
  void removed(PointId id) {
    absent_.push_back(pool_of_.at(id));
    want_.erase(id);
    pool_of_.erase(id);
  }
  static bool skippable(const InputError& e) {
    return e.kind() == Kind::Duplicate || e.kind() == Kind::Resolution;
  }

  testing::AssertionResult insert(Rng& rng) {
    const std::size_t i = take_absent(rng);
    last_ = "insert pool[" + std::to_string(i) + "] " + to_string<d>(s_.pool[i]);
    const auto before = snapshot(tree_);
    PointId id = 0;
    try {
      id = tree_.insert(s_.pool[i]);
    } catch (const InputError& e) {
      if (!skippable(e)) return testing::AssertionFailure() << last_ << ": " << kind_name(e.kind()) << ": " << e.what();
      last_ += " (rejected: " + std::string(e.what()) + ")";
      if (auto u = unchanged(tree_, before); !u) return u << " after a rejected insertion";
      return testing::AssertionSuccess();  // the candidate stays out of the pool
    }
    return added(id, i);
  }

  testing::AssertionResult erase(Rng& rng, bool by_coordinates) {
    const PointId id = take_present(rng);
    last_ = std::string(by_coordinates ? "erase coordinates " : "erase id ") + std::to_string(id) + " " +
            to_string<d>(want_.at(id));
    if (by_coordinates)
      tree_.erase(want_.at(id));
    else
      tree_.erase(id);
    removed(id);
    return testing::AssertionSuccess();
  }

  testing::AssertionResult batch(Rng& rng) {
    const std::size_t k = 2 + rng.below(5);
    std::vector<Edit<d>> edits;
    std::vector<std::size_t> inserted;  // pool indices of the insertions, in edit order
    std::vector<PointId> erased;
    last_ = "batch:";
    for (std::size_t j = 0; j < k; ++j) {
      const bool ins = !absent_.empty() && (present_.empty() || rng.below(2) == 0);
      if (ins) {
        const std::size_t i = take_absent(rng);
        inserted.push_back(i);
        edits.push_back({EditOp::Insert, s_.pool[i]});
        last_ += " +pool[" + std::to_string(i) + "]";
      } else if (!present_.empty()) {
        const PointId id = take_present(rng);
        erased.push_back(id);
        edits.push_back({EditOp::Delete, want_.at(id)});
        last_ += " -id" + std::to_string(id);
      }
    }
    const auto before = snapshot(tree_);
    std::vector<PointId> ids;
    try {
      ids = tree_.apply(edits);
    } catch (const InputError& e) {
      if (!skippable(e)) return testing::AssertionFailure() << last_ << ": " << kind_name(e.kind()) << ": " << e.what();
      last_ += " (rejected: " + std::string(e.what()) + ")";
      if (auto u = unchanged(tree_, before); !u) return u << " after a rejected batch";
      for (const auto id : erased) present_.push_back(id);  // the insertions stay out of the pool
      return testing::AssertionSuccess();
    }
    if (ids.size() != inserted.size())
      return testing::AssertionFailure() << last_ << ": apply() returned " << ids.size() << " ids for "
                                         << inserted.size() << " insertions";
    for (const auto id : erased) removed(id);
    for (std::size_t j = 0; j < ids.size(); ++j)
      if (auto r = added(ids[j], inserted[j]); !r) return r;
    return testing::AssertionSuccess();
  }

  const Scenario<d>& s_;
  DynamicQuadtree<d> tree_;
  PointMap<d> want_;
  std::map<PointId, std::size_t> pool_of_;
  std::vector<PointId> present_;
  std::vector<std::size_t> absent_;
  std::set<PointId> ever_;
  std::string last_;
};

struct DiffCase {
  std::size_t pool;      // points generated; about half start in the tree
  int updates;           // random updates
  std::uint64_t seed;
  double spread = 0x1p20;
  double fraction = 0.5;  // share of the pool in the initial tree
  int check_every = 1;    // compare with the oracle after every k-th update (and the last)
  int compact_every = 0;  // compact() after every k-th update (0: never)
};

template <std::size_t d>
void run_differential(Distribution dist, const DiffCase& c) {
  SCOPED_TRACE(std::string(distribution_name(dist)) + " d=" + std::to_string(d) + " pool=" + std::to_string(c.pool) +
               " seed=" + std::to_string(c.seed) + " spread=2^" + std::to_string(std::lround(std::log2(c.spread))));
  const auto s = make_scenario<d>(dist, c.pool, c.seed, c.spread, c.fraction);
  ASSERT_EQ(s.box, derive_box<d>(s.pool)) << "the initial set must hold the extremes";
  Driver<d> drv(s);
  ASSERT_TRUE(consistent(drv.tree(), drv.want())) << "after construction on " << s.initial.size() << " points";
  Rng rng(c.seed + 1000);
  for (int step = 1; step <= c.updates; ++step) {
    SCOPED_TRACE("step " + std::to_string(step));
    ASSERT_TRUE(drv.step(rng));
    if (c.compact_every && step % c.compact_every == 0) {
      drv.tree().compact();
      ASSERT_TRUE(invariants_hold(drv.tree())) << "after compact()";
    }
    if (step % c.check_every == 0 || step == c.updates) {
      ASSERT_TRUE(consistent(drv.tree(), drv.want())) << "after " << drv.last();
    }
  }
}

template <class T>
class DynamicQuadtreeDifferential : public testing::Test {};
template <class T>
class DynamicQuadtreeHistory : public testing::Test {};
template <class T>
class DynamicQuadtreeBadInput : public testing::Test {};
template <class T>
class DynamicQuadtreeApi : public testing::Test {};
template <class T>
class DynamicQuadtreeTiny : public testing::Test {};

using Dims = testing::Types<std::integral_constant<std::size_t, 2>, std::integral_constant<std::size_t, 3>>;
struct DimName {
  template <class T>
  static std::string GetName(int) {
    return "d" + std::to_string(T::value);
  }
};
TYPED_TEST_SUITE(DynamicQuadtreeDifferential, Dims, DimName);
TYPED_TEST_SUITE(DynamicQuadtreeHistory, Dims, DimName);
TYPED_TEST_SUITE(DynamicQuadtreeBadInput, Dims, DimName);
TYPED_TEST_SUITE(DynamicQuadtreeApi, Dims, DimName);
TYPED_TEST_SUITE(DynamicQuadtreeTiny, Dims, DimName);
template <class T>
class DynamicQuadtreeCheckers : public testing::Test {};
TYPED_TEST_SUITE(DynamicQuadtreeCheckers, Dims, DimName);

/// The default differential case of dimension d: about 150 points in 2D and 50 in 3D (the
/// octree of 50 points is as large as the quadtree of 150), 100 and 50 updates. Sizes are set
/// by the cost of check_invariants(), which walks the whole trace after every update.
template <std::size_t d>
DiffCase small_case(std::uint64_t seed, double spread = 0x1p20) {
  if constexpr (d == 2)
    return {scaled(std::size_t{300}), scaled(100), seed, spread};
  else
    return {scaled(std::size_t{100}), scaled(50), seed, spread};
}

TYPED_TEST(DynamicQuadtreeDifferential, Uniform) {
  constexpr std::size_t d = TypeParam::value;
  run_differential<d>(Distribution::Uniform, small_case<d>(101));
}

TYPED_TEST(DynamicQuadtreeDifferential, Clusters) {
  constexpr std::size_t d = TypeParam::value;
  run_differential<d>(Distribution::Clusters, small_case<d>(201));
  run_differential<d>(Distribution::Clusters, small_case<d>(202));
}

TYPED_TEST(DynamicQuadtreeDifferential, Shrinking) {
  constexpr std::size_t d = TypeParam::value;
  run_differential<d>(Distribution::Shrinking, small_case<d>(301, 0x1p20));
  run_differential<d>(Distribution::Shrinking, small_case<d>(302, 0x1p40));
}

TYPED_TEST(DynamicQuadtreeDifferential, Grid) {
  constexpr std::size_t d = TypeParam::value;
  run_differential<d>(Distribution::Grid, small_case<d>(401));
}

TYPED_TEST(DynamicQuadtreeDifferential, Collinear) {
  constexpr std::size_t d = TypeParam::value;
  run_differential<d>(Distribution::Collinear, small_case<d>(501));
}

TYPED_TEST(DynamicQuadtreeDifferential, Boundary) {
  constexpr std::size_t d = TypeParam::value;
  run_differential<d>(Distribution::Boundary, small_case<d>(601));
  run_differential<d>(Distribution::Boundary, small_case<d>(602));
}

TYPED_TEST(DynamicQuadtreeDifferential, Spiral) {
  constexpr std::size_t d = TypeParam::value;
  run_differential<d>(Distribution::Spiral, small_case<d>(701));
}

TYPED_TEST(DynamicQuadtreeDifferential, SparseStartGrowsFromFewPoints) {
  // A tree that starts with little more than the extremes and grows by insertions.
  constexpr std::size_t d = TypeParam::value;
  DiffCase c = small_case<d>(801);
  c.fraction = 0.05;
  run_differential<d>(Distribution::Clusters, c);
  c.seed = 802;
  c.fraction = 0.95;  // and one that starts nearly full and mostly shrinks
  run_differential<d>(Distribution::Shrinking, c);
}

TYPED_TEST(DynamicQuadtreeDifferential, CompactionBetweenUpdates) {
  // compact() frees the slots and point nodes the trace no longer refers to. A list's end
  // is never written and an empty child's list may never be read, so these stay unused
  // while the trace still points at them (a partition step's destinations); freeing them
  // would let a later re-execution write through a dangling pointer (the sanitizer job
  // sees it). Compacting after every few updates must keep every state exact.
  constexpr std::size_t d = TypeParam::value;
  for (const Distribution dist : {Distribution::Uniform, Distribution::Clusters, Distribution::Shrinking}) {
    DiffCase c = small_case<d>(1701 + static_cast<std::uint64_t>(dist));
    c.compact_every = 3;
    run_differential<d>(dist, c);
  }
}

TYPED_TEST(DynamicQuadtreeDifferential, Large) {
  // About 4000 points in 2D (clusters, shrinking to 2^40) and 2000 in 3D (uniform), compared
  // after every 10th update.
  constexpr std::size_t d = TypeParam::value;
  if constexpr (d == 2) {
    DiffCase c{scaled(std::size_t{4400}, 4), scaled(40, 2), 901};
    c.fraction = 0.9;
    c.check_every = 10;
    run_differential<d>(Distribution::Clusters, c);
    c.seed = 902;
    c.spread = 0x1p40;
    run_differential<d>(Distribution::Shrinking, c);
  } else {
    DiffCase c{scaled(std::size_t{2200}, 4), 20, 903};
    c.fraction = 0.9;
    c.check_every = 10;
    run_differential<d>(Distribution::Uniform, c);
  }
}

// --- batches -----------------------------------------------------------------------------------

TYPED_TEST(DynamicQuadtreeDifferential, BatchesApplyEditsInOrder) {
  // Within one batch a point may be inserted and erased again, or erased and inserted again;
  // every inserted point gets an id (in edit order), even if a later edit erases it.
  constexpr std::size_t d = TypeParam::value;
  const auto pool = generate<d>(Distribution::Clusters, 120, 31);
  Rng rng(32);
  auto init_idx = random_subset(pool, 0.5, rng);
  const Box<d> box = derive_box<d>(pool);
  std::vector<char> in(pool.size(), 0);
  for (const auto i : init_idx) in[i] = 1;
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < pool.size(); ++i)
    if (!in[i]) out.push_back(i);
  ASSERT_GE(out.size(), 3u);
  DynamicQuadtree<d> tree(box, pick_points(pool, init_idx));
  PointMap<d> want;
  for (std::size_t k = 0; k < init_idx.size(); ++k) want[k] = pool[init_idx[k]];

  const Point<d> a = pool[out[0]], b = pool[out[1]], c = pool[out[2]];
  const Point<d> x = want.at(0), y = want.at(1);
  const std::vector<Edit<d>> edits = {
      {EditOp::Insert, a}, {EditOp::Delete, a}, {EditOp::Delete, x}, {EditOp::Insert, x},
      {EditOp::Insert, b}, {EditOp::Delete, y}, {EditOp::Insert, c},
  };
  const auto ids = tree.apply(edits);
  ASSERT_EQ(ids.size(), 4u);
  EXPECT_EQ(std::set<PointId>(ids.begin(), ids.end()).size(), 4u) << "ids must be distinct";
  for (const auto id : ids) EXPECT_EQ(want.count(id), 0u) << "id " << id << " reused";
  EXPECT_FALSE(tree.contains(ids[0]));
  EXPECT_FALSE(tree.contains(0));
  EXPECT_FALSE(tree.contains(1));
  want.erase(0);
  want.erase(1);
  want[ids[1]] = x;
  want[ids[2]] = b;
  want[ids[3]] = c;
  EXPECT_TRUE(consistent(tree, want));

  // An empty batch changes nothing.
  const auto before = snapshot(tree);
  EXPECT_TRUE(tree.apply(std::span<const Edit<d>>{}).empty());
  EXPECT_TRUE(unchanged(tree, before));
}

// --- history independence ----------------------------------------------------------------------

/// Builds A on P from scratch and B on Q, edits B into P (singly or as one batch), and
/// compares: the leaves exactly, the leaves' points by coordinates, and B's trace with that
/// of a fresh tree built on B's input list.
template <std::size_t d>
void edited_equals_fresh(Distribution dist, std::size_t pool_size, std::uint64_t seed, double spread,
                         bool as_batch) {
  SCOPED_TRACE(std::string(distribution_name(dist)) + " d=" + std::to_string(d) + " pool=" +
               std::to_string(pool_size) + " seed=" + std::to_string(seed) + (as_batch ? " batch" : " single"));
  const auto pool = generate<d>(dist, pool_size, seed, spread);
  const Box<d> box = derive_box<d>(pool);
  Rng rng(seed + 7);
  const auto p_idx = random_subset(pool, 0.5, rng);
  const auto q_idx = random_subset(pool, 0.5, rng);
  DynamicQuadtree<d> a(box, pick_points(pool, p_idx));
  DynamicQuadtree<d> b(box, pick_points(pool, q_idx));

  std::vector<char> in_p(pool.size(), 0), in_q(pool.size(), 0);
  for (const auto i : p_idx) in_p[i] = 1;
  for (const auto i : q_idx) in_q[i] = 1;
  std::vector<Edit<d>> edits;
  for (std::size_t i = 0; i < pool.size(); ++i) {
    if (in_q[i] && !in_p[i]) edits.push_back({EditOp::Delete, pool[i]});
    if (in_p[i] && !in_q[i]) edits.push_back({EditOp::Insert, pool[i]});
  }
  rng.shuffle(edits);
  ASSERT_GT(edits.size(), 10u);
  if (as_batch) {
    b.apply(edits);
  } else {
    for (const auto& e : edits) {
      if (e.op == EditOp::Insert)
        b.insert(e.point);
      else
        b.erase(e.point);
    }
  }
  ASSERT_TRUE(invariants_hold(b));
  EXPECT_TRUE(same_leaves<d>(b.leaves(), a.leaves()));
  EXPECT_EQ(b.num_split(), a.num_split());
  EXPECT_TRUE(leaves_by_coordinates(b) == leaves_by_coordinates(a)) << "the leaves hold different points";
  auto pa = list_of(a), pb = list_of(b);
  std::sort(pa.begin(), pa.end());
  std::sort(pb.begin(), pb.end());
  EXPECT_EQ(pa, pb);

  // The live trace equals that of a from-scratch run on the same input list.
  const DynamicQuadtree<d> fresh(box, list_of(b));
  EXPECT_TRUE(same_leaves<d>(fresh.leaves(), b.leaves()));
  EXPECT_EQ(b.live_events(), fresh.live_events());
  EXPECT_EQ(b.record_bytes(), fresh.record_bytes());
  if (a.live_events() != b.live_events())
    std::printf("    [%s d=%zu] note: live events depend on the input order: %llu (P order) vs %llu (edited)\n",
                std::string(distribution_name(dist)).c_str(), d, static_cast<unsigned long long>(a.live_events()),
                static_cast<unsigned long long>(b.live_events()));
}

TYPED_TEST(DynamicQuadtreeHistory, EditedTreeEqualsFreshTree) {
  constexpr std::size_t d = TypeParam::value;
  const std::size_t n = d == 2 ? scaled(std::size_t{400}) : scaled(std::size_t{150});
  std::uint64_t seed = 1100;
  for (const Distribution dist : all_distributions()) {
    const double spread = dist == Distribution::Shrinking ? 0x1p40 : 0x1p20;
    edited_equals_fresh<d>(dist, n, ++seed, spread, false);
    edited_equals_fresh<d>(dist, n, ++seed, spread, true);
  }
}

TYPED_TEST(DynamicQuadtreeHistory, InsertThenEraseRestoresEverything) {
  // Inserting a point and erasing it again restores the leaves, the point list, the
  // positions and the trace size exactly.
  constexpr std::size_t d = TypeParam::value;
  for (const Distribution dist : {Distribution::Uniform, Distribution::Shrinking, Distribution::Boundary}) {
    const std::uint64_t seed = 1200 + static_cast<std::uint64_t>(dist);
    SCOPED_TRACE(std::string(distribution_name(dist)) + " seed=" + std::to_string(seed));
    const auto s = make_scenario<d>(dist, d == 2 ? 300 : 120, seed, 0x1p40, 0.5);
    DynamicQuadtree<d> tree(s.box, pick_points(s.pool, s.initial));
    std::vector<char> in(s.pool.size(), 0);
    for (const auto i : s.initial) in[i] = 1;
    int tried = 0;
    for (std::size_t i = 0; i < s.pool.size() && tried < scaled(25); ++i) {
      if (in[i]) continue;
      ++tried;
      SCOPED_TRACE("pool[" + std::to_string(i) + "] " + to_string<d>(s.pool[i]));
      const auto before = snapshot(tree);
      const PointId id = tree.insert(s.pool[i]);
      EXPECT_GT(tree.last_update().trace_distance, 0u);
      tree.erase(id);
      ASSERT_TRUE(unchanged(tree, before));
    }
    ASSERT_TRUE(invariants_hold(tree));
  }
}

TYPED_TEST(DynamicQuadtreeHistory, EraseThenReinsertGivesTheSameTree) {
  // Erasing a present point and inserting it again gives the same leaves (the point has a
  // new id and may move in the input list), and the trace of a fresh run on the new list.
  constexpr std::size_t d = TypeParam::value;
  const auto s = make_scenario<d>(Distribution::Clusters, d == 2 ? 300 : 120, 1300, 0x1p20, 0.8);
  DynamicQuadtree<d> tree(s.box, pick_points(s.pool, s.initial));
  Rng rng(1301);
  for (int t = 0; t < scaled(20); ++t) {
    SCOPED_TRACE("round " + std::to_string(t));
    const auto before = leaves_by_coordinates(tree);
    const auto leaves = tree.leaves();
    const auto pts = tree.points();
    const auto [old_id, p] = pts[rng.below(pts.size())];
    tree.erase(old_id);
    const PointId id = tree.insert(p);
    EXPECT_NE(id, old_id);
    EXPECT_FALSE(tree.contains(old_id));
    EXPECT_EQ(tree.find(p), std::optional<PointId>(id));
    ASSERT_TRUE(same_leaves<d>(tree.leaves(), leaves));
    ASSERT_TRUE(leaves_by_coordinates(tree) == before);
  }
  ASSERT_TRUE(invariants_hold(tree));
  const DynamicQuadtree<d> fresh(s.box, list_of(tree));
  EXPECT_EQ(tree.live_events(), fresh.live_events());
  EXPECT_EQ(tree.record_bytes(), fresh.record_bytes());
  tree.compact();
  DynamicQuadtree<d> fresh2(s.box, list_of(tree));
  fresh2.compact();
  EXPECT_EQ(tree.live_events(), fresh2.live_events()) << "after compact()";
  EXPECT_EQ(tree.record_bytes(), fresh2.record_bytes()) << "after compact()";
}

// --- stability ---------------------------------------------------------------------------------

struct StabilityFigures {
  double mean = 0;
  std::uint64_t max = 0;
  std::uint64_t live = 0;  // live events at the end
};

/// 50 updates (an insertion of a new point, then an erasure of a random present point, in
/// turn) on uniform points in 2D; with max_fraction_divisor k > 0, each update's trace
/// distance must stay below live/k. The tree is checked against the oracle at the end.
StabilityFigures stability_run(std::size_t n, std::uint64_t seed, std::uint64_t max_fraction_divisor) {
  SCOPED_TRACE("uniform n=" + std::to_string(n) + " seed=" + std::to_string(seed));
  // Under SAC_DEBUG_CHECKS every update checks the whole tree (seconds at n = 4000 at -O0).
  constexpr int kUpdates = kDebugChecks ? 10 : 50;
  const auto pool = generate<2>(Distribution::Uniform, n + kUpdates / 2, seed);
  Rng rng(seed + 1);
  // All but kUpdates/2 points (none an extreme) start in the tree.
  std::vector<char> in(pool.size(), 1);
  std::vector<char> extreme(pool.size(), 0);
  for (const auto i : extremes(pool)) extreme[i] = 1;
  std::vector<std::size_t> later;
  while (later.size() < kUpdates / 2) {
    const std::size_t i = rng.below(pool.size());
    if (in[i] && !extreme[i]) {
      in[i] = 0;
      later.push_back(i);
    }
  }
  std::vector<std::size_t> init;
  for (std::size_t i = 0; i < pool.size(); ++i)
    if (in[i]) init.push_back(i);
  DynamicQuadtree<2> tree(derive_box<2>(pool), pick_points(pool, init));
  std::vector<PointId> ids;
  for (PointId id = 0; id < init.size(); ++id) ids.push_back(id);
  StabilityFigures f;
  double sum = 0;
  for (int k = 0; k < kUpdates; ++k) {
    if (k % 2 == 0) {
      ids.push_back(tree.insert(pool[later[static_cast<std::size_t>(k / 2)]]));
    } else {
      const std::size_t j = rng.below(ids.size());
      tree.erase(ids[j]);
      ids[j] = ids.back();
      ids.pop_back();
    }
    const std::uint64_t td = tree.last_update().trace_distance;
    EXPECT_GT(td, 0u) << "update " << k;
    if (max_fraction_divisor) {
      EXPECT_LT(td, tree.live_events() / max_fraction_divisor)
          << "update " << k << " re-executed a large share of the trace (live " << tree.live_events() << ")";
    }
    sum += static_cast<double>(td);
    f.max = std::max(f.max, td);
  }
  f.mean = sum / kUpdates;
  f.live = tree.live_events();
  EXPECT_TRUE(invariants_hold(tree));
  EXPECT_TRUE(same_leaves<2>(tree.leaves(), oracle_leaves<2>(tree.box(), list_of(tree))));
  return f;
}

/// Mean trace distance of a single update on uniform 2D points: a bound well above what an
/// O(lg L/s) update re-executes at these sizes.
constexpr double kTraceDistanceBound = 3000;

TEST(DynamicQuadtreeStability, TraceDistanceDoesNotGrowWithN) {
  // O(lg L/s) per update: quadrupling n adds about one level to a uniform set's tree, so the
  // mean trace distance may grow a little but not in proportion to n. From n = 2000 on, every
  // single update must re-execute far less than the whole trace (trace distance < live/20).
  // Not scaled down in slow builds: the figures are deterministic (but stability_run makes
  // fewer updates under SAC_DEBUG_CHECKS).
  const auto a = stability_run(1000, 1401, 0);
  const auto m = stability_run(2000, 1402, 20);
  const auto b = stability_run(4000, 1402, 20);
  for (const auto& [n, f] : {std::pair{1000, a}, std::pair{2000, m}, std::pair{4000, b}})
    std::printf("    [uniform 2D] n=%d: mean trace distance %.0f, max %llu, live %llu\n", n, f.mean,
                static_cast<unsigned long long>(f.max), static_cast<unsigned long long>(f.live));
  EXPECT_LE(b.mean, 1.5 * a.mean) << "the mean trace distance grows with n";
  // An absolute bound well above a correct update's: a regression that makes an update
  // re-scan whole point lists exceeds it at once.
  EXPECT_LT(a.mean, kTraceDistanceBound);
  EXPECT_LT(m.mean, kTraceDistanceBound);
  EXPECT_LT(b.mean, kTraceDistanceBound);
  EXPECT_LT(b.mean, static_cast<double>(b.live) / 100) << "a mean update touches a large share of the trace";
}

// --- bad input -----------------------------------------------------------------------------

/// Runs f, which must throw InputError of kind `want` and leave the tree as it was. Returns
/// the message.
template <std::size_t d, class F>
std::string expect_rejected(DynamicQuadtree<d>& tree, Kind want, const std::string& what, F&& f) {
  SCOPED_TRACE(what);
  const auto before = snapshot(tree);
  std::string msg;
  try {
    f();
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(kind_name(e.kind()), kind_name(want)) << e.what();
    msg = e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an InputError: " << e.what();
  }
  EXPECT_TRUE(unchanged(tree, before));
  EXPECT_TRUE(invariants_hold(tree));
  return msg;
}

/// A point with other coordinates than p but the same located position (one ulp away).
template <std::size_t d>
std::optional<Point<d>> same_position_twin(const Box<d>& box, const Point<d>& p) {
  const auto q = locate(box, p);
  for (const double dir : {kInf, -kInf}) {
    Point<d> x = p;
    x[0] = std::nextafter(p[0], dir);
    if (const auto r = try_locate(box, x); r && *r == q) return x;
  }
  return std::nullopt;
}

/// A point whose located position is p's plus one grid unit on axis 0.
template <std::size_t d>
std::optional<Point<d>> next_position(const Box<d>& box, const Point<d>& p) {
  const auto q = locate(box, p);
  Point<d> x = p;
  for (int k = 0; k < (1 << 24); ++k) {
    x[0] = std::nextafter(x[0], kInf);
    const auto r = try_locate(box, x);
    if (!r) return std::nullopt;
    if (*r != q) {
      auto want = q;
      ++want[0];
      if (*r == want) return x;
      return std::nullopt;
    }
  }
  return std::nullopt;
}

template <std::size_t d>
Point<d> filled(double v) {
  Point<d> p;
  p.fill(v);
  return p;
}

TYPED_TEST(DynamicQuadtreeBadInput, RejectedUpdatesChangeNothing) {
  constexpr std::size_t d = TypeParam::value;
  const auto s = make_scenario<d>(Distribution::Uniform, 120, 1500, 0x1p20, 0.7);
  const Box<d>& box = s.box;
  const auto init = pick_points(s.pool, s.initial);
  DynamicQuadtree<d> tree(box, init);
  DynamicQuadtree<d> twin(box, init);  // gets only the valid updates
  PointMap<d> want;
  for (std::size_t k = 0; k < init.size(); ++k) want[k] = init[k];
  // A present point away from 0 (so that an ulp is far below a grid unit).
  PointId pid = 0;
  while (std::abs(want.at(pid)[0]) < 0.25) ++pid;
  const Point<d> p = want.at(pid);
  Point<d> mid = p;

  // NaN and infinities, in every axis.
  for (std::size_t a = 0; a < d; ++a)
    for (const double v : {kNaN, kInf, -kInf}) {
      Point<d> x = mid;
      x[a] = v;
      expect_rejected(tree, Kind::NotFinite, "insert " + to_string<d>(x), [&] { tree.insert(x); });
    }
  // Duplicates: the same coordinates, and other coordinates with the same located position.
  expect_rejected(tree, Kind::Duplicate, "insert a present point", [&] { tree.insert(p); });
  const auto twin_p = same_position_twin(box, p);
  ASSERT_TRUE(twin_p.has_value());
  ASSERT_NE(*twin_p, p);
  expect_rejected(tree, Kind::Duplicate, "insert " + to_string<d>(*twin_p) + " (same position as a present point)",
                  [&] { tree.insert(*twin_p); });
  // Outside the box: below the origin (by one ulp and by a lot), beyond o + 2L.
  for (std::size_t a = 0; a < d; ++a) {
    Point<d> x = mid;
    x[a] = std::nextafter(box.origin[a], -kInf);
    expect_rejected(tree, Kind::OutsideBox, "insert just below the origin " + to_string<d>(x), [&] { tree.insert(x); });
    x[a] = box.origin[a] - box.side / 4;
    expect_rejected(tree, Kind::OutsideBox, "insert below the origin " + to_string<d>(x), [&] { tree.insert(x); });
    x[a] = box.origin[a] + 2 * box.side;
    expect_rejected(tree, Kind::OutsideBox, "insert beyond o+L " + to_string<d>(x), [&] { tree.insert(x); });
  }
  // Spread beyond the resolution: a point one grid unit from a present one.
  const auto close = next_position(box, p);
  ASSERT_TRUE(close.has_value());
  expect_rejected(tree, Kind::Resolution, "insert " + to_string<d>(*close) + " one grid unit from a present point",
                  [&] { tree.insert(*close); });
  // Erasing what is not there: an unknown id, coordinates of no point, coordinates with the
  // located position of a present point but other values.
  expect_rejected(tree, Kind::Absent, "erase an unknown id", [&] { tree.erase(PointId{1000000}); });
  expect_rejected(tree, Kind::Absent, "erase absent coordinates", [&] { tree.erase(filled<d>(box.origin[0] + 1e-3)); });
  expect_rejected(tree, Kind::Absent, "erase the twin of a present point", [&] { tree.erase(*twin_p); });
  {
    const auto before = snapshot(tree);
    try {
      tree.erase(filled<d>(kNaN));
      ADD_FAILURE() << "erasing a NaN point did not throw";
    } catch (const InputError& e) {
      EXPECT_TRUE(e.kind() == Kind::Absent || e.kind() == Kind::NotFinite) << e.what();
    }
    EXPECT_TRUE(unchanged(tree, before));
  }
  // point() of an unknown id.
  EXPECT_THROW((void)tree.point(PointId{1000000}), InputError);

  // An erased id is gone for good.
  tree.erase(pid);
  twin.erase(pid);
  want.erase(pid);
  expect_rejected(tree, Kind::Absent, "erase an erased id", [&] { tree.erase(pid); });
  expect_rejected(tree, Kind::Absent, "erase erased coordinates", [&] { tree.erase(p); });
  EXPECT_FALSE(tree.contains(pid));
  EXPECT_FALSE(tree.find(p).has_value());
  try {
    (void)tree.point(pid);
    ADD_FAILURE() << "point() of an erased id did not throw";
  } catch (const InputError& e) {
    EXPECT_STREQ(kind_name(e.kind()), "Absent") << e.what();
  }

  // The tree still works, and the failures did not disturb the ids: the twin, which saw only
  // the valid updates, hands out the same id for the same insertion.
  const PointId again = tree.insert(p);
  EXPECT_EQ(again, twin.insert(p));
  EXPECT_NE(again, pid);
  want[again] = p;
  EXPECT_TRUE(consistent(tree, want));
  EXPECT_TRUE(same_leaves<d>(tree.leaves(), twin.leaves()));
  EXPECT_EQ(tree.live_events(), twin.live_events());
  EXPECT_EQ(tree.record_bytes(), twin.record_bytes());
}

TYPED_TEST(DynamicQuadtreeBadInput, ExactGridCases) {
  // The box [0, 1)^d: a coordinate k·2^-52 has the position k exactly.
  constexpr std::size_t d = TypeParam::value;
  const Box<d> box{filled<d>(0.0), 1.0};
  const Point<d> p = filled<d>(0.5), q = filled<d>(0.25);
  DynamicQuadtree<d> tree(box, std::vector<Point<d>>{p, q});
  PointMap<d> want{{0, p}, {1, q}};
  ASSERT_TRUE(consistent(tree, want));

  Point<d> x = p;
  x[0] = 0.5 + 0x1p-54;  // a quarter grid unit: same position
  expect_rejected(tree, Kind::Duplicate, "quarter grid unit", [&] { tree.insert(x); });
  x[0] = 0.5 + 0x1p-52;  // one grid unit on one axis
  expect_rejected(tree, Kind::Resolution, "one grid unit (one axis)", [&] { tree.insert(x); });
  const Point<d> diag = filled<d>(0.5 - 0x1p-52);  // one grid unit on every axis
  expect_rejected(tree, Kind::Resolution, "one grid unit (diagonal)", [&] { tree.insert(diag); });
  x[0] = 1.0;  // o + L: position 2^52
  expect_rejected(tree, Kind::OutsideBox, "at o + L", [&] { tree.insert(x); });
  x[0] = -0x1p-1074;  // the smallest subnormal below the origin
  expect_rejected(tree, Kind::OutsideBox, "just below the origin", [&] { tree.insert(x); });

  // Two grid units apart is legal (a level-51 pair: the tree is 52 levels deep); the
  // extreme corners of the box are inside.
  x[0] = 0.5 + 0x1p-51;
  const PointId deep = tree.insert(x);
  want[deep] = x;
  ASSERT_TRUE(consistent(tree, want));
  const PointId lo = tree.insert(filled<d>(0.0));
  want[lo] = filled<d>(0.0);
  const PointId hi = tree.insert(filled<d>(1.0 - 0x1p-53));
  want[hi] = filled<d>(1.0 - 0x1p-53);
  ASSERT_TRUE(consistent(tree, want));
  tree.erase(deep);
  want.erase(deep);
  ASSERT_TRUE(consistent(tree, want));
}

TYPED_TEST(DynamicQuadtreeBadInput, BadBatchAppliesNothing) {
  constexpr std::size_t d = TypeParam::value;
  const auto s = make_scenario<d>(Distribution::Clusters, 100, 1600, 0x1p20, 0.6);
  const auto init = pick_points(s.pool, s.initial);
  DynamicQuadtree<d> tree(s.box, init);
  std::vector<char> in(s.pool.size(), 0);
  for (const auto i : s.initial) in[i] = 1;
  std::vector<Point<d>> outside_set;  // pool points not in the tree
  for (std::size_t i = 0; i < s.pool.size(); ++i)
    if (!in[i]) outside_set.push_back(s.pool[i]);
  ASSERT_GE(outside_set.size(), 3u);
  const Point<d> a = outside_set[0], c = outside_set[1];
  const Point<d> b = init[2];  // present
  const auto close_to_a = next_position(s.box, a);
  ASSERT_TRUE(close_to_a.has_value());
  const auto twin_of_present = same_position_twin(s.box, init[0]);
  ASSERT_TRUE(twin_of_present.has_value());
  Point<d> nan = a, far = a;
  nan[d - 1] = kNaN;
  far[0] = s.box.origin[0] + 3 * s.box.side;

  struct BadCase {
    std::string name;
    Edit<d> third;
    Kind kind;
  };
  const std::vector<BadCase> cases = {
      {"NaN", {EditOp::Insert, nan}, Kind::NotFinite},
      {"outside", {EditOp::Insert, far}, Kind::OutsideBox},
      {"delete absent", {EditOp::Delete, c}, Kind::Absent},
      {"delete deleted", {EditOp::Delete, b}, Kind::Absent},
      // A point already in the set: the kind insert() reports for it (Duplicate).
      {"insert inserted", {EditOp::Insert, a}, Kind::Duplicate},
      {"insert present", {EditOp::Insert, init[0]}, Kind::Duplicate},
      {"insert same position as present", {EditOp::Insert, *twin_of_present}, Kind::Duplicate},
      {"resolution", {EditOp::Insert, *close_to_a}, Kind::Resolution},
  };
  // insert() and apply() classify the same bad insertion alike.
  expect_rejected(tree, Kind::Duplicate, "insert() of a present point", [&] { tree.insert(init[0]); });
  for (const auto& bc : cases) {
    // + a, − b, <bad>, + c: the first two are valid and must not be applied either.
    const std::vector<Edit<d>> edits = {{EditOp::Insert, a}, {EditOp::Delete, b}, bc.third, {EditOp::Insert, c}};
    const std::string msg = expect_rejected(tree, bc.kind, bc.name, [&] { tree.apply(edits); });
    EXPECT_TRUE(msg.find("edit 2") != std::string::npos || msg.find("and 2") != std::string::npos)
        << "the message should name the edit's index: " << msg;
    try {
      tree.apply(edits);
    } catch (const InputError& e) {
      // The failing edit comes last (an earlier insert at the same position comes first).
      ASSERT_FALSE(e.point_indices().empty()) << bc.name;
      EXPECT_EQ(e.point_indices().back(), 2u) << bc.name;
    }
  }
  // The same batch without the bad edit goes through.
  const std::vector<Edit<d>> good = {{EditOp::Insert, a}, {EditOp::Delete, b}, {EditOp::Insert, c}};
  const auto ids = tree.apply(good);
  ASSERT_EQ(ids.size(), 2u);
  PointMap<d> want;
  for (std::size_t k = 0; k < init.size(); ++k)
    if (k != 2) want[k] = init[k];
  want[ids[0]] = a;
  want[ids[1]] = c;
  EXPECT_TRUE(consistent(tree, want));
}

TYPED_TEST(DynamicQuadtreeBadInput, ConstructionRejectsBadPointLists) {
  constexpr std::size_t d = TypeParam::value;
  const auto pool = generate<d>(Distribution::Uniform, 12, 1700);
  const Box<d> box = derive_box<d>(pool);
  struct BadCase {
    std::string name;
    std::size_t index;    // where the bad point goes
    std::size_t partner;  // the other point of a bad pair (index itself for a lone bad point)
    Point<d> point;
    Kind kind;
  };
  Point<d> nan = pool[5], outside = pool[5];
  nan[1] = kNaN;
  outside[0] = box.origin[0] - 1.0;
  const auto close = next_position(box, pool[3]);
  ASSERT_TRUE(close.has_value());
  const auto twin_p = same_position_twin(box, pool[4]);
  ASSERT_TRUE(twin_p.has_value());
  const std::vector<BadCase> cases = {
      {"duplicate", 7, 2, pool[2], Kind::Duplicate},   {"same position", 9, 4, *twin_p, Kind::Duplicate},
      {"NaN", 8, 8, nan, Kind::NotFinite},             {"outside", 10, 10, outside, Kind::OutsideBox},
      {"resolution", 11, 3, *close, Kind::Resolution},
  };
  for (const auto& bc : cases) {
    SCOPED_TRACE(bc.name);
    auto pts = pool;
    pts[bc.index] = bc.point;
    try {
      const DynamicQuadtree<d> t(box, pts);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_STREQ(kind_name(e.kind()), kind_name(bc.kind)) << e.what();
      const std::string msg = e.what();
      EXPECT_TRUE(msg.find("point " + std::to_string(bc.index)) != std::string::npos ||
                  msg.find("point " + std::to_string(bc.partner)) != std::string::npos ||
                  msg.find("points " + std::to_string(bc.partner)) != std::string::npos)
          << "the message should name point " << bc.index << " (or " << bc.partner << "): " << msg;
    }
  }
}

// --- the query API ---------------------------------------------------------------------------

TYPED_TEST(DynamicQuadtreeApi, IdsAndLookups) {
  constexpr std::size_t d = TypeParam::value;
  const auto pool = generate<d>(Distribution::Clusters, 80, 1800);
  const Box<d> box = derive_box<d>(pool);
  const std::vector<Point<d>> init(pool.begin(), pool.begin() + 50);
  DynamicQuadtree<d> tree(box, init);
  EXPECT_EQ(tree.box(), box);
  // Construction: ids 0..n−1 in input order; points() in input order.
  const auto pts = tree.points();
  ASSERT_EQ(pts.size(), init.size());
  for (std::size_t k = 0; k < init.size(); ++k) {
    EXPECT_EQ(pts[k].first, PointId{k});
    EXPECT_EQ(pts[k].second, init[k]);
    EXPECT_EQ(tree.point(k), init[k]);
    EXPECT_EQ(tree.find(init[k]), std::optional<PointId>(k));
    EXPECT_TRUE(tree.contains(k));
  }
  EXPECT_FALSE(tree.contains(init.size()));
  EXPECT_FALSE(tree.find(pool[60]).has_value());
  // Insertions get fresh ids, never reused after erasure.
  std::set<PointId> ever;
  for (const auto& [id, p] : pts) ever.insert(id);
  for (std::size_t k = 50; k < pool.size(); ++k) {
    const PointId id = tree.insert(pool[k]);
    EXPECT_TRUE(ever.insert(id).second) << "id " << id << " handed out twice";
    EXPECT_EQ(tree.point(id), pool[k]);
    EXPECT_EQ(tree.find(pool[k]), std::optional<PointId>(id));
    if (k % 3 == 0) {
      tree.erase(id);
      EXPECT_FALSE(tree.contains(id));
      EXPECT_FALSE(tree.find(pool[k]).has_value());
      const PointId again = tree.insert(pool[k]);
      EXPECT_TRUE(ever.insert(again).second) << "erased id " << id << " reused";
    }
  }
  EXPECT_EQ(tree.size(), pool.size());
  ASSERT_TRUE(invariants_hold(tree));
}

template <std::size_t d>
void locate_and_neighbours(Distribution dist, std::size_t n, std::uint64_t seed) {
  SCOPED_TRACE(std::string(distribution_name(dist)) + " d=" + std::to_string(d) + " seed=" + std::to_string(seed));
  const auto pool = generate<d>(dist, n + 20, seed);
  const Box<d> box = derive_box<d>(pool);
  // Built with n points, then edited: the queries must reflect the current tree.
  DynamicQuadtree<d> tree(box, std::vector<Point<d>>(pool.begin(), pool.begin() + static_cast<std::ptrdiff_t>(n)));
  for (std::size_t k = n; k < pool.size(); ++k) tree.insert(pool[k]);
  for (PointId id = 0; id < 20; ++id) tree.erase(id);
  const auto positions = tree.positions();
  const StaticQuadtree<d> oracle(positions);
  const auto leaves = tree.leaves();
  ASSERT_TRUE(same_leaves<d>(leaves, {oracle.leaves().begin(), oracle.leaves().end()}));
  EXPECT_EQ(tree.num_split(), oracle.num_split());
  EXPECT_EQ(tree.num_leaves(), leaves.size());

  // locate: the input points, and random points of the box.
  for (const auto& [id, p] : tree.points()) {
    const CellId<d> c = tree.locate(p);
    EXPECT_EQ(c, oracle.locate(locate(box, p))) << "point " << id;
  }
  Rng rng(seed + 5);
  for (int t = 0; t < 300; ++t) {
    Point<d> x;
    for (std::size_t a = 0; a < d; ++a) x[a] = box.origin[a] + box.side * rng.uniform();
    const auto q = try_locate(box, x);
    if (!q) continue;
    EXPECT_EQ(tree.locate(x), oracle.locate(*q)) << to_string<d>(x);
  }
  EXPECT_EQ(tree.locate(box.origin), oracle.locate(Position<d>{}));
  try {
    (void)tree.locate(filled<d>(kNaN));
    ADD_FAILURE() << "locate(NaN) did not throw";
  } catch (const InputError& e) {
    EXPECT_STREQ(kind_name(e.kind()), "NotFinite") << e.what();
  }
  try {
    (void)tree.locate(filled<d>(box.origin[0] - box.side));
    ADD_FAILURE() << "locate(outside) did not throw";
  } catch (const InputError& e) {
    EXPECT_STREQ(kind_name(e.kind()), "OutsideBox") << e.what();
  }

  // neighbours of every leaf.
  for (const auto& leaf : leaves)
    ASSERT_EQ(tree.neighbours(leaf.cell), oracle.neighbours(leaf.cell)) << to_string(leaf.cell);
  // Not leaves: the (split) root and a child of a leaf.
  EXPECT_THROW((void)tree.neighbours(CellId<d>::root()), std::invalid_argument);
  EXPECT_THROW((void)tree.neighbours(child(leaves.front().cell, 0)), std::invalid_argument);
}

TYPED_TEST(DynamicQuadtreeApi, LocateAndNeighboursMatchTheOracle) {
  constexpr std::size_t d = TypeParam::value;
  locate_and_neighbours<d>(Distribution::Clusters, d == 2 ? 60 : 30, 1900);
  locate_and_neighbours<d>(Distribution::Boundary, d == 2 ? 60 : 30, 1901);
  locate_and_neighbours<d>(Distribution::Shrinking, d == 2 ? 60 : 30, 1902);
}

TYPED_TEST(DynamicQuadtreeApi, DirectoryStaysBoundedOverManyCycles) {
  // n stays fixed while 2000 insert/erase cycles name ever new cells: the directory must not
  // grow without bound (automatic compaction at doubling), and after compact() it is no
  // larger than a fresh tree's on the same points.
  constexpr std::size_t d = TypeParam::value;
  const std::size_t n = d == 2 ? 200 : 60;
  const int cycles = kDebugChecks ? 100 : scaled(2000, 4);  // each update checks the tree
  const auto pool = generate<d>(Distribution::Uniform, n, 2000);
  const Box<d> box = derive_box<d>(pool);
  DynamicQuadtree<d> tree(box, pool);
  tree.compact();
  const std::size_t start = tree.directory_size();
  std::vector<PointId> ids;
  for (PointId id = 0; id < n; ++id) ids.push_back(id);
  Rng rng(2001);
  std::size_t peak = 0;
  for (int c = 0; c < cycles; ++c) {
    Point<d> p;  // uniform in [0, 1)^d, inside the box of the pool
    for (auto& x : p) x = rng.uniform();
    PointId id = 0;
    try {
      id = tree.insert(p);
    } catch (const InputError& e) {
      ASSERT_TRUE(e.kind() == Kind::Duplicate || e.kind() == Kind::Resolution) << e.what();
      continue;
    }
    ids.push_back(id);
    const std::size_t j = rng.below(ids.size());
    tree.erase(ids[j]);
    ids[j] = ids.back();
    ids.pop_back();
    peak = std::max(peak, tree.directory_size());
  }
  ASSERT_TRUE(invariants_hold(tree));
  ASSERT_TRUE(same_leaves<d>(tree.leaves(), oracle_leaves<d>(box, list_of(tree))));
  tree.compact();
  DynamicQuadtree<d> fresh(box, list_of(tree));
  fresh.compact();
  std::printf("    [d=%zu n=%zu] directory: %zu at start, peak %zu over %d cycles, %zu after compact(), fresh %zu\n", d,
              n, start, peak, cycles, tree.directory_size(), fresh.directory_size());
  EXPECT_LE(tree.directory_size(), 2 * fresh.directory_size());
  EXPECT_LE(peak, 4 * std::max(start, fresh.directory_size()) + 64) << "the directory grows without bound";
  EXPECT_EQ(tree.live_events(), fresh.live_events());
  EXPECT_EQ(tree.record_bytes(), fresh.record_bytes());
  EXPECT_LE(tree.trace_bytes(), 2 * fresh.trace_bytes()) << "memory did not return to the from-scratch level";
}

// --- empty and tiny sets -------------------------------------------------------------------------

TYPED_TEST(DynamicQuadtreeTiny, EmptyTreeIsTheRootLeaf) {
  constexpr std::size_t d = TypeParam::value;
  const Box<d> box{filled<d>(-1.0), 4.0};
  DynamicQuadtree<d> tree(box);
  const std::vector<Leaf<d>> root = {{CellId<d>::root(), 0}};
  EXPECT_EQ(tree.leaves(), root);
  EXPECT_EQ(tree.size(), 0u);
  EXPECT_TRUE(tree.points().empty());
  EXPECT_TRUE(tree.positions().empty());
  EXPECT_EQ(tree.num_split(), 0u);
  EXPECT_EQ(tree.num_leaves(), 1u);
  const auto lwp = tree.leaves_with_points();
  ASSERT_EQ(lwp.size(), 1u);
  EXPECT_EQ(lwp[0].cell, CellId<d>::root());
  EXPECT_TRUE(lwp[0].points.empty());
  EXPECT_EQ(tree.locate(filled<d>(0.5)), CellId<d>::root());
  EXPECT_TRUE(tree.neighbours(CellId<d>::root()).empty());
  EXPECT_FALSE(tree.find(filled<d>(0.5)).has_value());
  EXPECT_TRUE(invariants_hold(tree));
  EXPECT_TRUE(tree.apply(std::span<const Edit<d>>{}).empty());
  EXPECT_TRUE(consistent(tree, PointMap<d>{}));
  // Erasing from the empty tree is an error that changes nothing.
  expect_rejected(tree, Kind::Absent, "erase id 0 from the empty tree", [&] { tree.erase(PointId{0}); });
  expect_rejected(tree, Kind::Absent, "erase a point from the empty tree", [&] { tree.erase(filled<d>(0.5)); });
}

TYPED_TEST(DynamicQuadtreeTiny, OneAndTwoPoints) {
  constexpr std::size_t d = TypeParam::value;
  const Box<d> box{filled<d>(0.0), 1.0};
  DynamicQuadtree<d> tree(box);
  const Point<d> p = filled<d>(0.3);
  const PointId a = tree.insert(p);
  EXPECT_EQ(tree.leaves(), (std::vector<Leaf<d>>{{CellId<d>::root(), 1}}));
  const auto lwp = tree.leaves_with_points();
  ASSERT_EQ(lwp.size(), 1u);
  EXPECT_EQ(lwp[0].points, std::vector<PointId>{a});
  EXPECT_EQ(tree.locate(p), CellId<d>::root());
  EXPECT_TRUE(consistent(tree, PointMap<d>{{a, p}}));

  // Two far apart, then two close together (a deep tree), each against the oracle.
  const PointId b = tree.insert(filled<d>(0.9));
  EXPECT_TRUE(consistent(tree, PointMap<d>{{a, p}, {b, filled<d>(0.9)}}));
  tree.erase(b);
  EXPECT_TRUE(consistent(tree, PointMap<d>{{a, p}}));
  Point<d> near = p;
  near[0] += 0x1p-40;
  const PointId c = tree.insert(near);
  EXPECT_TRUE(consistent(tree, PointMap<d>{{a, p}, {c, near}}));
  EXPECT_GT(tree.num_split(), 40u);
  tree.erase(p);
  EXPECT_TRUE(consistent(tree, PointMap<d>{{c, near}}));
  EXPECT_EQ(tree.leaves(), (std::vector<Leaf<d>>{{CellId<d>::root(), 1}}));
  tree.erase(c);
  EXPECT_EQ(tree.leaves(), (std::vector<Leaf<d>>{{CellId<d>::root(), 0}}));
  EXPECT_TRUE(consistent(tree, PointMap<d>{}));

  // The empty tree after updates has the trace of a fresh empty tree.
  const DynamicQuadtree<d> fresh(box);
  EXPECT_EQ(tree.live_events(), fresh.live_events());
  EXPECT_EQ(tree.record_bytes(), fresh.record_bytes());
}

TYPED_TEST(DynamicQuadtreeTiny, EraseDownToEmptyAndBack) {
  constexpr std::size_t d = TypeParam::value;
  const std::size_t n = d == 2 ? 40 : 20;
  const auto pool = generate<d>(Distribution::Clusters, n, 2100);
  const Box<d> box = derive_box<d>(pool);
  DynamicQuadtree<d> tree(box, pool);
  const DynamicQuadtree<d> full(box, pool);
  PointMap<d> want;
  for (std::size_t k = 0; k < n; ++k) want[k] = pool[k];
  Rng rng(2101);
  std::vector<PointId> order;
  for (PointId id = 0; id < n; ++id) order.push_back(id);
  rng.shuffle(order);
  for (const auto id : order) {
    SCOPED_TRACE("erase " + std::to_string(id));
    tree.erase(id);
    want.erase(id);
    ASSERT_TRUE(consistent(tree, want));
  }
  EXPECT_EQ(tree.leaves(), (std::vector<Leaf<d>>{{CellId<d>::root(), 0}}));
  EXPECT_EQ(tree.live_events(), DynamicQuadtree<d>(box).live_events());
  // Back again in another order, the first half one by one, the rest as one batch.
  auto back = pool;
  rng.shuffle(back);
  std::vector<Edit<d>> rest;
  for (std::size_t k = 0; k < n; ++k) {
    if (k < n / 2) {
      SCOPED_TRACE("insert " + to_string<d>(back[k]));
      want[tree.insert(back[k])] = back[k];
      ASSERT_TRUE(consistent(tree, want));
    } else {
      rest.push_back({EditOp::Insert, back[k]});
    }
  }
  const auto ids = tree.apply(rest);
  ASSERT_EQ(ids.size(), rest.size());
  for (std::size_t k = 0; k < ids.size(); ++k) want[ids[k]] = rest[k].point;
  ASSERT_TRUE(consistent(tree, want));
  EXPECT_TRUE(same_leaves<d>(tree.leaves(), full.leaves()));
  const DynamicQuadtree<d> fresh(box, list_of(tree));
  EXPECT_EQ(tree.live_events(), fresh.live_events());
  EXPECT_EQ(tree.record_bytes(), fresh.record_bytes());
}

TYPED_TEST(DynamicQuadtreeTiny, MovedTreeKeepsWorking) {
  constexpr std::size_t d = TypeParam::value;
  const auto pool = generate<d>(Distribution::Uniform, 30, 2200);
  const Box<d> box = derive_box<d>(pool);
  DynamicQuadtree<d> a(box, std::vector<Point<d>>(pool.begin(), pool.begin() + 20));
  DynamicQuadtree<d> b(std::move(a));
  PointMap<d> want;
  for (std::size_t k = 0; k < 20; ++k) want[k] = pool[k];
  want[b.insert(pool[25])] = pool[25];
  EXPECT_TRUE(consistent(b, want));
  DynamicQuadtree<d> c(box);
  c = std::move(b);
  c.erase(PointId{3});
  want.erase(3);
  EXPECT_TRUE(consistent(c, want));
}

// --- the checkers see corruption ------------------------------------------------------------
//
// Each test builds a small tree, sees the checkers pass, breaks exactly one thing through
// DynamicQuadtreeTestAccess, expects InvariantError, and repairs it before the tree goes.

/// 40 clustered points, and one more to insert later.
template <std::size_t d>
std::vector<Point<d>> checker_pool() {
  return generate<d>(Distribution::Clusters, 41, 2300);
}
template <std::size_t d>
DynamicQuadtree<d> checker_tree() {
  const auto pool = checker_pool<d>();
  return DynamicQuadtree<d>(derive_box<d>(pool), std::span<const Point<d>>(pool).first(40));
}

/// The newest `split` value of a cell's slot, writable: a change the engine never sees.
template <std::size_t d>
std::uint8_t& split_value(detail::DynamicState<d>& s, const CellId<d>& c) {
  sac::Mod<std::uint8_t>& split = s.dir.get(s.rt, c).split;
  // A default that nothing read has no version to corrupt: give it one, equal to it.
  if (s.rt.unused(split)) {
    s.rt.retire(split);
    s.rt.init(split, std::uint8_t{0});
  }
  return const_cast<std::uint8_t&>(split.get());
}

/// The message of the dynmesh::InvariantError that check() throws, or "" if none.
template <class Check>
std::string invariant_message(Check&& check) {
  try {
    check();
  } catch (const InvariantError& e) {
    return e.what();
  }
  return {};
}

using testing::HasSubstr;

TYPED_TEST(DynamicQuadtreeCheckers, DirectorySlotFiledUnderAnotherCell) {
  constexpr std::size_t d = TypeParam::value;
  auto tree = checker_tree<d>();
  auto& s = DynamicQuadtreeTestAccess::state(tree);
  ASSERT_TRUE(invariants_hold(tree));
  const CellId<d> leaf = tree.leaves().front().cell;  // a child of a split cell: it has a slot
  ASSERT_NE(s.dir.find(leaf), nullptr);
  detail::Slot<d>& slot = s.dir.get(s.rt, leaf);
  slot.key = detail::pack_cell<d>(parent(leaf));
  EXPECT_THROW(s.dir.check_invariants(), InvariantError);
  EXPECT_THAT(invariant_message([&] { s.dir.check_invariants(); }), HasSubstr("filed under another cell"));
  EXPECT_THROW(tree.check_invariants(), InvariantError);
  slot.key = detail::pack_cell<d>(leaf);
  EXPECT_TRUE(invariants_hold(tree));
}

TYPED_TEST(DynamicQuadtreeCheckers, DirectorySplitCellWithoutChildren) {
  constexpr std::size_t d = TypeParam::value;
  auto tree = checker_tree<d>();
  auto& s = DynamicQuadtreeTestAccess::state(tree);
  ASSERT_TRUE(invariants_hold(tree));
  // A deepest leaf (the leaves are sorted by level first): nothing named its children.
  const CellId<d> leaf = tree.leaves().back().cell;
  for (const CellId<d>& k : children(leaf)) ASSERT_EQ(s.dir.find(k), nullptr) << to_string(k);
  std::uint8_t& split = split_value(s, leaf);
  ASSERT_EQ(split, 0);
  split = detail::kTreeSplit;
  EXPECT_THROW(s.dir.check_invariants(), InvariantError);
  EXPECT_THAT(invariant_message([&] { s.dir.check_invariants(); }), HasSubstr("has no slot"));
  EXPECT_THROW(tree.check_invariants(), InvariantError);
  split = 0;
  EXPECT_TRUE(invariants_hold(tree));
}

TYPED_TEST(DynamicQuadtreeCheckers, CellListHoldingAFreedOrMisplacedNode) {
  constexpr std::size_t d = TypeParam::value;
  auto tree = checker_tree<d>();
  auto& s = DynamicQuadtreeTestAccess::state(tree);
  ASSERT_TRUE(invariants_hold(tree));
  // A leaf holding a point: its list is one node of that point, at the leaf's level.
  CellId<d> leaf{};
  for (const Leaf<d>& l : tree.leaves())
    if (l.npoints == 1 && l.cell.level > 1) leaf = l.cell;
  ASSERT_GT(leaf.level, 1);
  auto& head = const_cast<detail::PNode<d>*&>(s.dir.get(s.rt, leaf).pts.get());
  detail::PNode<d>* const saved = head;
  ASSERT_NE(saved, nullptr);
  // A node in no point's chain: what a list would hold if compact() had freed its node.
  detail::PNode<d> stray(saved->q);
  s.rt.init_default(stray.next);
  head = &stray;
  EXPECT_THAT(invariant_message([&] { tree.check_invariants(); }), HasSubstr("holds a freed node"));
  // The same point's node one level up: a live node, but not this cell's.
  detail::PNode<d>* up = nullptr;
  for (detail::InputNode<d>* n = s.first; n && !up; n = n->succ)
    if (n->q == saved->q) up = n;
  ASSERT_NE(up, nullptr);
  for (int l = 0; l + 1 < leaf.level; ++l) up = up->down;
  ASSERT_EQ(up->down, saved);
  head = up;
  EXPECT_THAT(invariant_message([&] { tree.check_invariants(); }), HasSubstr("holds another cell's node"));
  head = saved;
  EXPECT_TRUE(invariants_hold(tree));
}

TYPED_TEST(DynamicQuadtreeCheckers, TreeWithACrowdedCellTurnedLeaf) {
  constexpr std::size_t d = TypeParam::value;
  auto tree = checker_tree<d>();
  auto& s = DynamicQuadtreeTestAccess::state(tree);
  ASSERT_TRUE(invariants_hold(tree));
  // The parent of a deepest leaf is split only because it is crowded (no deeper split cell
  // can force it). As a leaf it breaks the tree's rules, not the directory's.
  const CellId<d> cell = parent(tree.leaves().back().cell);
  std::uint8_t& split = split_value(s, cell);
  ASSERT_TRUE(detail::tree_split(split));
  const std::uint8_t saved = split;
  split = 0;
  EXPECT_NO_THROW(s.dir.check_invariants());
  EXPECT_THROW(tree.check_invariants(), InvariantError);
  EXPECT_THAT(invariant_message([&] { tree.check_invariants(); }), HasSubstr("quadtree contract violated"));
  split = saved;
  EXPECT_TRUE(invariants_hold(tree));
}

TYPED_TEST(DynamicQuadtreeCheckers, PointIndexMissingAPoint) {
  constexpr std::size_t d = TypeParam::value;
  auto tree = checker_tree<d>();
  auto& s = DynamicQuadtreeTestAccess::state(tree);
  ASSERT_TRUE(invariants_hold(tree));
  const auto it = s.by_id.find(PointId{0});
  ASSERT_NE(it, s.by_id.end());
  auto* node = it->second;
  s.by_id.erase(it);
  EXPECT_THROW(tree.check_invariants(), InvariantError);
  EXPECT_THAT(invariant_message([&] { tree.check_invariants(); }), HasSubstr("point indexes"));
  s.by_id.emplace(PointId{0}, node);
  EXPECT_TRUE(invariants_hold(tree));
}

TYPED_TEST(DynamicQuadtreeCheckers, UpdatesRunTheCheckersUnderSacDebugChecks) {
  constexpr std::size_t d = TypeParam::value;
  auto tree = checker_tree<d>();
  auto& s = DynamicQuadtreeTestAccess::state(tree);
  ASSERT_TRUE(invariants_hold(tree));
  const auto it = s.by_id.find(PointId{0});
  auto* node = it->second;
  s.by_id.erase(it);  // survives the update below, which does not touch point 0
  const Point<d> extra = checker_pool<d>().back();
  if (kDebugChecks) {
    EXPECT_THROW(tree.insert(extra), InvariantError);
  } else {
    EXPECT_NO_THROW(tree.insert(extra));
  }
  EXPECT_TRUE(tree.find(extra).has_value()) << "the update itself went through";
  s.by_id.emplace(PointId{0}, node);
  EXPECT_TRUE(invariants_hold(tree));
}

}  // namespace

namespace {

// is_split and leaves_in (what MpiQuadtree reads of each rank's tree) agree with the static
// oracle and with leaves(): for every cell of levels 0 to 4, including cells strictly inside
// a leaf (no leaves) and leaves themselves (just the cell).
TYPED_TEST(DynamicQuadtreeApi, IsSplitAndLeavesInAgreeWithTheOracle) {
  constexpr std::size_t d = TypeParam::value;
  const std::vector<Point<d>> pts = generate<d>(Distribution::Clusters, d == 2 ? 200 : 60, 17);
  const Box<d> box = derive_box<d>(pts);
  DynamicQuadtree<d> tree(box, pts);
  const auto oracle = StaticQuadtree<d>::from_points(box, pts);
  const std::vector<Leaf<d>> all = tree.leaves();
  for (int level = 0; level <= 4; ++level) {
    const std::uint64_t n = cells_per_axis(level);
    for (std::uint64_t code = 0; code < (d == 2 ? n * n : n * n * n); ++code) {
      CellId<d> c;
      c.level = level;
      std::uint64_t rest = code;
      for (std::size_t a = 0; a < d; ++a) {
        c.index[a] = rest % n;
        rest /= n;
      }
      ASSERT_EQ(tree.is_split(c), oracle.is_split(c)) << to_string(c);
      std::vector<Leaf<d>> want;
      for (const Leaf<d>& leaf : all)
        if (contains(c, leaf.cell)) want.push_back(leaf);
      ASSERT_EQ(tree.leaves_in(c), want) << to_string(c);
    }
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------
// split_below: every cell coarser than a level split as well (the distributed meshes' local
// trees). Oracle: T*'s leaves of that level or finer, and each coarser leaf of T* cut into
// its descendants of that level (holding its point, if any).

namespace {

template <std::size_t d>
std::vector<Leaf<d>> cut_to(const std::vector<Leaf<d>>& tree, int level, std::span<const Position<d>> pts) {
  std::vector<Leaf<d>> out;
  for (const Leaf<d>& leaf : tree) {
    if (leaf.cell.level >= level) {
      out.push_back(leaf);
      continue;
    }
    const int shift = level - leaf.cell.level;
    const std::uint64_t side = std::uint64_t{1} << shift;
    std::uint64_t count = 1;
    for (std::size_t a = 0; a < d; ++a) count *= side;
    for (std::uint64_t code = 0; code < count; ++code) {
      CellId<d> c;
      c.level = level;
      std::uint64_t rest = code;
      for (std::size_t a = 0; a < d; ++a, rest >>= shift) c.index[a] = (leaf.cell.index[a] << shift) + (rest & (side - 1));
      std::uint32_t k = 0;
      for (const Position<d>& q : pts) k += contains(c, q) ? 1 : 0;
      out.push_back(Leaf<d>{c, leaf.npoints == 0 ? 0 : k});
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

template <std::size_t d>
void run_split_below(Distribution dist, std::uint64_t seed, int level, std::size_t updates) {
  SCOPED_TRACE("seed " + std::to_string(seed) + ", split_below " + std::to_string(level));
  const std::vector<Point<d>> pool = generate<d>(dist, scaled<std::size_t>(300), seed, 0x1p20);
  const Box<d> box = derive_box<d>(pool);
  Rng rng(seed + 99);
  std::vector<Point<d>> present, absent;
  for (const Point<d>& p : pool) (rng.below(2) ? present : absent).push_back(p);
  DynamicQuadtree<d> tree(box, present, DynamicQuadtreeOptions{level});
  for (std::size_t u = 0;; ++u) {
    const std::vector<Point<d>> now = list_of(tree);
    std::vector<Position<d>> qs;
    for (const Point<d>& p : now) qs.push_back(locate(box, p));
    const std::vector<Leaf<d>> want = cut_to<d>(oracle_leaves<d>(box, now), level, qs);
    ASSERT_TRUE(same_leaves<d>(tree.leaves(), want)) << "after " << u << " updates";
    ASSERT_NO_THROW(tree.check_invariants());
    // From scratch on the same points: the same leaves.
    ASSERT_EQ(DynamicQuadtree<d>(box, now, DynamicQuadtreeOptions{level}).leaves(), tree.leaves());
    if (u == updates) break;
    if (!absent.empty() && (rng.below(2) || tree.size() == 0)) {
      const std::size_t i = rng.below(absent.size());
      tree.insert(absent[i]);
      absent.erase(absent.begin() + static_cast<std::ptrdiff_t>(i));
    } else {
      const std::vector<Point<d>> in = list_of(tree);
      const Point<d> gone = in[rng.below(in.size())];
      tree.erase(gone);
      absent.push_back(gone);
    }
  }
}

}  // namespace

TEST(DynamicQuadtreeSplitBelow, EqualsTStarCutToTheLevel2D) {
  for (int level : {1, 2, 3, 4})
    for (Distribution dist : {Distribution::Uniform, Distribution::Clusters, Distribution::Shrinking})
      run_split_below<2>(dist, 11 + static_cast<std::uint64_t>(level), level, scaled<std::size_t>(60));
}

TEST(DynamicQuadtreeSplitBelow, EqualsTStarCutToTheLevel3D) {
  for (int level : {1, 2})
    for (Distribution dist : {Distribution::Uniform, Distribution::Clusters})
      run_split_below<3>(dist, 21 + static_cast<std::uint64_t>(level), level, scaled<std::size_t>(30));
}

TEST(DynamicQuadtreeSplitBelow, EmptyAndSinglePointSetsAreCutToo) {
  const Box<2> box{{0, 0}, 1};
  DynamicQuadtree<2> empty(box, {}, DynamicQuadtreeOptions{2});
  EXPECT_EQ(empty.leaves().size(), 16u);
  EXPECT_NO_THROW(empty.check_invariants());
  const PointId id = empty.insert({0.3, 0.3});
  EXPECT_EQ(empty.leaves().size(), 16u);
  empty.erase(id);
  EXPECT_EQ(empty.leaves().size(), 16u);
  EXPECT_NO_THROW(empty.check_invariants());
}

TEST(DynamicQuadtreeSplitBelow, LevelOutOfRangeIsRefused) {
  const Box<2> box{{0, 0}, 1};
  EXPECT_THROW(DynamicQuadtree<2>(box, {}, DynamicQuadtreeOptions{-1}), std::invalid_argument);
  EXPECT_THROW(DynamicQuadtree<2>(box, {}, DynamicQuadtreeOptions{kMaxSplitBelow + 1}), std::invalid_argument);
}

TEST(DynamicQuadtreeSplitBelow, TheCheckerRefusesALeafAboveTheLevel) {
  const Box<2> box{{0, 0}, 1};
  const std::vector<Point<2>> pts{{0.1, 0.1}, {0.9, 0.9}};
  std::vector<Position<2>> qs;
  for (const auto& p : pts) qs.push_back(locate(box, p));
  const auto t = oracle_leaves<2>(box, pts);  // leaves of level 1 and finer
  EXPECT_TRUE(check_tree<2>(qs, t).ok());
  EXPECT_FALSE(check_tree<2>(qs, t, 64, 3).ok());
  EXPECT_TRUE(check_tree<2>(qs, cut_to<2>(t, 3, qs), 64, 3).ok());
  EXPECT_FALSE(check_tree<2>(qs, cut_to<2>(t, 3, qs)).ok()) << "unforced, the cut tree has unjustified splits";
}
