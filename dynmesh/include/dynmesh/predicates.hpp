// dynmesh/predicates.hpp — exact 2D orientation and in-circle predicates, and 3D orientation.
//
// Purpose: the geometric decisions the meshes make (is a triangle counter-clockwise, is a
// point strictly inside a circumcircle, does a point encroach a segment, is a tetrahedron
// positively oriented) decided exactly on IEEE double inputs, so that the static and the
// self-adjusting meshers, and the mesh checkers, never disagree through rounding. Each test
// first evaluates its determinant in double, inline, and returns the sign when it exceeds
// Shewchuk's a-priori error bound for that evaluation (his ccwerrboundA, iccerrboundA and
// o3derrboundA) plus a small absolute term for the products that underflow (an overflow
// leaves the comparison undecided); otherwise it asks CGAL's
// Exact_predicates_inexact_constructions_kernel (LGPL, Debian's libcgal-dev): an
// interval filter with an exact fallback. Before that, a call whose coordinates are so large
// (or small) that the filter's products overflow (or underflow) is rescaled by a power of
// two, exactly, and filtered again. No public header includes CGAL's: the library compiles them.
// The inline stage decides nearly all calls on meshing input and saves the call and CGAL's
// own filter setup (the predicates are a large part of a mesh's build).
//
// Invariants: the result is the sign of the exact real determinant of the double inputs,
// for every finite input (including exactly degenerate and nearly degenerate ones).
// Complexity: O(1); a few ns when the inline filter succeeds, more on (near-)degenerate input.
// Paper: Shewchuk, "Adaptive precision floating-point arithmetic and fast robust geometric
// predicates" (1997) for the determinants; CGAL's filtered kernel for the implementation.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "dynmesh/point.hpp"

namespace dynmesh {

namespace detail {
/// The exact signs (CGAL), for the cases the inline filters below cannot settle.
int orient2d_exact(const Point<2>& a, const Point<2>& b, const Point<2>& c) noexcept;
int incircle_exact(const Point<2>& a, const Point<2>& b, const Point<2>& c, const Point<2>& d) noexcept;
int pencil_exact(const Point<2>& p, const Point<2>& q, double h, const Point<2>& x) noexcept;
int orient3d_exact(const Point<3>& a, const Point<3>& b, const Point<3>& c, const Point<3>& d) noexcept;
/// How many calls on this thread reached exact arithmetic (CGAL's kernel or GMP rationals)
/// in orient2d, incircle, pencil and orient3d: for tests and experiments that check the
/// filters decide.
std::uint64_t exact_stage_calls() noexcept;
/// Shewchuk's bounds, ε = 2^−53: the error of the double evaluations below is at most
/// bound × permanent when no intermediate value overflows or underflows.
inline constexpr double kEpsilon = 0x1p-53;
inline constexpr double kOrientBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;
inline constexpr double kIncircleBound = (10.0 + 96.0 * kEpsilon) * kEpsilon;
inline constexpr double kOrient3dBound = (7.0 + 56.0 * kEpsilon) * kEpsilon;
/// For pencil(): a term carries at most 5ε of relative error (a rounded difference in each
/// factor, the product, the h product, a sum) and the final difference ε more; 12ε leaves room.
inline constexpr double kPencilBound = 12.0 * kEpsilon;
/// Added to the orient2d and pencil bounds: far above the error of the products that
/// underflow, far below any determinant the filters decide in a mesh.
inline constexpr double kUnderflowRoom = 0x1p-1000;
}  // namespace detail

/// Sign of det[[bx−ax, by−ay], [cx−ax, cy−ay]]: +1 when a, b, c turn counter-clockwise,
/// −1 clockwise, 0 collinear. Inputs must be finite.
inline int orient2d(const Point<2>& a, const Point<2>& b, const Point<2>& c) noexcept {
  const double acx = a[0] - c[0], bcy = b[1] - c[1], acy = a[1] - c[1], bcx = b[0] - c[0];
  const double left = acx * bcy;
  const double right = acy * bcx;
  const double det = left - right;
  const double permanent = std::fabs(left) + std::fabs(right);
  // No range test (a hot path: the tests would cost more than the filter): the absolute term
  // covers products that underflow (each off by at most 2^-1075), and a difference or a
  // product that overflows makes the permanent infinite or the determinant NaN, so that
  // neither comparison holds.
  const double bound = detail::kOrientBound * permanent + detail::kUnderflowRoom;
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return detail::orient2d_exact(a, b, c);
}

/// For a, b, c counter-clockwise: +1 when d lies strictly inside their circumcircle, −1
/// strictly outside, 0 on it (the sign flips for clockwise a, b, c; a, b, c collinear gives
/// the orientation-style sign of the degenerate determinant, as the classic incircle test).
/// Inputs must be finite.
inline int incircle(const Point<2>& a, const Point<2>& b, const Point<2>& c, const Point<2>& d) noexcept {
  const double adx = a[0] - d[0], ady = a[1] - d[1];
  const double bdx = b[0] - d[0], bdy = b[1] - d[1];
  const double cdx = c[0] - d[0], cdy = c[1] - d[1];
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double alift = adx * adx + ady * ady;
  const double blift = bdx * bdx + bdy * bdy;
  const double clift = cdx * cdx + cdy * cdy;
  const double det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
  const double permanent = (std::fabs(bdxcdy) + std::fabs(cdxbdy)) * alift +
                           (std::fabs(cdxady) + std::fabs(adxcdy)) * blift +
                           (std::fabs(adxbdy) + std::fabs(bdxady)) * clift;
  // No range test, as orient2d: an underflow's error (at most 2^-1075 a product) is
  // multiplied by at most a lift or a degree-2 difference, each below 2M² for M the largest
  // difference, so they add up to less than 30·2^-1075·(M² + 1); (M² + 1)·2^-1000 is far
  // above that. An overflow makes the permanent or the room infinite, or the determinant
  // NaN, and then neither comparison holds. The room's factor is a normal number: with a
  // subnormal one every call would multiply into the subnormal range, which x86 does in
  // microcode, slowly.
  const double m = std::max({std::fabs(adx), std::fabs(ady), std::fabs(bdx), std::fabs(bdy), std::fabs(cdx), std::fabs(cdy)});
  const double bound = detail::kIncircleBound * permanent + (m * m + 1) * detail::kUnderflowRoom;
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return detail::incircle_exact(a, b, c, d);
}

/// The circles through p and q form a pencil; its member with centre m + h·J(q − p) (m the
/// midpoint, J the +90° turn) is the ccw-leaf of pq for h = k and the circle of the apex
/// for h = ρ + k (docs/DESIGN.md, "DynHPU"). Returns the sign of (x−p)·(x−q) − 2h·orient(p, q, x),
/// which is −1 exactly when x lies strictly inside that circle, 0 on it, +1 outside. Exact
/// for finite p, q, x and h.
inline int pencil(const Point<2>& p, const Point<2>& q, double h, const Point<2>& x) noexcept {
  const double apx = x[0] - p[0], apy = x[1] - p[1], aqx = x[0] - q[0], aqy = x[1] - q[1];
  const double bx = q[0] - p[0], by = q[1] - p[1];
  const double d1 = apx * aqx, d2 = apy * aqy;
  const double c1 = bx * apy, c2 = by * apx;
  const double h2 = 2.0 * h;
  const double det = (d1 + d2) - h2 * (c1 - c2);
  const double permanent = std::fabs(d1) + std::fabs(d2) + std::fabs(h2) * (std::fabs(c1) + std::fabs(c2));
  // As orient2d: the absolute term covers underflow (with |h| ≤ 2^60, at most 2^-1012 in
  // all), and an overflow leaves both comparisons false.
  if (std::fabs(h) <= 0x1p60) {
    const double bound = detail::kPencilBound * permanent + detail::kUnderflowRoom;
    if (det > bound) return 1;
    if (-det > bound) return -1;
  }
  return detail::pencil_exact(p, q, h, x);
}

/// Sign of det[b − a, c − a, d − a]: +1 when a, b, c, d are positively oriented (d on the
/// side of the plane abc from which a, b, c turn counter-clockwise; the unit tetrahedron
/// (0,0,0), (1,0,0), (0,1,0), (0,0,1) is positive), −1 negatively, 0 coplanar. This is
/// the orientation of a tetrahedron in docs/FORMATS.md, "`dynmesh mesh` in 3D", and the
/// opposite of Shewchuk's orient3d sign.
/// Inputs must be finite.
inline int orient3d(const Point<3>& a, const Point<3>& b, const Point<3>& c, const Point<3>& d) noexcept {
  // Shewchuk's evaluation, relative to d: his determinant is det[a − d, b − d, c − d], which
  // is −det[b − a, c − a, d − a], so the signs below are his, negated.
  const double adx = a[0] - d[0], ady = a[1] - d[1], adz = a[2] - d[2];
  const double bdx = b[0] - d[0], bdy = b[1] - d[1], bdz = b[2] - d[2];
  const double cdx = c[0] - d[0], cdy = c[1] - d[1], cdz = c[2] - d[2];
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double permanent = (std::fabs(bdxcdy) + std::fabs(cdxbdy)) * std::fabs(adz) +
                           (std::fabs(cdxady) + std::fabs(adxcdy)) * std::fabs(bdz) +
                           (std::fabs(adxbdy) + std::fabs(bdxady)) * std::fabs(cdz);
  // As incircle: an underflowed product (off by at most 2^-1075) is multiplied by at most one
  // difference, below M, so (M + 1)·2^-1000 covers all of them, and stays a normal number;
  // an overflow leaves both comparisons false.
  const double m = std::max({std::fabs(adz), std::fabs(bdz), std::fabs(cdz), std::fabs(adx), std::fabs(ady),
                             std::fabs(bdx), std::fabs(bdy), std::fabs(cdx), std::fabs(cdy)});
  const double bound = detail::kOrient3dBound * permanent + (m + 1) * detail::kUnderflowRoom;
  if (det > bound) return -1;
  if (-det > bound) return 1;
  return detail::orient3d_exact(a, b, c, d);
}

/// True when x lies strictly inside the circle with diameter ab, i.e. (a−x)·(b−x) < 0: x
/// encroaches the segment ab (Ruppert; Triangle's test for subsegments). Inputs finite.
bool encroaches(const Point<2>& a, const Point<2>& b, const Point<2>& x) noexcept;

}  // namespace dynmesh
