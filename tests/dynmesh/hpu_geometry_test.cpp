// Tests of hpu/hpu_geometry.hpp's formulas that compute in frames scaled by a power of two
// (geometry/powers_of_two.hpp, tested in powers_of_two_test.cpp) against the same formulas
// written plainly with std::ldexp and std::ilogb: the twin and the program must keep every
// bit.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "hpu/hpu_geometry.hpp"

namespace dynmesh::detail {
namespace {

constexpr std::uint64_t kSeed = 20261128;

// The formulas written plainly, as the oracle.
int edge_class_ldexp(const Point<2>& a, const Point<2>& b) {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const int e = std::ilogb(std::max(std::abs(dx), std::abs(dy)));
  const double sx = std::ldexp(dx, -e), sy = std::ldexp(dy, -e);
  return e + (std::ilogb(sx * sx + sy * sy) >> 1);
}

Point<2> off_center_ldexp(const Point<2>& p, const Point<2>& q, const Point<2>& t, double apex) {
  double bx = q[0] - p[0], by = q[1] - p[1], cx = t[0] - p[0], cy = t[1] - p[1];
  const int e = std::ilogb(std::max({std::abs(bx), std::abs(by), std::abs(cx), std::abs(cy)}));
  bx = std::ldexp(bx, -e), by = std::ldexp(by, -e), cx = std::ldexp(cx, -e), cy = std::ldexp(cy, -e);
  const double mx = 0.5 * bx, my = 0.5 * by;
  const double ax = mx - apex * by, ay = my + apex * bx;
  const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  const double d = 2.0 * (bx * cy - by * cx);
  const double ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
  const bool circumcentre = (ux - mx) * (ux - mx) + (uy - my) * (uy - my) <= apex * apex * b2;
  const double rx = circumcentre ? ux : ax, ry = circumcentre ? uy : ay;
  return Point<2>{p[0] + std::ldexp(rx, e), p[1] + std::ldexp(ry, e)};
}

bool circumradius_above_ldexp(const Point<2>& a, const Point<2>& b, const Point<2>& c, int j) {
  const Point<2>*P = &a, *Q = &b, *R = &c;
  if (xy_less(*Q, *P) && xy_less(*Q, *R)) std::tie(P, Q, R) = std::tuple{Q, R, P};
  else if (xy_less(*R, *P) && xy_less(*R, *Q)) std::tie(P, Q, R) = std::tuple{R, P, Q};
  double bx = (*Q)[0] - (*P)[0], by = (*Q)[1] - (*P)[1], cx = (*R)[0] - (*P)[0], cy = (*R)[1] - (*P)[1];
  const double m = std::max({std::abs(bx), std::abs(by), std::abs(cx), std::abs(cy)});
  if (!(m > 0)) return true;
  const int e = std::ilogb(m);
  bx = std::ldexp(bx, -e), by = std::ldexp(by, -e), cx = std::ldexp(cx, -e), cy = std::ldexp(cy, -e);
  const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  const double d = 2.0 * (bx * cy - by * cx);
  const double ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
  const long k = std::clamp(2L * (static_cast<long>(j) + 1 - e), -4000L, 4000L);
  return ux * ux + uy * uy > std::ldexp(1.0, static_cast<int>(k));
}

TEST(HpuGeometry, ClassesAndOffCentersKeepTheirBitsAtEveryScale) {
  std::mt19937_64 rng(kSeed + 2);
  SCOPED_TRACE("seed " + std::to_string(kSeed + 2));
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double apex = apex_height(20.7);
  std::size_t compared = 0;
  for (int i = 0; i < 300'000; ++i) {
    // A triangle of scale 2^s around a centre of scale 2^c: huge, tiny (subnormal
    // differences) and ordinary boxes.
    const int s = static_cast<int>(rng() % 2080) - 1070, c = std::min(s + static_cast<int>(rng() % 60), 1000);
    const Point<2> o{std::ldexp(u(rng), c), std::ldexp(u(rng), c)};
    const auto near = [&] { return Point<2>{o[0] + std::ldexp(u(rng), s), o[1] + std::ldexp(u(rng), s)}; };
    const Point<2> p = near(), q = near(), t = near();
    if (p == q || !std::isfinite(p[0]) || !std::isfinite(q[0]) || !std::isfinite(t[0])) continue;
    ASSERT_EQ(edge_class(p, q), edge_class_ldexp(p, q)) << i;
    if (orient2d(p, q, t) <= 0) continue;
    const Point<2> r = off_center(p, q, t, apex).at, r0 = off_center_ldexp(p, q, t, apex);
    // Both NaN (a flat triangle's circumcentre) or the same bits.
    for (int a = 0; a < 2; ++a)
      ASSERT_TRUE(std::bit_cast<std::uint64_t>(r[a]) == std::bit_cast<std::uint64_t>(r0[a]) ||
                  (std::isnan(r[a]) && std::isnan(r0[a])))
          << i;
    const int j = static_cast<int>(rng() % 2100) - 1080;
    ASSERT_EQ(circumradius_above(p, q, t, j), circumradius_above_ldexp(p, q, t, j)) << i;
    ++compared;
  }
  EXPECT_GT(compared, 100'000u);
}

}  // namespace
}  // namespace dynmesh::detail
