// mesh_test.cpp — mesh.hpp: canonical triangles, the canonical Mesh, apply_change.
#include "dynmesh/mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace {

using namespace dynmesh;

// The n x n grid of unit squares, each split by its rising diagonal, counter-clockwise.
std::vector<Triangle> grid(int n) {
  std::vector<Triangle> out;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Point<2> a{double(i), double(j)}, b{double(i + 1), double(j)}, c{double(i + 1), double(j + 1)},
          d{double(i), double(j + 1)};
      out.push_back(canonical_triangle(a, b, c));
      out.push_back(canonical_triangle(a, c, d));
    }
  return out;
}

TEST(MeshCanonical, TriangleStartsAtSmallestCornerAndKeepsOrientation) {
  const Point<2> a{0, 0}, b{1, 0}, c{0, 1};
  const Triangle expected{{a, b, c}};
  EXPECT_EQ(canonical_triangle(a, b, c), expected);
  EXPECT_EQ(canonical_triangle(b, c, a), expected);
  EXPECT_EQ(canonical_triangle(c, a, b), expected);
  // Ties on x are broken by y.
  const Point<2> p{0, 1}, q{0, 0}, r{1, 0};
  EXPECT_EQ(canonical_triangle(p, q, r), (Triangle{{q, r, p}}));
}

TEST(MeshCanonical, BoxSplitByDiagonal) {
  const Point<2> o{0, 0}, x{1, 0}, y{0, 1}, xy{1, 1};
  const std::vector<Triangle> ts = {canonical_triangle(xy, y, o), canonical_triangle(x, xy, o)};
  const Mesh m = make_mesh(ts);
  EXPECT_EQ(m.vertices, (std::vector<Point<2>>{o, y, x, xy}));
  using Tri = std::array<std::uint32_t, 3>;
  EXPECT_EQ(m.triangles, (std::vector<Tri>{{0, 2, 3}, {0, 3, 1}}));
  EXPECT_EQ(m.triangle(1), (Triangle{{o, xy, y}}));
}

TEST(MeshCanonical, IndependentOfOrderAndRotation) {
  const std::vector<Triangle> ts = grid(4);
  const Mesh reference = make_mesh(ts);
  std::mt19937 rng(12345);
  for (int round = 0; round < 20; ++round) {
    std::vector<Triangle> shuffled = ts;
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    for (Triangle& t : shuffled) std::rotate(t.v.begin(), t.v.begin() + rng() % 3, t.v.end());
    EXPECT_EQ(make_mesh(shuffled), reference) << "round " << round;
  }
}

TEST(MeshCanonical, TrianglesOfGivesSortedCanonicalTriangles) {
  std::vector<Triangle> ts = grid(3);
  const Mesh m = make_mesh(ts);
  EXPECT_EQ(m.num_vertices(), 16u);
  EXPECT_EQ(m.num_triangles(), 18u);
  EXPECT_TRUE(std::is_sorted(m.vertices.begin(), m.vertices.end(), xy_less));
  for (const auto& t : m.triangles) EXPECT_TRUE(t[0] < t[1] && t[0] < t[2]);
  std::sort(ts.begin(), ts.end());
  EXPECT_EQ(triangles_of(m), ts);
}

TEST(MeshCanonical, DuplicatesAreKept) {
  std::vector<Triangle> ts = grid(1);
  ts.push_back(ts[0]);
  const Mesh m = make_mesh(ts);
  EXPECT_EQ(m.num_vertices(), 4u);
  ASSERT_EQ(m.num_triangles(), 3u);
  EXPECT_EQ(m.triangles[0], m.triangles[1]);
}

TEST(MeshCanonical, Empty) {
  const Mesh m = make_mesh({});
  EXPECT_TRUE(m.vertices.empty());
  EXPECT_TRUE(m.triangles.empty());
  EXPECT_TRUE(triangles_of(m).empty());
}

// Flip the diagonal of grid square (i, j): the change from grid(n) to the flipped mesh.
MeshChange flip_square(int i, int j) {
  const Point<2> a{double(i), double(j)}, b{double(i + 1), double(j)}, c{double(i + 1), double(j + 1)},
      d{double(i), double(j + 1)};
  MeshChange change;
  change.removed = {canonical_triangle(a, b, c), canonical_triangle(a, c, d)};
  change.added = {canonical_triangle(a, b, d), canonical_triangle(b, c, d)};
  std::sort(change.removed.begin(), change.removed.end());
  std::sort(change.added.begin(), change.added.end());
  return change;
}

TEST(MeshApplyChange, FlipsAndInverse) {
  std::vector<Triangle> tris = grid(4);
  std::sort(tris.begin(), tris.end());
  const std::vector<Triangle> before = tris;

  const MeshChange change = flip_square(2, 1);
  ASSERT_TRUE(apply_change(tris, change));
  EXPECT_TRUE(std::is_sorted(tris.begin(), tris.end()));
  EXPECT_EQ(tris.size(), before.size());
  for (const Triangle& t : change.added) EXPECT_TRUE(std::binary_search(tris.begin(), tris.end(), t));
  for (const Triangle& t : change.removed) EXPECT_FALSE(std::binary_search(tris.begin(), tris.end(), t));

  const MeshChange inverse{change.added, change.removed};
  ASSERT_TRUE(apply_change(tris, inverse));
  EXPECT_EQ(tris, before);
}

TEST(MeshApplyChange, MatchesRebuildingTheSet) {
  std::vector<Triangle> tris = grid(4);
  std::sort(tris.begin(), tris.end());
  // Several squares at once, including the first and the last triangle of the order.
  MeshChange change;
  for (auto [i, j] : {std::pair{0, 0}, {3, 3}, {1, 2}, {2, 0}}) {
    const MeshChange one = flip_square(i, j);
    change.removed.insert(change.removed.end(), one.removed.begin(), one.removed.end());
    change.added.insert(change.added.end(), one.added.begin(), one.added.end());
  }
  std::sort(change.removed.begin(), change.removed.end());
  std::sort(change.added.begin(), change.added.end());

  std::vector<Triangle> expected;
  std::set_difference(tris.begin(), tris.end(), change.removed.begin(), change.removed.end(),
                      std::back_inserter(expected));
  expected.insert(expected.end(), change.added.begin(), change.added.end());
  std::sort(expected.begin(), expected.end());

  ASSERT_TRUE(apply_change(tris, change));
  EXPECT_EQ(tris, expected);
}

TEST(MeshApplyChange, UnsortedGroupsAreAccepted) {
  std::vector<Triangle> tris = grid(2);
  std::sort(tris.begin(), tris.end());
  std::vector<Triangle> expected = tris;
  ASSERT_TRUE(apply_change(expected, flip_square(1, 1)));

  MeshChange change = flip_square(1, 1);
  std::reverse(change.removed.begin(), change.removed.end());
  std::reverse(change.added.begin(), change.added.end());
  ASSERT_TRUE(apply_change(tris, change));
  EXPECT_EQ(tris, expected);
  ASSERT_TRUE(apply_change(tris, {}));  // the empty change is a no-op
  EXPECT_EQ(tris, expected);
}

TEST(MeshApplyChange, RejectsAbsentRemovalAndPresentAddition) {
  std::vector<Triangle> tris = grid(2);
  std::sort(tris.begin(), tris.end());

  std::vector<Triangle> copy = tris;
  const MeshChange absent{{canonical_triangle({5, 5}, {6, 5}, {5, 6})}, {}};
  EXPECT_FALSE(apply_change(copy, absent));

  copy = tris;
  const MeshChange present{{}, {tris[3]}};
  EXPECT_FALSE(apply_change(copy, present));

  copy = tris;
  const MeshChange twice{{tris[1], tris[1]}, {}};
  EXPECT_FALSE(apply_change(copy, twice));

  copy = tris;
  const Triangle fresh = canonical_triangle({5, 5}, {6, 5}, {5, 6});
  const MeshChange added_twice{{}, {fresh, fresh}};
  EXPECT_FALSE(apply_change(copy, added_twice));
}

TEST(MeshApplyChange, IntoEmptyAndToEmpty) {
  std::vector<Triangle> tris;
  std::vector<Triangle> all = grid(2);
  std::sort(all.begin(), all.end());
  ASSERT_TRUE(apply_change(tris, MeshChange{{}, all}));
  EXPECT_EQ(tris, all);
  ASSERT_TRUE(apply_change(tris, MeshChange{all, {}}));
  EXPECT_TRUE(tris.empty());
}

}  // namespace
