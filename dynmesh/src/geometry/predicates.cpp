// predicates.cpp — the exact stage of orient2d, incircle and orient3d, and encroaches, on
// CGAL's filtered kernel (see predicates.hpp).
//
// Purpose: the only translation unit that sees CGAL. The predicates forward to
// Exact_predicates_inexact_constructions_kernel, whose predicates are filtered: a static
// error bound on the double evaluation, then interval arithmetic, then exact rationals (GMP)
// when neither can certify the sign.
// Invariants: the returned int is the sign of the exact determinant of the double inputs
// (−1, 0 or +1); CGAL's Sign enum already uses exactly these values.
// Complexity: O(1); the exact fallback costs microseconds but runs only on (nearly)
// degenerate input, once the rescaling below has settled the calls whose filters overflowed.
// Paper: Shewchuk (1997) for the determinants and their sign conventions; Brönnimann,
// Burnikel, Pion, "Interval arithmetic yields efficient dynamic filters for computational
// geometry" (1998) for the filter CGAL implements.
#include "dynmesh/predicates.hpp"

#include "geometry/powers_of_two.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace dynmesh {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using KPoint = Kernel::Point_2;
using KPoint3 = Kernel::Point_3;

KPoint to_kernel(const Point<2>& p) noexcept { return KPoint(p[0], p[1]); }
KPoint3 to_kernel(const Point<3>& p) noexcept { return KPoint3(p[0], p[1], p[2]); }

thread_local std::uint64_t exact_evaluations = 0;

/// Coordinates beyond these magnitudes are rescaled before the exact stage. Above 2^200 the
/// in-circle filter's degree-4 products can overflow (at 2^254), and the others' too further
/// up; below 2^-200 the products underflow past the filters' absolute room. Either way a
/// common power-of-two scale brings the calls back into the range the filters decide.
constexpr double kRescaleAbove = 0x1p200;
constexpr double kRescaleBelow = 0x1p-200;

/// Rescales the points in place by the power of two that brings their largest coordinate
/// magnitude into [1/2, 1) (subnormal ones as near as a factor 2^1000 takes them), when that
/// magnitude is outside [2^-200, 2^200] and every coordinate scales exactly; returns whether
/// it did. A common positive scale leaves each sign unchanged: orient2d, encroachment and the
/// pencil's determinant are homogeneous of degree 2 in the coordinates, incircle of degree 4,
/// orient3d of degree 3, and the pencil's h is a ratio. So a call whose inline filter
/// overflowed (a fuzzed input near 10^291 sent every call to GMP) is decided by the filters
/// again.
template <std::size_t d, std::size_t N>
bool rescale(std::array<Point<d>, N>& pts) noexcept {
  double m = 0;
  for (const auto& p : pts)
    for (std::size_t c = 0; c < d; ++c) m = std::max(m, std::fabs(p[c]));
  if (!(m > kRescaleAbove || (m < kRescaleBelow && m > 0))) return false;
  // 2^−(⌊log2 m⌋ + 1), though never above 2^1000: for m down to 2^−1074 the result's
  // largest coordinate is then at least 2^−74, so no call rescales twice.
  const double s = detail::pow2(std::min(-detail::exponent_of(m) - 1, 1000));
  std::array<Point<d>, N> scaled;
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t c = 0; c < d; ++c) {
      // A product by a power of two is exact unless it rounds into the subnormal range,
      // which only a scale below 1 can do, and which the way back then detects.
      const double x = pts[i][c], y = x * s;
      if (s < 1 && std::fabs(y) < std::numeric_limits<double>::min() && y / s != x) return false;
      scaled[i][c] = y;
    }
  pts = scaled;
  return true;
}

}  // namespace

std::uint64_t detail::exact_stage_calls() noexcept { return exact_evaluations; }

int detail::orient2d_exact(const Point<2>& a, const Point<2>& b, const Point<2>& c) noexcept {
  // The rescaled points' largest coordinate is in [2^-74, 1), so the call below cannot come
  // back here through another rescale: it decides in its filter or reaches CGAL.
  if (std::array pts{a, b, c}; rescale(pts)) return orient2d(pts[0], pts[1], pts[2]);
  // A difference of doubles is zero exactly when they are equal, and is otherwise rounded
  // to a value of the same sign. So when one factor of a product is an exact zero, the sign
  // is the other product's, from the factors' signs. The filter fails on such calls when
  // both products are zero (a repeated point, points on one axis-parallel line), where its
  // bound is its absolute room alone.
  const double acx = a[0] - c[0], bcy = b[1] - c[1], acy = a[1] - c[1], bcx = b[0] - c[0];
  const auto sgn = [](double v) { return (v > 0) - (v < 0); };
  if (acx == 0 || bcy == 0) return -sgn(acy) * sgn(bcx);
  if (acy == 0 || bcx == 0) return sgn(acx) * sgn(bcy);
  ++exact_evaluations;
  // CGAL::LEFT_TURN == POSITIVE == +1: c left of the directed line ab, i.e. a, b, c ccw.
  return static_cast<int>(Kernel::Orientation_2()(to_kernel(a), to_kernel(b), to_kernel(c)));
}

int detail::incircle_exact(const Point<2>& a, const Point<2>& b, const Point<2>& c, const Point<2>& d) noexcept {
  if (std::array pts{a, b, c, d}; rescale(pts)) return incircle(pts[0], pts[1], pts[2], pts[3]);
  ++exact_evaluations;
  // ON_POSITIVE_SIDE == +1 of the circle oriented by a, b, c: the inside when a, b, c are ccw.
  // CGAL evaluates the full lifted determinant, so collinear a, b, c get its sign, as promised.
  return static_cast<int>(Kernel::Side_of_oriented_circle_2()(to_kernel(a), to_kernel(b),
                                                              to_kernel(c), to_kernel(d)));
}

int detail::pencil_exact(const Point<2>& p, const Point<2>& q, double h, const Point<2>& x) noexcept {
  if (std::array pts{p, q, x}; rescale(pts)) return pencil(pts[0], pts[1], h, pts[2]);
  ++exact_evaluations;
  using Q = CGAL::Exact_rational;
  const Q px(p[0]), py(p[1]), qx(q[0]), qy(q[1]), xx(x[0]), xy(x[1]), hh(h);
  const Q det = (xx - px) * (xx - qx) + (xy - py) * (xy - qy) - 2 * hh * ((qx - px) * (xy - py) - (qy - py) * (xx - px));
  return CGAL::sign(det);
}

int detail::orient3d_exact(const Point<3>& a, const Point<3>& b, const Point<3>& c, const Point<3>& d) noexcept {
  if (std::array pts{a, b, c, d}; rescale(pts)) return orient3d(pts[0], pts[1], pts[2], pts[3]);
  ++exact_evaluations;
  // CGAL's POSITIVE == +1 is the sign of det[b − a, c − a, d − a]: the unit tetrahedron is
  // positive in both (tests/dynmesh/predicates_test.cpp, Predicates.Orient3dConvention).
  return static_cast<int>(Kernel::Orientation_3()(to_kernel(a), to_kernel(b), to_kernel(c), to_kernel(d)));
}

bool encroaches(const Point<2>& a, const Point<2>& b, const Point<2>& x) noexcept {
  // CGAL's filter overflows as the inline ones do; its exact stage is not counted, since it
  // cannot be told apart from the filter's success from here.
  if (std::array pts{a, b, x}; rescale(pts)) return encroaches(pts[0], pts[1], pts[2]);
  // The angle at x of a, x, b is obtuse exactly when x is strictly inside the diametral circle.
  return Kernel::Angle_2()(to_kernel(a), to_kernel(x), to_kernel(b)) == CGAL::OBTUSE;
}

}  // namespace dynmesh
