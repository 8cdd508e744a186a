// sa_bucket_tree_test.cpp — src/hpu/sa_bucket_tree.hpp: the self-adjusting bucket tree is
// the BucketTree of the inserted vertices after run() and after every propagate(), on
// random insertions and deletions (fixed seeds), with the engine's checker and a trace of
// the size a from-scratch run leaves.
#include "hpu/sa_bucket_tree.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <deque>
#include <random>
#include <string>
#include <vector>

#include <sac/engine.hpp>
#include <sac/fn.hpp>
#include <sac/mod.hpp>

#include "dynamic_test_support.hpp"
#include "hpu/bucket_tree.hpp"

namespace {

using namespace dynmesh;
using detail::SaBucketTree;
using dynmesh_test::kSanitized;

/// The input: vertex ids in insertion order, a modifiable list.
struct Cell {
  explicit Cell(std::uint32_t v) : id(v) {}
  std::uint32_t id;
  sac::Mod<Cell*> next;
};

void insert_all(sac::Engine& e, Cell* c, SaBucketTree* t) {
  if (!c) return;
  SaBucketTree::insert(e, t, c->id);
  e.memo_read(c->next, sac::fn<&insert_all>(t));
}

/// A list, an engine and a tree built from scratch on `ids`: the reference run.
struct TreeRun {
  TreeRun(const Box<2>& box, std::span<const Point<2>> pts, const std::vector<std::uint32_t>& ids) : tree(e, box, pts) {
    for (const std::uint32_t v : ids) cells.emplace_back(v);
    for (std::size_t i = 0; i < cells.size(); ++i) e.set(cells[i].next, i + 1 < cells.size() ? &cells[i + 1] : nullptr);
    e.set(head, cells.empty() ? nullptr : &cells[0]);
    e.run([this](sac::Engine& en) { en.memo_read(head, sac::fn<&insert_all>(&tree)); });
  }
  sac::Engine e;
  SaBucketTree tree;
  std::deque<Cell> cells;
  sac::Mod<Cell*> head;
};

std::vector<detail::BucketLeaf> static_leaves(const Box<2>& box, std::span<const Point<2>> pts,
                                              const std::vector<std::uint32_t>& ids) {
  detail::BucketTree t(box);
  for (const std::uint32_t v : ids) t.insert(v, pts[v], pts);
  return t.leaves();
}

TEST(SaBucketTree, EqualsTheStaticTreeAfterEveryUpdate) {
  const Box<2> box{{-1, -1}, 2};
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    const std::size_t n = kSanitized ? 150 : 600, updates = kSanitized ? 40 : 150;
    // Points in clusters at several scales (deep splits), ids by position in `pts`.
    std::vector<Point<2>> pts;
    pts.reserve(n + updates);
    while (pts.size() < n + updates) {
      const double s = std::ldexp(1.0, -4 - static_cast<int>(u(rng) * 20));  // at most 1/16
      const Point<2> c{-0.9 + 1.7 * u(rng), -0.9 + 1.7 * u(rng)};              // inside the box
      for (int k = 0; k < 12 && pts.size() < n + updates; ++k) pts.push_back(Point<2>{c[0] + s * u(rng), c[1] + s * u(rng)});
    }
    std::vector<std::uint32_t> ids(n);
    for (std::uint32_t i = 0; i < n; ++i) ids[i] = i;
    std::shuffle(ids.begin(), ids.end(), rng);

    TreeRun dyn(box, pts, ids);
    ASSERT_EQ(dyn.tree.leaves(), static_leaves(box, pts, ids));
    std::uint32_t fresh = static_cast<std::uint32_t>(n);
    // The dynamic list, as cells in order (the mutator relinks them).
    std::vector<Cell*> order;
    for (auto& c : dyn.cells) order.push_back(&c);
    double distance = 0;
    for (std::size_t step = 0; step < updates; ++step) {
      const bool erase = !order.empty() && (rng() % 2 == 0);
      const std::size_t at = order.empty() ? 0 : rng() % (order.size() + (erase ? 0 : 1));
      sac::Mod<Cell*>& link = at == 0 ? dyn.head : order[at - 1]->next;
      if (erase) {
        dyn.e.set(link, order[at]->next.get());
        order.erase(order.begin() + static_cast<std::ptrdiff_t>(at));
      } else {
        Cell* c = &dyn.cells.emplace_back(fresh++);
        dyn.e.set(c->next, at < order.size() ? order[at] : nullptr);
        dyn.e.set(link, c);
        order.insert(order.begin() + static_cast<std::ptrdiff_t>(at), c);
      }
      dyn.e.propagate();
      distance += static_cast<double>(dyn.e.stats().last_trace_distance) / static_cast<double>(updates);
      std::vector<std::uint32_t> now;
      for (const Cell* c : order) now.push_back(c->id);
      ASSERT_EQ(dyn.tree.leaves(), static_leaves(box, pts, now)) << "after update " << step;
      if (step % 10 == 0) {
        dyn.e.check_invariants();
        TreeRun scratch(box, pts, now);
        EXPECT_EQ(dyn.e.live_events(), scratch.e.live_events()) << "after update " << step;
      }
    }
    // An update re-runs its own descent and the later insertions that read a node it
    // changed. Where it was one of the first kCapacity + 1 points of a cell, that cell splits
    // at another insertion and the later insertions below it re-run too: about
    // kCapacity·depth insertions of depth reads each, in expectation over the order, far
    // below n·depth (measured: 330-560 events at n = 600). Inputs placed by a memoized
    // partition, as QuadTreeRefine places them, would cost O(depth) (docs/HPU_ON_CELLS.md).
    std::printf("seed %llu: mean trace distance per update %.1f (n = %zu)\n", static_cast<unsigned long long>(seed),
                distance, n);
    EXPECT_LT(distance, 1500.0);
  }
}

TEST(SaBucketTree, AGridSplitsIntoItsExpectedLeaves) {
  // 64 points on an 8 x 8 grid: every cell of level 2 holds 4, so the tree stops there.
  const Box<2> box{{0, 0}, 1};
  std::vector<Point<2>> pts;
  for (int i = 0; i < 64; ++i) pts.push_back(Point<2>{(i % 8 + 0.5) / 8, (i / 8 + 0.5) / 8});
  std::vector<std::uint32_t> ids(pts.size());
  for (std::uint32_t i = 0; i < ids.size(); ++i) ids[i] = i;
  TreeRun r(box, pts, ids);
  const auto leaves = r.tree.leaves();
  EXPECT_EQ(leaves, static_leaves(box, pts, ids));
  ASSERT_EQ(leaves.size(), 16u);
  for (const auto& l : leaves) {
    EXPECT_EQ(l.level, 2);
    EXPECT_EQ(l.items.size(), 4u);
  }
}

}  // namespace
