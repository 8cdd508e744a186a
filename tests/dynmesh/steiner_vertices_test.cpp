// steiner_vertices_test.cpp — src/hpu/steiner_vertices.hpp: one vertex object per point while
// it is referenced, kept through a release to no references until collect(), freed by it;
// differential against a map of reference counts under random acquires and releases (the
// table's deletions move entries back), with the checker after every batch; the checker
// catches a release without an acquire.
#include "hpu/steiner_vertices.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <map>
#include <random>
#include <vector>

#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh::detail {
namespace {

TEST(SteinerVertices, OnePointOneObject) {
  SteinerVertices sv;
  const CellVertex* a = sv.acquire(Point<2>{0.25, 0.5});
  const CellVertex* b = sv.acquire(Point<2>{0.25, 0.5});
  const CellVertex* c = sv.acquire(Point<2>{0.5, 0.25});
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  EXPECT_EQ(a->p, (Point<2>{0.25, 0.5}));
  EXPECT_EQ(sv.size(), 2u);
  // Equal as doubles, as the trace's keys compare them: -0.0 is 0.0.
  EXPECT_EQ(sv.acquire(Point<2>{0.0, 1.0}), sv.acquire(Point<2>{-0.0, 1.0}));
  EXPECT_NO_THROW(sv.check_invariants());
}

/// The property the program needs: a vertex released to no references and made again
/// within one propagation (before collect()) is the same object.
TEST(SteinerVertices, ReleasedAndMadeAgainBeforeCollectIsTheSameObject) {
  SteinerVertices sv;
  const CellVertex* a = sv.acquire(Point<2>{0.125, 0.75});
  sv.release(a);
  EXPECT_EQ(sv.size(), 1u);  // idle, not freed
  EXPECT_EQ(sv.acquire(Point<2>{0.125, 0.75}), a);
  sv.collect();
  EXPECT_EQ(sv.size(), 1u);  // referenced again: kept
  sv.release(a);
  sv.collect();
  EXPECT_EQ(sv.size(), 0u);
  EXPECT_NO_THROW(sv.check_invariants());
  // The freed slot is reused for the next point.
  const CellVertex* b = sv.acquire(Point<2>{0.875, 0.0625});
  EXPECT_EQ(b->p, (Point<2>{0.875, 0.0625}));
  EXPECT_EQ(sv.size(), 1u);
  EXPECT_NO_THROW(sv.check_invariants());
}

TEST(SteinerVertices, RandomReferencesMatchAMapOfCounts) {
  const std::uint64_t seed = 20261129;
  std::printf("[ SteinerVertices ] seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  // Few distinct coordinates, so that points collide in the table and deletions shift.
  std::uniform_int_distribution<int> coord(0, 127);
  SteinerVertices sv;
  std::map<Point<2>, int> refs;
  std::map<Point<2>, const CellVertex*> object;
  std::vector<Point<2>> held;  // one entry per reference
  for (int batch = 0; batch < 200; ++batch) {
    for (int k = 0; k < 100; ++k) {
      if (held.empty() || rng() % 3 != 0) {
        const Point<2> p{coord(rng) / 128.0, coord(rng) / 128.0};
        const CellVertex* v = sv.acquire(p);
        ASSERT_EQ(v->p, p);
        if (refs[p]++ > 0 || object.count(p)) {
          ASSERT_EQ(v, object[p]) << "a point held, or idle, got another object";
        }
        object[p] = v;
        held.push_back(p);
      } else {
        const std::size_t i = rng() % held.size();
        const Point<2> p = held[i];
        held[i] = held.back();
        held.pop_back();
        sv.release(object.at(p));
        --refs[p];
      }
    }
    if (batch % 4 == 3) {
      sv.collect();
      for (auto it = refs.begin(); it != refs.end();) {
        if (it->second == 0) {
          object.erase(it->first);
          it = refs.erase(it);
        } else {
          ++it;
        }
      }
      ASSERT_EQ(sv.size(), refs.size());
    }
    ASSERT_NO_THROW(sv.check_invariants()) << "batch " << batch;
  }
}

TEST(SteinerVertices, CheckerCatchesAReleaseWithoutAnAcquire) {
  SteinerVertices sv;
  const CellVertex* a = sv.acquire(Point<2>{0.5, 0.5});
  sv.release(a);
  sv.release(a);  // one more than acquired
  EXPECT_THROW(sv.check_invariants(), InvariantError);
}

}  // namespace
}  // namespace dynmesh::detail
