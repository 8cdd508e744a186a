// Tests of cell_view.hpp's record of what a step used of a cell (CellInterest): the 256ths
// of a box hold every vertex inside the box, whatever the cell and the rounding, and a change
// of a leaf counts exactly when it changes the vertices inside the used box (or the kind).
// The program's reads that rely on it are checked end to end by hpu_cells_program_test.cpp
// (every update against the twin). Also the directory's node links and the one view that
// may keep its marks on the nodes, and the nearest search from a focus's leaf upwards
// (search_near), which must visit what the search from the root visits, in its order.
#include "hpu/cell_view.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <deque>
#include <limits>
#include <random>
#include <vector>

#include <sac/engine.hpp>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"
#include "hpu/cell_store.hpp"

namespace {

using dynmesh::Box;
using dynmesh::Point;
using namespace dynmesh::detail;

TEST(CellInterest, EveryVertexInsideABoxIsInsideItsParts) {
  std::mt19937_64 rng(20261127);
  std::printf("seed 20261127\n");
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int t = 0; t < 20000; ++t) {
    // A box of awkward origin and side, a cell of some level, a used box near the cell, and
    // points on and inside its edges (the rounding cases).
    const Box<2> box{{-3.7 + u(rng), 1e3 * u(rng)}, 0.1 + 100 * u(rng)};
    const int level = static_cast<int>(rng() % 30);
    const std::uint64_t n = std::uint64_t{1} << level;
    const CellKey k{level, rng() % n, rng() % n};
    const CellFrame f(box, k);
    const double w = std::ldexp(box.side, -level);
    ASSERT_EQ(f.inv, 256.0 / w) << "the frame's width is ldexp's, try " << t;
    const double x0 = f.ox + w * (1.4 * u(rng) - 0.2), x1 = x0 + w * u(rng);
    const double y0 = f.oy + w * (1.4 * u(rng) - 0.2), y1 = y0 + w * u(rng);
    const CellInterest in = f.interest(x0, y0, x1, y1);
    const Point<2> corners[] = {{x0, y0}, {x1, y1}, {x0, y1}, {x1, y0}};
    for (const Point<2>& p : corners) ASSERT_TRUE(f.inside(in, p)) << "try " << t;
    const Point<2> mid{x0 + (x1 - x0) * u(rng), y0 + (y1 - y0) * u(rng)};
    if (mid[0] >= x0 && mid[0] <= x1 && mid[1] >= y0 && mid[1] <= y1) {
      ASSERT_TRUE(f.inside(in, mid)) << "try " << t;
    }
  }
}

TEST(CellInterest, APartIsTheFloorOfTheScaledOffsetClamped) {
  // part() truncates instead of calling std::floor: the same 256ths, on the grid lines too.
  std::mt19937_64 rng(20261128);
  std::printf("seed 20261128\n");
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int t = 0; t < 20000; ++t) {
    const double o = -10 + 20 * u(rng), inv = std::ldexp(256.0, static_cast<int>(rng() % 60) - 30);
    const double on_line = o + static_cast<double>(rng() % 300) / inv - 20 / inv;
    for (const double x : {o + (1.4 * u(rng) - 0.2) * 256 / inv, on_line, std::nextafter(on_line, 1e300),
                           std::nextafter(on_line, -1e300), o, std::nextafter(o, -1e300)}) {
      const double f = std::floor((x - o) * inv);
      const auto expected = static_cast<std::uint8_t>(f <= 0 ? 0 : f >= 255 ? 255 : f);
      ASSERT_EQ(CellFrame::part(x, o, inv), expected) << "x = " << x << ", o = " << o << ", try " << t;
    }
  }
}

TEST(CellInterest, ALeafChangesForAReadOnlyInsideWhatItUsed) {
  const Box<2> box{{0, 0}, 16};
  const CellKey k{2, 1, 1};  // [4, 8] × [4, 8]
  std::deque<CellVertex> vs;
  const auto v = [&](double x, double y) { return &vs.emplace_back(Point<2>{x, y}); };
  const CellVertex *a = v(4.5, 4.5), *b = v(5, 7), *c = v(7.5, 7.5), *d = v(7.6, 4.2), *e = v(4.4, 4.6);
  const auto leaf = [](std::vector<const CellVertex*> xs) { return CellState::leaf(xs.begin(), xs.end()); };
  const CellState before = leaf({a, b, c});
  const CellInterest lower_left = CellFrame(box, k).interest(4, 4, 5.5, 5.5);  // holds a, not b or c

  EXPECT_FALSE(interest_changed(box, k, lower_left, before, leaf({a, b})));     // c left: outside
  EXPECT_FALSE(interest_changed(box, k, lower_left, before, leaf({a, b, c, d})));  // d came: outside
  EXPECT_TRUE(interest_changed(box, k, lower_left, before, leaf({b, c})));      // a left
  EXPECT_TRUE(interest_changed(box, k, lower_left, before, leaf({a, b, c, e})));  // e came: inside
  EXPECT_TRUE(interest_changed(box, k, lower_left, before, CellState::split()));  // a kind change
  // All of it: any other vertex set changes it; none of it: only the kind does.
  EXPECT_TRUE(interest_changed(box, k, CellInterest{}, before, leaf({a, b, c, d})));
  EXPECT_FALSE(interest_changed(box, k, CellInterest::none(), before, leaf({d})));
  EXPECT_TRUE(interest_changed(box, k, CellInterest::none(), before, CellState{}));  // absent
}

TEST(CellDirectory, NodesLinkTheirParentAndChildrenWhateverTheOrderMade) {
  sac::Engine e;
  CellDirectory dir(Box<2>{{0, 0}, 1});
  CellNode* c = dir.node(e, CellKey{2, 1, 2});  // below a cell not made yet
  CellNode* root = dir.node(e, CellKey{});
  CellNode* mid = dir.node(e, CellKey{1, 0, 1});
  EXPECT_EQ(c->parent, mid);
  EXPECT_EQ(mid->parent, root);
  EXPECT_EQ(root->parent, nullptr);
  EXPECT_EQ(mid->child[CellDirectory::child_index(c->key)], c);
  EXPECT_EQ(root->child[CellDirectory::child_index(mid->key)], mid);
  EXPECT_EQ(root->child[0], nullptr);
  EXPECT_NO_THROW(dir.check_invariants());
  mid->child[0] = c;  // a link that is not the lookup
  EXPECT_THROW(dir.check_invariants(), dynmesh::InvariantError);
  mid->child[0] = nullptr;
  c->parent = nullptr;
  EXPECT_THROW(dir.check_invariants(), dynmesh::InvariantError);
}

TEST(CellDirectory, OneViewAtATimeKeepsItsMarksOnTheNodes) {
  sac::Engine e;
  CellDirectory dir(Box<2>{{0, 0}, 1});
  CellNode* root = dir.node(e, CellKey{});
  {
    CellView v(e, dir);
    EXPECT_THROW(CellView(e, dir), dynmesh::InvariantError);
    root->mark.gen = 1;  // as a step of the first view leaves it
    root->mark.read = true;
  }
  CellView w(e, dir);  // the first is gone: the marks start clean
  EXPECT_EQ(root->mark.gen, 0u);
  EXPECT_FALSE(root->mark.read);
}

// The nearest search's keep() and a record of the vertices handed over, in order.
struct NearestRecord {
  Point<2> p;
  double best = std::numeric_limits<double>::infinity();
  std::vector<const CellVertex*> seen;
  double reach() const { return best * (1 + 0x1p-19); }
  bool keep(double x0, double y0, double x1, double y1) const {
    const double dx = p[0] < x0 ? x0 - p[0] : p[0] > x1 ? p[0] - x1 : 0.0;
    const double dy = p[1] < y0 ? y0 - p[1] : p[1] > y1 ? p[1] - y1 : 0.0;
    return std::hypot(dx, dy) <= reach();
  }
  bool see(const CellVertex* w) {
    seen.push_back(w);
    if (w->p == p) return false;  // the focus's own vertex
    best = std::min(best, std::hypot(w->p[0] - p[0], w->p[1] - p[1]));
    return false;
  }
};

TEST(CellView, TheNearestSearchFromTheLeafUpVisitsWhatTheSearchFromTheRootVisits) {
  std::mt19937_64 rng(20261128);
  std::printf("seed 20261128\n");
  std::uniform_real_distribution<double> u(0.0, 1.0);
  sac::Engine e;
  const Box<2> box{{-2.1, 3.3}, 7.7};  // inexact, so that points on midlines round either way
  CellDirectory dir(box);
  InputCells in(dir);
  std::deque<CellVertex> vs;
  // Clustered and spread points, so that leaves lie at many levels, and points on the
  // midlines of cells, where a focus's grid position and the search's side tests can part.
  for (int i = 0; i < 3000; ++i) {
    const double s = i % 3 == 0 ? 1.0 : i % 3 == 1 ? 1.0 / 64 : 1.0 / 4096;
    const Point<2> x{box.origin[0] + box.side * (s * u(rng) + (1 - s) * 0.3),
                     box.origin[1] + box.side * (s * u(rng) + (1 - s) * 0.6)};
    in.insert(e, &vs.emplace_back(x));
  }
  for (int i = 1; i < 16; ++i) in.insert(e, &vs.emplace_back(Point<2>{box.origin[0] + box.side * i / 16, box.origin[1] + box.side / 2}));
  CellView view(e, dir);
  std::size_t focused = 0;
  e.run([&](sac::Engine&) {  // a view peeks, which only the computation may
    for (const CellVertex& v : vs) {
      NearestRecord down{v.p, std::numeric_limits<double>::infinity(), {}};
      NearestRecord up = down;
      view.reset();
      view.search(v.p, 0.0, dir.margin_for(v.p, 0.0), [&](double a, double b, double c, double d) { return down.keep(a, b, c, d); },
                  [&](const CellVertex* w) { return down.see(w); });
      view.used_all();
      view.reset();
      view.search_near(v.p, 0.0, dir.margin_for(v.p, 0.0), [&](double a, double b, double c, double d) { return up.keep(a, b, c, d); },
                       [&](const CellVertex* w) { return up.see(w); }, [&] { return up.reach(); });
      view.used_all();
      ASSERT_EQ(up.seen, down.seen) << "at (" << v.p[0] << ", " << v.p[1] << ")";
      focused += up.seen.size() < 200;
    }
  });
  EXPECT_GT(focused, vs.size() * 9 / 10) << "most searches see a few cells only";
}

}  // namespace
