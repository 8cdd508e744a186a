// powers_of_two.hpp (private) — exact powers of two and the exponent of a double, without
// libm calls: the frames scaled by a power of two that the hpu formulas (hpu_geometry.hpp)
// and the predicates' rescale (predicates.cpp) compute in, so that products neither overflow
// nor underflow.
//
// Purpose: std::ilogb and std::ldexp are calls into libm, and the twin and the program ask
// for an exponent for every edge they classify; these are a few bit operations, inline.
// Invariants: exponent_of(x) == std::ilogb(x) for every double; pow2(e) == std::ldexp(1.0, e)
// for every int; scale_down_by(x, exponent_of(m)) == std::ldexp(x, -exponent_of(m)) for
// |x| <= m, m finite and non-zero; to_unit_frame scales as std::ldexp does
// (tests/dynmesh/powers_of_two_test.cpp).
// Complexity: O(1).
// Paper: IEEE 754 binary64's layout.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace dynmesh::detail {

/// std::ilogb(x) without the libm call, for finite non-zero x (subnormals included); std::ilogb
/// itself otherwise. The twin and the program call it for every edge they classify.
inline int exponent_of(double x) noexcept {
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  const int field = static_cast<int>((bits >> 52) & 0x7ff);
  const std::uint64_t mantissa = bits & ((std::uint64_t{1} << 52) - 1);
  if (field == 0x7ff || (field == 0 && mantissa == 0)) return std::ilogb(x);  // inf, NaN, ±0
  if (field == 0) return -1011 - std::countl_zero(mantissa);                  // subnormal
  return field - 1023;
}

/// 2^e, exactly, for e in [-1074, 1023] (subnormal below -1022); 0 below and +inf above, as
/// std::ldexp(1.0, e) saturates.
inline double pow2(int e) noexcept {
  if (e > 1023) return std::numeric_limits<double>::infinity();
  if (e < -1074) return 0.0;
  if (e >= -1022) return std::bit_cast<double>(static_cast<std::uint64_t>(e + 1023) << 52);
  return std::bit_cast<double>(std::uint64_t{1} << (e + 1074));
}

/// std::ldexp(x, -exponent_of(m)) for |x| ≤ m, m finite and non-zero: x in the frame where m
/// lies in [1, 2). Scaling up is exact, and scaling down rounds once, as ldexp does; only a
/// subnormal m needs two factors (both scale up, so both are exact).
inline double scale_down_by(double x, int e) noexcept {
  if (e >= -1023) return x * pow2(-e);
  return (x * pow2(1023)) * pow2(-e - 1023);
}

/// A vector pair (ux, uy), (vx, vy) in the frame where its largest coordinate lies in [1, 2):
/// scaled by 2^-e in place, e returned; 0, and nothing scaled, when the largest magnitude
/// (by std::max, as the callers had it) is not a positive finite number (all zero, an
/// infinity). A corner's angle is the same in that frame, and its products neither
/// overflow nor underflow (the quality report's and the mesh checker's frame).
inline int to_unit_frame(double& ux, double& uy, double& vx, double& vy) noexcept {
  const double m = std::max({std::abs(ux), std::abs(uy), std::abs(vx), std::abs(vy)});
  if (!(m > 0) || !std::isfinite(m)) return 0;
  const int e = exponent_of(m);
  ux = scale_down_by(ux, e), uy = scale_down_by(uy, e), vx = scale_down_by(vx, e), vy = scale_down_by(vy, e);
  return e;
}

}  // namespace dynmesh::detail
