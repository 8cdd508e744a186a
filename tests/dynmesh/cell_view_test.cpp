// Tests of cell_interest.hpp's record of what a step used of a cell (CellInterest): the 256ths
// of a box hold every vertex inside the box, whatever the cell and the rounding, and a change
// of a leaf counts exactly when it changes the vertices inside the used box (or the kind).
// The program's reads that rely on it are checked end to end by hpu_cells_program_test.cpp
// (every update against the twin). Also the directory's node links and the one view that
// may keep its marks on the nodes, and the nearest search from a focus's leaf upwards
// (search_near), which must visit what the search from the root visits, in its order; and
// follow_cell, where a read of a leaf that split or merged away moves.
#include "hpu/cell_view.hpp"

#include <gtest/gtest.h>

#include <algorithm>
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
  // All of it: any other vertex set changes it; none of it: nothing does, the kind included
  // (the step's answers held whatever the cell held).
  EXPECT_TRUE(interest_changed(box, k, CellInterest{}, before, leaf({a, b, c, d})));
  EXPECT_FALSE(interest_changed(box, k, CellInterest::none(), before, leaf({d})));
  EXPECT_FALSE(interest_changed(box, k, CellInterest::none(), before, CellState{}));  // absent
  EXPECT_FALSE(interest_changed(box, k, CellInterest::none(), before, CellState::split()));
}

// follow_cell: when a read's leaf split or merged away, the cell it moves to must hold, inside
// the used box, exactly the vertices the step saw there, and its new interest must hold every
// point of the used box that lies in the old cell (so that a later change there is seen).
// Random cells, used boxes and vertex sets, a third of them with a vertex that came inside
// the used box; the test counts both outcomes.
TEST(FollowCell, TheCellItFollowsToHoldsWhatTheStepUsed) {
  std::mt19937_64 rng(20261129);
  std::printf("seed 20261129\n");
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int followed[2] = {0, 0}, refused[2] = {0, 0};
  for (int t = 0; t < 4000; ++t) {
    sac::Engine rt;
    const Box<2> box{{-3.7 + u(rng), 1e3 * u(rng)}, 0.1 + 100 * u(rng)};
    CellDirectory dir(box);
    const int level = 1 + static_cast<int>(rng() % 20);
    const std::uint64_t side = std::uint64_t{1} << level;
    CellNode* n = dir.node(rt, CellKey{level, rng() % side, rng() % side});
    const bool up = t % 2 == 1;  // a merge above n, else a split of n
    CellNode* p = dir.node(rt, n->key.parent());
    for (unsigned c = 0; c < 4; ++c) dir.node(rt, (up ? p : n)->key.child(c));
    const CellFrame fn(box, n->key);
    const double w = 256.0 / fn.inv;
    const auto in_cell = [&](const CellKey& k, const Point<2>& x) {
      return k.contains(CellDirectory::cell_at(dir.position(x), k.level));
    };
    // Points of a region: of n, or of n's parent for a merge.
    const CellKey region = up ? p->key : n->key;
    const CellFrame fr(box, region);
    std::deque<CellVertex> store;
    const auto point_in = [&](const CellKey& k) {
      const CellFrame f(box, k);
      const double wk = 256.0 / f.inv;
      for (;;) {
        const Point<2> x{f.ox + wk * u(rng), f.oy + wk * u(rng)};
        if (in_cell(k, x)) return &store.emplace_back(x);
      }
    };
    std::vector<const CellVertex*> seen_v, now_v;
    const int k_seen = 1 + static_cast<int>(rng() % 6);
    for (int i = 0; i < k_seen; ++i) seen_v.push_back(point_in(n->key));
    now_v = seen_v;
    // The used box, near n.
    const double x0 = fn.ox + w * (1.4 * u(rng) - 0.2), x1 = x0 + w * 0.6 * u(rng);
    const double y0 = fn.oy + w * (1.4 * u(rng) - 0.2), y1 = y0 + w * 0.6 * u(rng);
    const auto in_used = [&](const Point<2>& x) { return x[0] >= x0 && x[0] <= x1 && x[1] >= y0 && x[1] <= y1; };
    if (up)
      for (int i = static_cast<int>(rng() % 3); i > 0; --i) now_v.push_back(point_in(region));  // siblings'
    switch (rng() % 3) {
      case 0:  // one came, anywhere
        now_v.push_back(point_in(region));
        break;
      case 1:  // one came inside the used box, in n, when there is room
        for (int i = 0; i < 50; ++i) {
          const Point<2> x{x0 + (x1 - x0) * u(rng), y0 + (y1 - y0) * u(rng)};
          if (in_used(x) && in_cell(n->key, x)) {
            now_v.push_back(&store.emplace_back(x));
            break;
          }
        }
        break;
      default:  // one of n's left
        if (now_v.size() > 1) now_v.erase(now_v.begin() + static_cast<std::ptrdiff_t>(rng() % seen_v.size()));
    }
    if (now_v.size() > CellState::kCapacity) continue;
    CellInterest in = fn.interest(x0, y0, x1, y1);
    const CellState seen = CellState::leaf(seen_v.begin(), seen_v.end());
    // The store at the read's time: n split into four leaves, or n's parent one leaf.
    std::vector<std::pair<CellNode*, CellState>> values;
    if (up) {
      values.emplace_back(p, CellState::leaf(now_v.begin(), now_v.end()));
    } else {
      values.emplace_back(n, CellState::split());
      for (unsigned c = 0; c < 4; ++c) {
        std::vector<const CellVertex*> mine;
        for (const CellVertex* v : now_v)
          if (in_cell(n->child[c]->key, v->p)) mine.push_back(v);
        values.emplace_back(n->child[c], CellState::leaf(mine.begin(), mine.end()));
      }
    }
    const auto value = [&](const CellNode* x) -> const CellState* {
      for (const auto& [node, s] : values)
        if (node == x) return &s;
      return nullptr;  // never written: absent
    };
    const CellState now = up ? CellState{} : CellState::split();
    CellInterest moved = in;
    CellNode* d = follow_cell(box, dir, n, &moved, seen, now, value);
    // Did the vertices inside the used box, in n, change?
    std::vector<const CellVertex*> a, b;
    for (const CellVertex* v : seen_v)
      if (in_used(v->p)) a.push_back(v);
    for (const CellVertex* v : now_v)
      if (in_used(v->p) && in_cell(n->key, v->p)) b.push_back(v);
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    const bool changed = a != b;
    if (!d) {
      ++refused[changed];
      continue;
    }
    ++followed[changed];
    ASSERT_FALSE(changed) << "followed a read whose used vertices changed, try " << t;
    ASSERT_NE(value(d), nullptr);
    ASSERT_EQ(value(d)->kind, CellState::Leaf) << "try " << t;
    ASSERT_TRUE(up ? d->key.contains(n->key) : n->key.contains(d->key)) << "try " << t;
    // Every vertex inside the used box in n is in d, and inside d's new interest; so is any
    // point of the used box in n (a vertex that may come later).
    const CellFrame fd(box, d->key);
    for (const CellVertex* v : now_v)
      if (in_used(v->p) && in_cell(n->key, v->p)) {
        ASSERT_TRUE(in_cell(d->key, v->p)) << "try " << t;
        ASSERT_TRUE(fd.inside(moved, v->p)) << "try " << t;
      }
    for (int i = 0; i < 20; ++i) {
      const Point<2> x{x0 + (x1 - x0) * u(rng), y0 + (y1 - y0) * u(rng)};
      if (in_used(x) && in_cell(n->key, x)) {
        ASSERT_TRUE(in_cell(d->key, x)) << "try " << t;
        ASSERT_TRUE(fd.inside(moved, x)) << "try " << t;
      }
    }
  }
  std::printf("followed %d (changed %d), refused %d (changed %d)\n", followed[0] + followed[1], followed[1],
              refused[0] + refused[1], refused[1]);
  EXPECT_GT(followed[0], 200);
  EXPECT_GT(refused[1], 200);
}

TEST(FollowCell, AWholeCellOrALeafStillALeafNeverFollows) {
  sac::Engine rt;
  const Box<2> box{{0, 0}, 16};
  CellDirectory dir(box);
  CellNode* n = dir.node(rt, CellKey{2, 1, 1});  // [4, 8] × [4, 8]
  for (unsigned c = 0; c < 4; ++c) dir.node(rt, n->key.child(c));
  std::deque<CellVertex> vs;
  const CellVertex* a = &vs.emplace_back(Point<2>{4.5, 4.5});
  const CellVertex* b = &vs.emplace_back(Point<2>{7.5, 7.5});
  const CellState seen = CellState::leaf(&a, &a + 1);
  const CellState lower_left = CellState::leaf(&a, &a + 1), upper_right = CellState::leaf(&b, &b + 1);
  const auto value = [&](const CellNode* x) -> const CellState* {
    static const CellState split = CellState::split(), empty = CellState::leaf(&a, &a);
    if (x == n) return &split;
    if (x == n->child[0]) return &lower_left;
    if (x == n->child[3]) return &upper_right;
    return &empty;
  };
  // Used near a, in the lower left quarter: follows there.
  CellInterest in = CellFrame(box, n->key).interest(4.2, 4.2, 5, 5);
  EXPECT_EQ(follow_cell(box, dir, n, &in, seen, CellState::split(), value), n->child[0]);
  // The whole cell (an insertion's leaf): never.
  in = CellInterest{};
  EXPECT_EQ(follow_cell(box, dir, n, &in, seen, CellState::split(), value), nullptr);
  // Across the children's border: no one child holds it.
  in = CellFrame(box, n->key).interest(4.2, 4.2, 6.5, 5);
  EXPECT_EQ(follow_cell(box, dir, n, &in, seen, CellState::split(), value), nullptr);
  // Still a leaf: a change of its vertices, not of its cell.
  in = CellFrame(box, n->key).interest(4.2, 4.2, 5, 5);
  EXPECT_EQ(follow_cell(box, dir, n, &in, seen, CellState::leaf(&b, &b + 1), value), nullptr);
}

TEST(CellDirectory, NodesLinkTheirParentAndChildrenWhateverTheOrderMade) {
  sac::Engine rt;
  CellDirectory dir(Box<2>{{0, 0}, 1});
  CellNode* c = dir.node(rt, CellKey{2, 1, 2});  // below a cell not made yet
  CellNode* root = dir.node(rt, CellKey{});
  CellNode* mid = dir.node(rt, CellKey{1, 0, 1});
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
  sac::Engine rt;
  CellDirectory dir(Box<2>{{0, 0}, 1});
  CellNode* root = dir.node(rt, CellKey{});
  {
    CellView v(rt, dir);
    EXPECT_THROW(CellView(rt, dir), dynmesh::InvariantError);
    root->mark.gen = 1;  // as a step of the first view leaves it
    root->mark.read = true;
  }
  CellView w(rt, dir);  // the first is gone: the marks start clean
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
  sac::Engine rt;
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
    in.insert(rt, &vs.emplace_back(x));
  }
  for (int i = 1; i < 16; ++i) in.insert(rt, &vs.emplace_back(Point<2>{box.origin[0] + box.side * i / 16, box.origin[1] + box.side / 2}));
  CellView view(rt, dir);
  std::size_t focused = 0;
  rt.run([&](sac::Engine&) {  // a view peeks, which only the computation may
    for (const CellVertex& v : vs) {
      NearestRecord down{v.p, std::numeric_limits<double>::infinity(), {}};
      NearestRecord up = down;
      view.begin_run();
      view.search(v.p, 0.0, dir.margin_for(v.p, 0.0), [&](double a, double b, double c, double d) { return down.keep(a, b, c, d); },
                  [&](const CellVertex* w) { return down.see(w); });
      view.used_all();
      view.begin_run();
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
