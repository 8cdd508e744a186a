// distributions_test.cpp — generators, the random source, closest pair and spread.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/io.hpp"

namespace {

using namespace dynmesh;

template <std::size_t d>
double brute_closest(const std::vector<Point<d>>& pts) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (std::size_t j = i + 1; j < pts.size(); ++j) {
      double s = 0;
      for (std::size_t a = 0; a < d; ++a) s += (pts[i][a] - pts[j][a]) * (pts[i][a] - pts[j][a]);
      best = std::min(best, std::sqrt(s));
    }
  return best;
}

TEST(Rng, MersenneTwisterIsTheStandardOne) {
  // The standard fixes the 10000th output of a default-seeded mt19937_64.
  Rng rng(5489u);
  std::uint64_t x = 0;
  for (int i = 0; i < 10000; ++i) x = rng.bits();
  EXPECT_EQ(x, 9981545732273789042ULL);
}

TEST(Rng, TransformsAreFixed) {
  // Pinned values: a change in a transform would silently change every generated point set
  // (and every recorded experiment). Uniform, below() and the uniform generator use exact
  // arithmetic only; normal() goes through libm (log, sin, cos), hence the 4-ulp tolerance.
  Rng rng(1);
  EXPECT_EQ(rng.uniform(), 0x1.122deafddb434p-3);
  EXPECT_EQ(rng.below(1000), 590u);
  EXPECT_DOUBLE_EQ(rng.normal(), 0x1.16007c53e018dp+0);
  const auto p = generate<2>(Distribution::Uniform, 2, 7);
  EXPECT_EQ(p[0], (Point<2>{0x1.823eca63d6cdbp-1, 0x1.e60acea8f4698p-1}));
  const auto b = generate<3>(Distribution::Boundary, 3, 7);
  EXPECT_EQ(b[1], (Point<3>{0x1.4e13c8cp-1, 0x1.c756ecb9p-2, 0x1.a9ce96p-1}));
  Rng a(99), c(99);
  for (int i = 0; i < 100; ++i) {
    EXPECT_EQ(a.below(7), c.below(7));
    EXPECT_EQ(a.normal(), c.normal());
  }
}

TEST(Rng, BelowIsInRangeAndRoughlyUniform) {
  Rng rng(3);
  std::vector<int> hist(10, 0);
  for (int i = 0; i < 100000; ++i) {
    const auto x = rng.below(10);
    ASSERT_LT(x, 10u);
    ++hist[x];
  }
  for (int h : hist) EXPECT_NEAR(h, 10000, 500);
  EXPECT_EQ(rng.below(1), 0u);
  const std::uint64_t big = (std::uint64_t{1} << 63) + 12345;
  for (int i = 0; i < 100; ++i) EXPECT_LT(rng.below(big), big);
}

TEST(Rng, NormalHasMeanZeroAndUnitVariance) {
  Rng rng(4);
  double s = 0, s2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double z = rng.normal();
    s += z;
    s2 += z * z;
  }
  EXPECT_NEAR(s / n, 0.0, 0.01);
  EXPECT_NEAR(s2 / n, 1.0, 0.02);
}

TEST(Distributions, PythonUniformMatchesCPython) {
  // CPython: r = random.Random(1); [r.random() for _ in range(4)]; random.Random(2).random().
  const auto pts = python_uniform(2);
  EXPECT_EQ(pts[0][0], 0.13436424411240122);
  EXPECT_EQ(pts[0][1], 0.8474337369372327);
  EXPECT_EQ(pts[1][0], 0.763774618976614);
  EXPECT_EQ(pts[1][1], 0.2550690257394217);
  EXPECT_EQ(python_uniform(1, 2)[0][0], 0.9560342718892494);
}

TEST(Distributions, NamesRoundTrip) {
  EXPECT_EQ(all_distributions().size(), 8u);
  for (const Distribution dist : all_distributions()) EXPECT_EQ(parse_distribution(distribution_name(dist)), dist);
  EXPECT_FALSE(parse_distribution("gaussian").has_value());
  EXPECT_EQ(parse_distribution("uniform"), Distribution::Uniform);
  EXPECT_EQ(parse_distribution("shrinking"), Distribution::Shrinking);
  EXPECT_EQ(parse_distribution("curves"), Distribution::Curves);
}

template <std::size_t d>
void deterministic_distinct_and_sized(Distribution dist) {
  for (const std::size_t n : {0u, 1u, 2u, 3u, 17u, 1000u}) {
    const auto a = generate<d>(dist, n, 123);
    const auto b = generate<d>(dist, n, 123);
    ASSERT_EQ(a.size(), n) << distribution_name(dist);
    EXPECT_EQ(a, b);
    if (n < 2) continue;
    // Distinct located positions in the derived box (locate_points rejects duplicates).
    PointFile<d> f{"gen", a, std::vector<std::size_t>(n, 1)};
    EXPECT_NO_THROW((void)locate_points(f, derive_box<d>(a))) << distribution_name(dist) << " n=" << n;
    for (const auto& p : a)
      for (double x : p) EXPECT_TRUE(std::isfinite(x));
  }
  EXPECT_NE(generate<d>(dist, 100, 1), generate<d>(dist, 100, 2)) << distribution_name(dist);
}

TEST(Distributions, DeterministicDistinctAndSized) {
  for (const Distribution dist : all_distributions()) {
    deterministic_distinct_and_sized<2>(dist);
    deterministic_distinct_and_sized<3>(dist);
  }
}

TEST(Distributions, GridIsIntegerLattice) {
  const auto pts = generate<3>(Distribution::Grid, 1000, 5);  // exactly 10^3
  std::set<Point<3>> s(pts.begin(), pts.end());
  EXPECT_EQ(s.size(), 1000u);
  for (const auto& p : pts)
    for (double x : p) {
      EXPECT_EQ(x, std::floor(x));
      EXPECT_GE(x, 0);
      EXPECT_LE(x, 9);
    }
}

TEST(Distributions, CollinearIsExactlyOnOneLine) {
  // On the line through (0.125, 0.25, 0.375) with direction (0.75, 0.625, 0.4375): the cross
  // products with the direction vanish exactly (every coordinate is an exact dyadic).
  const auto p2 = generate<2>(Distribution::Collinear, 5000, 5);
  for (const auto& p : p2) EXPECT_EQ((p[0] - 0.125) * 0.625 - (p[1] - 0.25) * 0.75, 0.0);
  const auto p3 = generate<3>(Distribution::Collinear, 5000, 5);
  for (const auto& p : p3) {
    EXPECT_EQ((p[0] - 0.125) * 0.625 - (p[1] - 0.25) * 0.75, 0.0);
    EXPECT_EQ((p[1] - 0.25) * 0.4375 - (p[2] - 0.375) * 0.625, 0.0);
  }
}

template <std::size_t d>
void boundary_points_lie_on_cell_boundaries() {
  const auto pts = generate<d>(Distribution::Boundary, 3000, 8);
  const Box<d> box = derive_box<d>(pts);
  const double w = kBoundaryExtent;
  for (std::size_t a = 0; a < d; ++a) EXPECT_EQ(box.origin[a], -w);
  EXPECT_EQ(box.side, 3 * w);
  std::size_t upper = 0, lower = 0;
  for (const auto& p : pts) {
    const Position<d> q = locate(box, p);
    for (std::size_t a = 0; a < d; ++a) {
      if (p[a] == 0.0 || p[a] == w) continue;  // the two pinned corners
      // p = −w + 3w·i/2^l exactly: the exact position is a multiple of 2^(52−l).
      const double t = (p[a] + w) / (3 * w);  // i / 2^l, exact
      int l = 0;
      double i = t;
      while (i != std::floor(i)) {
        i *= 2;
        ++l;
      }
      ASSERT_LE(l, 24);
      const std::uint64_t exact = static_cast<std::uint64_t>(i) << (kMaxLevel - l);
      if (q[a] == exact)
        ++upper;
      else if (q[a] == exact - 1)
        ++lower;
      else
        ADD_FAILURE() << "q = " << q[a] << ", boundary at " << exact;
    }
  }
  // Both sides of the rule's rounding occur.
  EXPECT_GT(upper, pts.size() * d / 5);
  EXPECT_GT(lower, pts.size() * d / 5);
}

TEST(Distributions, BoundaryPointsLieOnCellBoundaries) {
  boundary_points_lie_on_cell_boundaries<2>();
  boundary_points_lie_on_cell_boundaries<3>();
}

template <std::size_t d>
void shrinking_spread_is_independent_of_n() {
  for (const double spread : {0x1p12, 0x1p20, 0x1p30, 0x1p40}) {
    for (const std::size_t n : {500u, 5000u, 50000u}) {
      const auto pts = generate<d>(Distribution::Shrinking, n, 21, spread);
      const double lg = log2_spread<d>(derive_box<d>(pts), pts);
      EXPECT_NEAR(lg, std::log2(spread), 1.5) << "d=" << d << " n=" << n << " target 2^" << std::log2(spread);
    }
  }
}

TEST(Distributions, ShrinkingSpreadFollowsTheParameter) {
  shrinking_spread_is_independent_of_n<2>();
  shrinking_spread_is_independent_of_n<3>();
}

// --- curves ----------------------------------------------------------------------------------

template <std::size_t d>
double squared_distance(const Point<d>& a, const Point<d>& b) {
  double s = 0;
  for (std::size_t k = 0; k < d; ++k) s += (a[k] - b[k]) * (a[k] - b[k]);
  return s;
}

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <std::size_t d>
void curves_are_curves(std::size_t n, std::uint64_t seed) {
  SCOPED_TRACE("d=" + std::to_string(d) + " n=" + std::to_string(n) + " seed=" + std::to_string(seed));
  const auto pts = generate<d>(Distribution::Curves, n, seed);
  ASSERT_EQ(pts.size(), n);
  EXPECT_EQ(pts, generate<d>(Distribution::Curves, n, seed));  // deterministic for the seed
  EXPECT_NE(pts, generate<d>(Distribution::Curves, n, seed + 1));
  // Strictly inside the unit box, as the other distributions are.
  for (const auto& p : pts)
    for (const double x : p) {
      EXPECT_GT(x, 0.0);
      EXPECT_LT(x, 1.0);
    }
  // Distinct, also as located positions in the derived box.
  EXPECT_EQ(std::set<Point<d>>(pts.begin(), pts.end()).size(), n);
  PointFile<d> f{"curves", pts, std::vector<std::size_t>(n, 1)};
  EXPECT_NO_THROW((void)locate_points(f, derive_box<d>(pts)));

  // curve_points: the same points, curve by curve; max(2, round(√n/4)) curves, none empty.
  const auto curves = curve_points<d>(n, seed);
  const std::size_t k = std::max<std::size_t>(2, static_cast<std::size_t>(std::round(std::sqrt(double(n)) / 4)));
  ASSERT_EQ(curves.size(), k);
  std::vector<Point<d>> joined;
  for (const auto& c : curves) {
    EXPECT_GE(c.size(), 1u);
    joined.insert(joined.end(), c.begin(), c.end());
  }
  std::vector<Point<d>> sorted = pts;
  std::sort(sorted.begin(), sorted.end());
  std::sort(joined.begin(), joined.end());
  EXPECT_EQ(joined, sorted);

  // Curve-like: the median distance from a point to its nearest neighbour on its own curve is
  // at least 10 times smaller than the median distance to the nearest point of another curve.
  std::vector<double> along, across;
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const std::size_t first = along.size();
    for (std::size_t i = 0; i < curves[c].size(); ++i) {
      double same = std::numeric_limits<double>::infinity(), other = same;
      for (std::size_t e = 0; e < curves.size(); ++e)
        for (std::size_t j = 0; j < curves[e].size(); ++j) {
          if (e == c && j == i) continue;
          double& best = e == c ? same : other;
          best = std::min(best, squared_distance<d>(curves[c][i], curves[e][j]));
        }
      along.push_back(std::sqrt(same));
      across.push_back(std::sqrt(other));
    }
    // Even spacing along each curve (stratified arc lengths): neighbours are 0.5 to 1.5
    // spacings apart, so the curve's median is within a small factor of its smallest.
    const std::vector<double> own(along.begin() + static_cast<std::ptrdiff_t>(first), along.end());
    if (own.size() >= 3) {
      EXPECT_LT(median_of(own), 4 * *std::min_element(own.begin(), own.end())) << "curve " << c;
    }
  }
  const double along_median = median_of(along), across_median = median_of(across);
  std::printf("[ curves d=%zu n=%zu ] %zu curves, median spacing along a curve %.3g, to another curve %.3g (%.0fx)\n",
              d, n, curves.size(), along_median, across_median, across_median / along_median);
  EXPECT_GE(across_median, 10 * along_median);
}

TEST(Distributions, CurvesAreDeterministicInsideDistinctAndCurveLike) {
  for (const std::size_t n : {400u, 3000u}) {
    curves_are_curves<2>(n, 11);
    curves_are_curves<2>(n, 12);
    curves_are_curves<3>(n, 13);
  }
  // Few points: at least two curves, every point placed.
  for (const std::size_t n : {2u, 3u, 5u}) {
    EXPECT_EQ(curve_points<2>(n, 1).size(), 2u);
    EXPECT_EQ(generate<2>(Distribution::Curves, n, 1).size(), n);
  }
  EXPECT_EQ(curve_points<2>(1, 1).size(), 1u);
  EXPECT_TRUE(curve_points<3>(0, 1).empty());
  // Pinned bits: the generator uses + − × / and sqrt only (no libm), so these hold on every
  // platform; a change here changes every recorded curves experiment.
  EXPECT_EQ(generate<2>(Distribution::Curves, 100, 7)[0], (Point<2>{0x1.292bf62563208p-1, 0x1.545bb6cf4c321p-2}));
}

TEST(Distributions, BadSpreadIsRejected) {
  EXPECT_THROW((void)generate<2>(Distribution::Shrinking, 10, 1, 1.0), std::invalid_argument);
  EXPECT_THROW((void)generate<2>(Distribution::Uniform, 10, 1, std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
}

TEST(ClosestPair, AgreesWithBruteForce) {
  std::mt19937_64 gen(1);
  for (int t = 0; t < 50; ++t) {
    const auto dist = all_distributions()[static_cast<std::size_t>(t) % all_distributions().size()];
    const auto p2 = generate<2>(dist, 2 + static_cast<std::size_t>(gen() % 300), gen());
    EXPECT_EQ(closest_pair_distance<2>(p2), brute_closest<2>(p2)) << distribution_name(dist);
    const auto p3 = generate<3>(dist, 2 + static_cast<std::size_t>(gen() % 200), gen());
    EXPECT_EQ(closest_pair_distance<3>(p3), brute_closest<3>(p3)) << distribution_name(dist);
  }
  EXPECT_EQ(closest_pair_distance<2>(std::vector<Point<2>>{{1, 1}}), std::numeric_limits<double>::infinity());
  EXPECT_EQ(closest_pair_distance<2>(std::vector<Point<2>>{{1, 1}, {3, 1}, {1, 1}}), 0.0);
  EXPECT_EQ(log2_spread<2>(Box<2>{{0, 0}, 8}, std::vector<Point<2>>{{1, 1}, {2, 1}, {5, 5}}), 3.0);
}

}  // namespace
