// predicates.cpp — the exact stage of orient2d and incircle, and encroaches, on CGAL's
// filtered kernel (see predicates.hpp).
//
// Purpose: the only translation unit that sees CGAL. Both predicates forward to
// Exact_predicates_inexact_constructions_kernel, whose predicates are filtered: a static
// error bound on the double evaluation, then interval arithmetic, then exact rationals (GMP)
// when neither can certify the sign.
// Invariants: the returned int is the sign of the exact determinant of the double inputs
// (−1, 0 or +1); CGAL's Sign enum already uses exactly these values.
// Complexity: O(1); the exact fallback costs microseconds but runs only on (nearly)
// degenerate input.
// Paper: Shewchuk (1997) for the determinants and their sign conventions; Brönnimann,
// Burnikel, Pion, "Interval arithmetic yields efficient dynamic filters for computational
// geometry" (1998) for the filter CGAL implements.
#include "dynmesh/predicates.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>

namespace dynmesh {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using KPoint = Kernel::Point_2;

KPoint to_kernel(const Point<2>& p) noexcept { return KPoint(p[0], p[1]); }

}  // namespace

int detail::orient2d_exact(const Point<2>& a, const Point<2>& b, const Point<2>& c) noexcept {
  // CGAL::LEFT_TURN == POSITIVE == +1: c left of the directed line ab, i.e. a, b, c ccw.
  return static_cast<int>(Kernel::Orientation_2()(to_kernel(a), to_kernel(b), to_kernel(c)));
}

int detail::incircle_exact(const Point<2>& a, const Point<2>& b, const Point<2>& c, const Point<2>& d) noexcept {
  // ON_POSITIVE_SIDE == +1 of the circle oriented by a, b, c: the inside when a, b, c are ccw.
  // CGAL evaluates the full lifted determinant, so collinear a, b, c get its sign, as promised.
  return static_cast<int>(Kernel::Side_of_oriented_circle_2()(to_kernel(a), to_kernel(b),
                                                              to_kernel(c), to_kernel(d)));
}

int detail::pencil_exact(const Point<2>& p, const Point<2>& q, double h, const Point<2>& x) noexcept {
  using Q = CGAL::Exact_rational;
  const Q px(p[0]), py(p[1]), qx(q[0]), qy(q[1]), xx(x[0]), xy(x[1]), hh(h);
  const Q det = (xx - px) * (xx - qx) + (xy - py) * (xy - qy) - 2 * hh * ((qx - px) * (xy - py) - (qy - py) * (xx - px));
  return CGAL::sign(det);
}

bool encroaches(const Point<2>& a, const Point<2>& b, const Point<2>& x) noexcept {
  // The angle at x of a, x, b is obtuse exactly when x is strictly inside the diametral circle.
  return Kernel::Angle_2()(to_kernel(a), to_kernel(x), to_kernel(b)) == CGAL::OBTUSE;
}

}  // namespace dynmesh
