// static_quadtree_test.cpp — T* (the oracle) and the tree checker.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <set>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace {

using namespace dynmesh;
using Kind = InputError::Kind;

template <std::size_t d>
std::vector<Position<d>> located(const std::vector<Point<d>>& pts) {
  const Box<d> box = derive_box<d>(pts);
  std::vector<Position<d>> q;
  for (const auto& p : pts) q.push_back(locate(box, p));
  return q;
}

/// The leaves of a tree given by its split set (closed under parent).
template <std::size_t d>
std::vector<Leaf<d>> leaves_of(const std::set<CellId<d>>& split, const std::vector<Position<d>>& pts) {
  std::vector<Leaf<d>> out;
  if (split.empty()) {
    out.push_back({CellId<d>::root(), static_cast<std::uint32_t>(pts.size())});
    return out;
  }
  for (const auto& s : split)
    for (const auto& ch : children(s))
      if (!split.count(ch)) {
        std::uint32_t k = 0;
        for (const auto& q : pts) k += contains(ch, q) ? 1 : 0;
        out.push_back({ch, k});
      }
  std::sort(out.begin(), out.end());
  return out;
}

/// T* straight from its definition, by brute force over every cell of levels 0..max_level:
/// crowded cells, then "a level m−1 cell touching a split level-m cell is split" iterated to
/// a fixed point (the parent touches its child, so the parent rule is included). Valid when
/// no cell deeper than max_level is crowded.
template <std::size_t d>
std::set<CellId<d>> naive_tstar(const std::vector<Position<d>>& pts, int max_level) {
  std::vector<CellId<d>> cells;
  for (int l = 0; l <= max_level; ++l) {
    const std::uint64_t n = cells_per_axis(l);
    std::uint64_t total = 1;
    for (std::size_t a = 0; a < d; ++a) total *= n;
    for (std::uint64_t t = 0; t < total; ++t) {
      CellId<d> c;
      c.level = l;
      std::uint64_t r = t;
      for (std::size_t a = 0; a < d; ++a) {
        c.index[a] = r % n;
        r /= n;
      }
      cells.push_back(c);
    }
  }
  auto crowded = [&](const CellId<d>& c) {
    int inside = 0, around = 0;
    for (const auto& q : pts) {
      bool in = true, near = true;
      for (std::size_t a = 0; a < d; ++a) {
        const auto i = static_cast<long long>(q[a] >> (kMaxLevel - c.level));
        const auto j = static_cast<long long>(c.index[a]);
        in = in && i == j;
        near = near && i - j <= 1 && j - i <= 1;
      }
      inside += in ? 1 : 0;
      around += near ? 1 : 0;
    }
    return inside >= 2 || (inside == 1 && around >= 2);
  };
  std::set<CellId<d>> split;
  for (const auto& c : cells)
    if (crowded(c)) split.insert(c);
  for (bool changed = true; changed;) {
    changed = false;
    for (const auto& c : cells) {
      if (split.count(c)) continue;
      for (const auto& t : split)
        if (t.level == c.level + 1 && touches(c, t)) {
          split.insert(c);
          changed = true;
          break;
        }
    }
  }
  return split;
}

template <std::size_t d>
std::set<CellId<d>> split_set(const StaticQuadtree<d>& tree) {
  const auto v = tree.split_cells();
  return {v.begin(), v.end()};
}

// --- hand-made cases ---------------------------------------------------------------------------

TEST(StaticQuadtree, EmptyAndSinglePoint) {
  const StaticQuadtree<2> empty(std::vector<Position<2>>{});
  ASSERT_EQ(empty.leaves().size(), 1u);
  EXPECT_EQ(empty.leaves()[0], (Leaf<2>{CellId<2>::root(), 0}));
  EXPECT_NO_THROW(empty.check_invariants());

  const StaticQuadtree<3> one(std::vector<Position<3>>{{1, 2, 3}});
  ASSERT_EQ(one.leaves().size(), 1u);
  EXPECT_EQ(one.leaves()[0], (Leaf<3>{CellId<3>::root(), 1}));
  EXPECT_EQ(one.depth(), 0);
  EXPECT_EQ(one.locate({kResolution - 1, 0, 0}), CellId<3>::root());
  EXPECT_TRUE(one.neighbours(CellId<3>::root()).empty());
  EXPECT_NO_THROW(one.check_invariants());
}

TEST(StaticQuadtree, TwoClosePointsByHand) {
  // p1 at the origin, p2 one level-2 cell to the right: both lie in the level-1 cell (0,0);
  // at level 2 they occupy the touching cells (0,0) and (1,0), so both are crowded; at level 3
  // their cells (0,0) and (2,0) are two apart, so nothing deeper is crowded.
  // Split: root; level 2: (0,0), (1,0) (crowded); level 1: (0,0) (crowded, parent) and (1,0)
  // (touches the split level-2 cell (1,0) at x = 2^51: grading). Nothing else touches.
  const std::uint64_t u2 = std::uint64_t{1} << 50;  // side of a level-2 cell
  const std::vector<Position<2>> pts = {{0, 0}, {u2, 0}};
  const StaticQuadtree<2> tree(pts);
  const std::vector<CellId<2>> want_split = {{0, {0, 0}}, {1, {0, 0}}, {1, {1, 0}}, {2, {0, 0}}, {2, {1, 0}}};
  EXPECT_EQ(tree.split_cells(), want_split);
  const std::vector<Leaf<2>> want = {
      {{1, {0, 1}}, 0}, {{1, {1, 1}}, 0},                                      //
      {{2, {0, 1}}, 0}, {{2, {1, 1}}, 0}, {{2, {2, 0}}, 0}, {{2, {2, 1}}, 0},  //
      {{2, {3, 0}}, 0}, {{2, {3, 1}}, 0},                                      //
      {{3, {0, 0}}, 1}, {{3, {0, 1}}, 0}, {{3, {1, 0}}, 0}, {{3, {1, 1}}, 0},  //
      {{3, {2, 0}}, 1}, {{3, {2, 1}}, 0}, {{3, {3, 0}}, 0}, {{3, {3, 1}}, 0},
  };
  EXPECT_EQ(std::vector<Leaf<2>>(tree.leaves().begin(), tree.leaves().end()), want);
  EXPECT_EQ(tree.locate(pts[0]), (CellId<2>{3, {0, 0}}));
  EXPECT_EQ(tree.locate(pts[1]), (CellId<2>{3, {2, 0}}));
  EXPECT_EQ(tree.depth(), 3);
  EXPECT_NO_THROW(tree.check_invariants());
  // Neighbours of the leaf (2,0)@2 = [2,3]×[0,1]·2^50: the level-3 leaves (3,0), (3,1) across
  // its left side, the level-2 leaf (1,1) at its upper-left corner, and the level-2 leaves
  // (2,1) above, (3,0) to the right and (3,1) at the upper-right corner.
  const std::vector<CellId<2>> nb = {{2, {1, 1}}, {2, {2, 1}}, {2, {3, 0}}, {2, {3, 1}}, {3, {3, 0}}, {3, {3, 1}}};
  EXPECT_EQ(tree.neighbours(CellId<2>{2, {2, 0}}), nb);
}

/// The hand-derived T* of {origin, (2^(52−m), 0, ...)}: the two points occupy touching
/// level-m cells and nothing deeper is crowded. By induction from level m up, the split cells
/// of every level 1..m are exactly the index-(0,…) cell (crowded, or the parent of one) and the
/// index-(1,0,…) cell (it touches the split (1,0,…) cell one level deeper across the plane
/// x = 2^(52−l)); the grading cascade runs all the way to the root.
template <std::size_t d>
std::set<CellId<d>> cascade_split(int m) {
  std::set<CellId<d>> s = {CellId<d>::root()};
  for (int l = 1; l <= m; ++l) {
    CellId<d> a{l, {}};
    CellId<d> b{l, {}};
    b.index[0] = 1;
    s.insert(a);
    s.insert(b);
  }
  return s;
}

template <std::size_t d>
void check_cascade(int m) {
  std::vector<Position<d>> pts(2);
  pts[1][0] = std::uint64_t{1} << (kMaxLevel - m);
  const StaticQuadtree<d> tree(pts);
  EXPECT_EQ(split_set(tree), cascade_split<d>(m));
  const auto want = leaves_of<d>(cascade_split<d>(m), pts);
  EXPECT_EQ(std::vector<Leaf<d>>(tree.leaves().begin(), tree.leaves().end()), want);
  EXPECT_EQ(tree.leaves().size(), (kChildren<d> - 1) * (2 * static_cast<std::size_t>(m) + 1) + 1);
  EXPECT_EQ(tree.depth(), m + 1);
  EXPECT_NO_THROW(tree.check_invariants());
}

TEST(StaticQuadtree, GradingCascadeByHand) {
  for (int m : {1, 2, 3, 10, 40, 51}) {
    SCOPED_TRACE(m);
    check_cascade<2>(m);
    check_cascade<3>(m);
  }
}

TEST(StaticQuadtree, DeepestLegalPairAndResolutionError) {
  // Two grid units apart: crowded down to level 51 (touching cells), not at level 52.
  const std::vector<Position<2>> ok = {{0, 0}, {2, 0}};
  const StaticQuadtree<2> tree(ok);
  EXPECT_EQ(tree.depth(), 52);
  EXPECT_NO_THROW(tree.check_invariants());

  for (const std::vector<Position<2>>& bad : {std::vector<Position<2>>{{5, 5}, {7, 0}, {6, 6}},
                                              std::vector<Position<2>>{{0, 0}, {1, 0}}}) {
    try {
      const StaticQuadtree<2> t(bad);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_EQ(e.kind(), Kind::Resolution);
      EXPECT_NE(std::string(e.what()).find("resolution of 2^52"), std::string::npos) << e.what();
      EXPECT_EQ(e.point_indices().size(), 2u);
    }
  }
  try {
    const StaticQuadtree<3> t(std::vector<Position<3>>{{9, 9, 9}, {1, 2, 3}, {1, 2, 3}});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), Kind::Duplicate);
    EXPECT_EQ(e.point_indices(), (std::vector<std::size_t>{1, 2}));
  }
  try {
    const StaticQuadtree<2> t(std::vector<Position<2>>{{0, 0}, {kResolution, 0}});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), Kind::OutsideBox);
  }
}

TEST(StaticQuadtree, FromPointsNamesThePoint) {
  const Box<2> box{{0, 0}, 1};
  try {
    (void)StaticQuadtree<2>::from_points(box, std::vector<Point<2>>{{0.5, 0.5}, {1.5, 0.5}});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), Kind::OutsideBox);
    EXPECT_NE(std::string(e.what()).find("point 1"), std::string::npos) << e.what();
  }
}

// --- the definition, by brute force --------------------------------------------------------

template <std::size_t d>
void compare_with_definition(int grid_level, int max_points, int trials, std::uint64_t seed) {
  std::mt19937_64 gen(seed);
  for (int t = 0; t < trials; ++t) {
    // Points at corners of the level-K grid: nothing deeper than level K can be crowded.
    const int k = 1 + static_cast<int>(gen() % static_cast<unsigned>(max_points));
    std::set<Position<d>> chosen;
    const bool clustered = gen() % 2 == 0;
    const std::uint64_t span = clustered ? 4 : cells_per_axis(grid_level);
    std::array<std::uint64_t, d> base{};
    for (auto& b : base) b = clustered ? gen() % (cells_per_axis(grid_level) - 4) : 0;
    while (static_cast<int>(chosen.size()) < k) {
      Position<d> q;
      for (std::size_t a = 0; a < d; ++a) q[a] = (base[a] + gen() % span) << (kMaxLevel - grid_level);
      chosen.insert(q);
    }
    std::vector<Position<d>> pts(chosen.begin(), chosen.end());
    std::shuffle(pts.begin(), pts.end(), gen);
    const StaticQuadtree<d> tree(pts);
    const auto want = naive_tstar<d>(pts, grid_level);
    ASSERT_EQ(split_set(tree), want) << "trial " << t;
    ASSERT_EQ(std::vector<Leaf<d>>(tree.leaves().begin(), tree.leaves().end()), leaves_of<d>(want, pts));
    ASSERT_TRUE(check_tree<d>(pts, tree.leaves()).ok()) << check_tree<d>(pts, tree.leaves()).summary();
  }
}

TEST(StaticQuadtree, MatchesTheDefinitionByBruteForce2D) { compare_with_definition<2>(5, 12, 150, 1); }
TEST(StaticQuadtree, MatchesTheDefinitionByBruteForce3D) { compare_with_definition<3>(3, 10, 100, 2); }

// --- distributions -----------------------------------------------------------------------------

template <std::size_t d>
void order_independence(Distribution dist, std::size_t n) {
  auto pts = generate<d>(dist, n, 42);
  const Box<d> box = derive_box<d>(pts);
  const auto a = StaticQuadtree<d>::from_points(box, pts);
  std::mt19937_64 gen(5);
  for (int t = 0; t < 3; ++t) {
    std::shuffle(pts.begin(), pts.end(), gen);
    const auto b = StaticQuadtree<d>::from_points(box, pts);
    ASSERT_TRUE(std::equal(a.leaves().begin(), a.leaves().end(), b.leaves().begin(), b.leaves().end()))
        << distribution_name(dist);
    EXPECT_EQ(a.split_cells(), b.split_cells());
  }
}

TEST(StaticQuadtree, OrderIndependence) {
  for (const Distribution dist : all_distributions()) {
    order_independence<2>(dist, 1500);
    order_independence<3>(dist, 800);
  }
}

template <std::size_t d>
void accepts_oracle(Distribution dist, std::size_t n, double spread = 0x1p20) {
  const auto pts = generate<d>(dist, n, 7, spread);
  const auto q = located<d>(pts);
  const StaticQuadtree<d> tree(q);
  const auto rep = check_tree<d>(q, tree.leaves());
  EXPECT_TRUE(rep.ok()) << distribution_name(dist) << " d=" << d << ": " << rep.summary();
  EXPECT_NO_THROW(tree.check_invariants());
  std::size_t occupied = 0;
  for (const auto& leaf : tree.leaves()) occupied += leaf.npoints;
  EXPECT_EQ(occupied, n);
  for (const auto& p : q) {
    const CellId<d> c = tree.locate(p);
    EXPECT_TRUE(contains(c, p));
    EXPECT_EQ(tree.leaves()[tree.leaf_index(c)].npoints, 1u);
  }
}

TEST(StaticQuadtree, CheckerAcceptsTheOracleOnEveryDistribution) {
  for (const Distribution dist : all_distributions()) {
    accepts_oracle<2>(dist, 4000);
    accepts_oracle<3>(dist, 2000);
  }
}

TEST(StaticQuadtree, CheckerAcceptsShrinkingUpToSpread2To40) {
  for (const double spread : {0x1p10, 0x1p20, 0x1p30, 0x1p40}) {
    accepts_oracle<2>(Distribution::Shrinking, 3000, spread);
    accepts_oracle<3>(Distribution::Shrinking, 2000, spread);
  }
}

TEST(StaticQuadtree, DepthFollowsTheSpread) {
  // The quadtree depth is lg(L/s) + O(1) (Acar & Hudson, Section 2).
  for (const double spread : {0x1p10, 0x1p25, 0x1p40}) {
    const auto pts = generate<2>(Distribution::Shrinking, 2000, 3, spread);
    const StaticQuadtree<2> tree(located<2>(pts));
    const double lg = log2_spread<2>(derive_box<2>(pts), pts);
    EXPECT_GE(tree.depth(), lg - 2);
    EXPECT_LE(tree.depth(), lg + 4);
  }
}

// --- locate and neighbours against brute force ---------------------------------------------------

template <std::size_t d>
void locate_and_neighbours(Distribution dist, std::size_t n) {
  const auto q = located<d>(generate<d>(dist, n, 9));
  const StaticQuadtree<d> tree(q);
  const auto leaves = tree.leaves();
  std::mt19937_64 gen(3);
  for (int t = 0; t < 200; ++t) {
    Position<d> r;
    for (auto& x : r) x = gen() % kResolution;
    const CellId<d> c = tree.locate(r);
    EXPECT_TRUE(contains(c, r));
    EXPECT_TRUE(tree.is_leaf(c));
  }
  for (std::size_t i = 0; i < leaves.size(); i += std::max<std::size_t>(1, leaves.size() / 60)) {
    const CellId<d>& a = leaves[i].cell;
    std::vector<CellId<d>> want;
    for (const auto& b : leaves)
      if (b.cell != a && touches(a, b.cell)) want.push_back(b.cell);
    ASSERT_EQ(tree.neighbours(a), want) << to_string(a);
    for (const auto& b : want) {
      EXPECT_LE(std::abs(a.level - b.level), 1);
      EXPECT_FALSE(leaves[i].npoints > 0 && leaves[tree.leaf_index(b)].npoints > 0);
    }
  }
  EXPECT_THROW((void)tree.neighbours(CellId<d>::root()), std::invalid_argument);
}

TEST(StaticQuadtree, LocateAndNeighboursAgreeWithBruteForce) {
  locate_and_neighbours<2>(Distribution::Clusters, 300);
  locate_and_neighbours<2>(Distribution::Boundary, 300);
  locate_and_neighbours<3>(Distribution::Uniform, 150);
  locate_and_neighbours<3>(Distribution::Shrinking, 150);
}

// --- hand-broken trees -------------------------------------------------------------------------

template <std::size_t d>
std::vector<Leaf<d>> tree_leaves(const StaticQuadtree<d>& t) {
  return {t.leaves().begin(), t.leaves().end()};
}

/// Replaces every leaf inside `cell` by `cell` itself, holding their points.
template <std::size_t d>
std::vector<Leaf<d>> collapse(std::vector<Leaf<d>> leaves, const CellId<d>& cell) {
  std::uint32_t k = 0;
  std::erase_if(leaves, [&](const Leaf<d>& l) {
    if (!contains(cell, l.cell)) return false;
    k += l.npoints;
    return true;
  });
  leaves.push_back({cell, k});
  std::sort(leaves.begin(), leaves.end());
  return leaves;
}

/// Replaces leaf `cell` by its children.
template <std::size_t d>
std::vector<Leaf<d>> split_leaf(std::vector<Leaf<d>> leaves, const CellId<d>& cell,
                                const std::vector<Position<d>>& pts) {
  std::erase_if(leaves, [&](const Leaf<d>& l) { return l.cell == cell; });
  for (const auto& ch : children(cell)) {
    std::uint32_t k = 0;
    for (const auto& q : pts) k += contains(ch, q) ? 1 : 0;
    leaves.push_back({ch, k});
  }
  std::sort(leaves.begin(), leaves.end());
  return leaves;
}

template <std::size_t d>
std::set<ViolationKind> kinds(const CheckReport<d>& rep) {
  std::set<ViolationKind> s;
  for (const auto& v : rep.violations) s.insert(v.kind);
  return s;
}

TEST(Checker, DetectsARemovedCrowdingSplit) {
  // Cascade with m = 3: removing the split of (0,0)@3 leaves p1 alone in (0,0)@3 while p2
  // sits in the neighbouring cell (1,0)@3: the leaf is crowded and touches p2's leaf.
  std::vector<Position<2>> pts(2);
  pts[1][0] = std::uint64_t{1} << 49;
  const StaticQuadtree<2> tree(pts);
  const auto broken = collapse(tree_leaves(tree), CellId<2>{3, {0, 0}});
  const auto rep = check_tree<2>(pts, broken);
  EXPECT_TRUE(rep.has(ViolationKind::CrowdedLeaf)) << rep.summary();
  EXPECT_TRUE(rep.has(ViolationKind::TouchingOccupied)) << rep.summary();
  EXPECT_FALSE(rep.has(ViolationKind::UnjustifiedSplit)) << rep.summary();
}

TEST(Checker, DetectsARemovedGradingSplit) {
  // Find split cells that hold no point (so are not crowded) and have only leaf children: they
  // are split for grading alone. Un-splitting any of them must be reported as a grading violation.
  for (const Distribution dist : {Distribution::Clusters, Distribution::Shrinking, Distribution::Boundary}) {
    const auto pts = located<2>(generate<2>(dist, 500, 13));
    const StaticQuadtree<2> tree(pts);
    int tried = 0;
    for (const auto& s : tree.split_cells()) {
      bool bottom = true;
      for (const auto& ch : children(s)) bottom = bottom && tree.is_leaf(ch);
      if (!bottom) continue;
      bool empty = true;
      for (const auto& q : pts) empty = empty && !contains(s, q);
      if (!empty) continue;  // an empty cell is not crowded: its split is forced by grading
      const auto rep = check_tree<2>(pts, collapse(tree_leaves(tree), s));
      ASSERT_TRUE(rep.has(ViolationKind::Grading)) << to_string(s) << "\n" << rep.summary();
      if (++tried == 10) break;
    }
    EXPECT_GT(tried, 0) << distribution_name(dist);
  }
}

TEST(Checker, DetectsAnUnjustifiedSplit) {
  // One point: T* is the root alone. Splitting the root is unjustified and breaks nothing else.
  const std::vector<Position<2>> one = {{123, 456}};
  const StaticQuadtree<2> t1(one);
  const auto rep1 = check_tree<2>(one, split_leaf(tree_leaves(t1), CellId<2>::root(), one));
  ASSERT_EQ(rep1.violations.size(), 1u) << rep1.summary();
  EXPECT_EQ(rep1.violations[0].kind, ViolationKind::UnjustifiedSplit);
  EXPECT_EQ(rep1.violations[0].cell, CellId<2>::root());

  // Cascade with m = 3: the empty level-1 leaf (0,1) touches no split level-2 cell (those lie
  // below y = 2^50), so splitting it is unjustified; its children keep the grading.
  std::vector<Position<2>> pts(2);
  pts[1][0] = std::uint64_t{1} << 49;
  const StaticQuadtree<2> tree(pts);
  const auto rep = check_tree<2>(pts, split_leaf(tree_leaves(tree), CellId<2>{1, {0, 1}}, pts));
  ASSERT_EQ(rep.violations.size(), 1u) << rep.summary();
  EXPECT_EQ(rep.violations[0].kind, ViolationKind::UnjustifiedSplit);
  EXPECT_EQ(rep.violations[0].cell, (CellId<2>{1, {0, 1}}));

  // In 3D, splitting a deepest empty leaf is unjustified (and breaks the grading too).
  const auto q3 = located<3>(generate<3>(Distribution::Uniform, 200, 4));
  const StaticQuadtree<3> t3(q3);
  const auto deepest = t3.leaves().back();
  ASSERT_EQ(deepest.cell.level, t3.depth());
  auto leaves3 = tree_leaves(t3);
  const auto it = std::find_if(leaves3.rbegin(), leaves3.rend(), [](const Leaf<3>& l) { return l.npoints == 0; });
  ASSERT_NE(it, leaves3.rend());
  const auto rep3 = check_tree<3>(q3, split_leaf(leaves3, it->cell, q3));
  EXPECT_TRUE(rep3.has(ViolationKind::UnjustifiedSplit)) << rep3.summary();
}

TEST(Checker, DetectsMergedOccupiedLeaves) {
  // Merging the cell that holds both points of the cascade into one leaf: overfull.
  std::vector<Position<2>> pts(2);
  pts[1][0] = std::uint64_t{1} << 49;
  const StaticQuadtree<2> tree(pts);
  const auto rep = check_tree<2>(pts, collapse(tree_leaves(tree), CellId<2>{2, {0, 0}}));
  EXPECT_TRUE(rep.has(ViolationKind::Overfull)) << rep.summary();
  // Two occupied leaves that touch: add a point to the leaf next to p1's without refining.
  auto pts2 = pts;
  pts2.push_back({0, std::uint64_t{1} << 48});  // in (0,1)@4, touching p1's leaf (0,0)@4
  auto leaves = tree_leaves(tree);
  for (auto& l : leaves)
    if (l.cell == CellId<2>{4, {0, 1}}) l.npoints = 1;
  const auto rep2 = check_tree<2>(pts2, leaves);
  EXPECT_TRUE(rep2.has(ViolationKind::TouchingOccupied)) << rep2.summary();
  EXPECT_TRUE(rep2.has(ViolationKind::CrowdedLeaf)) << rep2.summary();
}

TEST(Checker, DetectsStructuralDamage) {
  std::vector<Position<2>> pts(2);
  pts[1][0] = std::uint64_t{1} << 49;
  const StaticQuadtree<2> tree(pts);
  const auto good = tree_leaves(tree);
  ASSERT_TRUE(check_tree<2>(pts, good).ok());

  auto gap = good;
  gap.erase(gap.begin() + 3);
  EXPECT_EQ(kinds(check_tree<2>(pts, gap)), std::set<ViolationKind>{ViolationKind::Gap});

  auto overlap = good;
  overlap.push_back({CellId<2>{2, {0, 0}}, 0});
  EXPECT_TRUE(check_tree<2>(pts, overlap).has(ViolationKind::Overlap));

  auto dup = good;
  dup.push_back(good.front());
  EXPECT_TRUE(check_tree<2>(pts, dup).has(ViolationKind::DuplicateLeaf));

  auto bad = good;
  bad.push_back({CellId<2>{1, {2, 0}}, 0});
  EXPECT_TRUE(check_tree<2>(pts, bad).has(ViolationKind::BadCell));

  auto miscount = good;
  miscount[0].npoints = 1;
  EXPECT_EQ(kinds(check_tree<2>(pts, miscount)), std::set<ViolationKind>{ViolationKind::CountMismatch});

  EXPECT_TRUE(check_tree<2>(pts, std::vector<Leaf<2>>{}).has(ViolationKind::Gap));
  EXPECT_THROW(require_valid_tree<2>(pts, gap), InvariantError);
}

TEST(Checker, AcceptsLeavesInAnyOrder) {
  const auto pts = located<3>(generate<3>(Distribution::Clusters, 400, 2));
  const StaticQuadtree<3> tree(pts);
  auto leaves = tree_leaves(tree);
  std::mt19937_64 gen(8);
  std::shuffle(leaves.begin(), leaves.end(), gen);
  EXPECT_TRUE(check_tree<3>(pts, leaves).ok()) << check_tree<3>(pts, leaves).summary();
  leaves.push_back(leaves[17]);
  EXPECT_EQ(kinds(check_tree<3>(pts, leaves)), std::set<ViolationKind>{ViolationKind::DuplicateLeaf});
}

TEST(Checker, ReportIsCapped) {
  const auto pts = located<2>(generate<2>(Distribution::Uniform, 2000, 1));
  // The single root leaf for 2000 points: overfull, count mismatch, crowded... and no more
  // than max_violations entries.
  const std::vector<Leaf<2>> root = {{CellId<2>::root(), 0}};
  const auto rep = check_tree<2>(pts, root, 1);
  EXPECT_EQ(rep.violations.size(), 1u);
  EXPECT_TRUE(rep.truncated);
  EXPECT_NE(rep.summary().find("more"), std::string::npos);
}

// --- size ------------------------------------------------------------------------------------

template <std::size_t d>
void timed_build(Distribution dist, std::size_t n, double spread = 0x1p20) {
  const auto q = located<d>(generate<d>(dist, n, 17, spread));
  const auto t0 = std::chrono::steady_clock::now();
  const StaticQuadtree<d> tree(q);
  const auto t1 = std::chrono::steady_clock::now();
  const auto rep = check_tree<d>(q, tree.leaves());
  const auto t2 = std::chrono::steady_clock::now();
  EXPECT_TRUE(rep.ok()) << rep.summary();
  const double build = std::chrono::duration<double>(t1 - t0).count();
  const double check = std::chrono::duration<double>(t2 - t1).count();
  std::printf("    [%s d=%zu n=%zu] %zu leaves, depth %d: build %.3f s, check %.3f s\n",
              std::string(distribution_name(dist)).c_str(), d, n, tree.leaves().size(), tree.depth(), build, check);
  // Printed, not asserted: the machines are shared (bench/ measures the build's speed).
}

TEST(StaticQuadtree, HundredThousandPoints) {
#ifdef NDEBUG
  constexpr std::size_t n = 100000;
#else
  constexpr std::size_t n = 20000;  // debug and sanitizer builds: correctness only
#endif
  timed_build<2>(Distribution::Uniform, n);
  timed_build<3>(Distribution::Uniform, n);
  timed_build<2>(Distribution::Shrinking, n, 0x1p40);
  timed_build<3>(Distribution::Clusters, n);
}

}  // namespace
