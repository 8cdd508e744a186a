// dynmesh/predicates.hpp — exact 2D orientation and in-circle predicates.
//
// Purpose: the geometric decisions the meshes make (is a triangle counter-clockwise, is a
// point strictly inside a circumcircle, does a point encroach a segment) decided exactly on IEEE double inputs, so that the
// static and the self-adjusting meshers, and the mesh checker, never disagree through
// rounding. The work is done by CGAL's Exact_predicates_inexact_constructions_kernel
// (LGPL, Debian's libcgal-dev): a floating-point filter with an exact fallback. CGAL's
// headers are confined to src/predicates.cpp.
//
// Invariants: the result is the sign of the exact real determinant of the double inputs,
// for every finite input (including exactly degenerate and nearly degenerate ones).
// Complexity: O(1); a few ns when the filter succeeds, more on (near-)degenerate input.
// Paper: Shewchuk, "Adaptive precision floating-point arithmetic and fast robust geometric
// predicates" (1997) for the determinants; CGAL's filtered kernel for the implementation.
#pragma once

#include "dynmesh/point.hpp"

namespace dynmesh {

/// Sign of det[[bx−ax, by−ay], [cx−ax, cy−ay]]: +1 when a, b, c turn counter-clockwise,
/// −1 clockwise, 0 collinear. Inputs must be finite.
int orient2d(const Point<2>& a, const Point<2>& b, const Point<2>& c) noexcept;

/// For a, b, c counter-clockwise: +1 when d lies strictly inside their circumcircle, −1
/// strictly outside, 0 on it (the sign flips for clockwise a, b, c; a, b, c collinear gives
/// the orientation-style sign of the degenerate determinant, as the classic incircle test).
/// Inputs must be finite.
int incircle(const Point<2>& a, const Point<2>& b, const Point<2>& c, const Point<2>& d) noexcept;

/// True when x lies strictly inside the circle with diameter ab, i.e. (a−x)·(b−x) < 0: x
/// encroaches the segment ab (Ruppert; Triangle's test for subsegments). Inputs finite.
bool encroaches(const Point<2>& a, const Point<2>& b, const Point<2>& x) noexcept;

}  // namespace dynmesh
