// Tests of geometry/powers_of_two.hpp against libm: exponent_of is std::ilogb, pow2 is
// std::ldexp(1.0, e), scale_down_by is std::ldexp within its frame, and to_unit_frame scales
// four numbers by their largest exponent as std::ldexp does, for every double (random bit
// patterns from a fixed, printed seed, and the edge cases).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "geometry/powers_of_two.hpp"

namespace dynmesh::detail {
namespace {

constexpr std::uint64_t kSeed = 20261128;

double random_bits(std::mt19937_64& rng) { return std::bit_cast<double>(rng()); }

/// A finite non-zero double of any exponent, subnormals included.
double random_finite(std::mt19937_64& rng) {
  for (;;) {
    const double x = random_bits(rng);
    if (std::isfinite(x) && x != 0) return x;
  }
}

TEST(PowersOfTwo, ExponentOfIsIlogbEverywhere) {
  std::mt19937_64 rng(kSeed);
  SCOPED_TRACE("seed " + std::to_string(kSeed));
  for (int i = 0; i < 1'000'000; ++i) {
    const double x = random_bits(rng);
    if (std::isnan(x)) continue;
    ASSERT_EQ(exponent_of(x), std::ilogb(x)) << x;
  }
  for (const double x : {0.0, -0.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::denorm_min(),
                         std::numeric_limits<double>::min(), std::numeric_limits<double>::max(), 1.0, 0x1.fffffffffffffp-1023,
                         -0x1p-1070})
    EXPECT_EQ(exponent_of(x), std::ilogb(x)) << x;
  EXPECT_EQ(exponent_of(std::numeric_limits<double>::quiet_NaN()), std::ilogb(std::numeric_limits<double>::quiet_NaN()));
}

TEST(PowersOfTwo, Pow2IsLdexpOfOneAndSaturatesAsIt) {
  for (int e = -1300; e <= 1300; ++e) ASSERT_EQ(pow2(e), std::ldexp(1.0, e)) << e;
}

TEST(PowersOfTwo, ScaleDownByIsLdexpWithinTheFrame) {
  std::mt19937_64 rng(kSeed + 1);
  SCOPED_TRACE("seed " + std::to_string(kSeed + 1));
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 1'000'000; ++i) {
    const double m = std::abs(random_finite(rng));
    const int e = exponent_of(m);
    // x of any size up to m: a fraction of m, or m's bits with fewer exponent.
    double x = i % 2 ? m * u(rng) : std::ldexp(m, -static_cast<int>(rng() % 1200));
    if (i % 3 == 0) x = -x;
    ASSERT_EQ(scale_down_by(x, e), std::ldexp(x, -e)) << x << " in the frame of " << m;
    ASSERT_EQ(scale_down_by(m, e), std::ldexp(m, -e)) << m;
  }
}

TEST(PowersOfTwo, ToUnitFrameIsLdexpByTheLargestExponent) {
  std::mt19937_64 rng(kSeed + 2);
  SCOPED_TRACE("seed " + std::to_string(kSeed + 2));
  for (int i = 0; i < 200'000; ++i) {
    std::array<double, 4> v{};
    for (double& x : v) x = random_finite(rng);
    if (i % 5 == 0) v[i % 4] = 0.0;
    std::array<double, 4> w = v;
    const int e = to_unit_frame(w[0], w[1], w[2], w[3]);
    const double m = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2]), std::abs(v[3])});
    ASSERT_EQ(e, std::ilogb(m));
    for (int k = 0; k < 4; ++k) ASSERT_EQ(w[k], std::ldexp(v[k], -e)) << v[k] << " in the frame of " << m;
    const double big = std::max({std::abs(w[0]), std::abs(w[1]), std::abs(w[2]), std::abs(w[3])});
    ASSERT_TRUE(big >= 1.0 && big < 2.0) << big;
  }
  // All zero, or the largest magnitude infinite (or a NaN where std::max keeps it): nothing
  // is scaled.
  for (const double bad : {0.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    double a = bad, b = 3.0e300, c = -2.0e-300, d = 0.0;
    if (bad == 0.0) b = c = 0.0;
    const double b0 = b, c0 = c;
    EXPECT_EQ(to_unit_frame(a, b, c, d), 0);
    EXPECT_EQ(b, b0);
    EXPECT_EQ(c, c0);
  }
}

}  // namespace
}  // namespace dynmesh::detail
