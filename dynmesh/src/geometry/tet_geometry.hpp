// tet_geometry.hpp (private) — a tetrahedron's six edge vectors in a frame scaled by a power
// of two, and the vector algebra the 3D checker and the 3D statistics compute in it.
//
// Purpose: dihedral angles, circumradii and volumes are products of up to four coordinate
// differences; in a box of side near 1e300 they overflow and near 1e-300 they underflow. A
// common power-of-two scale is exact and changes no angle or ratio, so the measures are
// computed where the largest difference lies in [1, 2) (the 3D twin of to_unit_frame in
// powers_of_two.hpp). One place, so that the checker's bounds (tet_mesh_check.hpp) and the
// quality statistics (tet_mesh_io.hpp) agree on every figure.
// Invariants: edges[k] is fl(v[j] − v[i]) for the k-th pair (i, j) of kTetEdgePairs, times
// 2^-exponent (exact unless a component is below 2^-1022 of the largest); all zero and
// exponent 0 when the corners coincide or a difference is not finite.
// Complexity: O(1).
// Paper: none (vector algebra; the identity (e × u) × (e × w) = det(e, u, w)·e for angles).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "dynmesh/point.hpp"
#include "geometry/powers_of_two.hpp"

namespace dynmesh::detail {

using Vec3 = std::array<double, 3>;

inline double dot(const Vec3& a, const Vec3& b) noexcept { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

inline Vec3 cross(const Vec3& a, const Vec3& b) noexcept {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

inline double det3(const Vec3& a, const Vec3& b, const Vec3& c) noexcept { return dot(a, cross(b, c)); }

/// The six edges (i, j), i < j, in the order the dihedral angles are reported.
inline constexpr std::array<std::array<std::size_t, 2>, 6> kTetEdgePairs{
    {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};

struct TetEdges {
  std::array<Vec3, 6> edges{};  // v[j] − v[i] for kTetEdgePairs[k], scaled by 2^-exponent
  int exponent = 0;

  /// v[to] − v[from] in the frame, for any two distinct corners.
  Vec3 from_to(std::size_t from, std::size_t to) const noexcept {
    const std::size_t lo = std::min(from, to), hi = std::max(from, to);
    const std::size_t k = lo == 0 ? hi - 1 : lo + hi;  // (0,1..3) -> 0..2, (1,2) -> 3, (1,3) -> 4, (2,3) -> 5
    const Vec3& e = edges[k];
    return from < to ? e : Vec3{-e[0], -e[1], -e[2]};
  }
};

inline TetEdges tet_edges(const std::array<Point<3>, 4>& v) noexcept {
  TetEdges t;
  double m = 0;
  for (std::size_t k = 0; k < 6; ++k) {
    const auto [i, j] = kTetEdgePairs[k];
    for (std::size_t a = 0; a < 3; ++a) {
      t.edges[k][a] = v[j][a] - v[i][a];
      m = std::max(m, std::abs(t.edges[k][a]));
    }
  }
  if (!(m > 0) || !std::isfinite(m)) return TetEdges{};
  t.exponent = exponent_of(m);
  for (Vec3& e : t.edges)
    for (double& x : e) x = scale_down_by(x, t.exponent);
  return t;
}

}  // namespace dynmesh::detail
