// dynmesh/detail/mesh_grid.hpp — the meshes' grid vertices in double, and the resolution
// rule that keeps them distinct, in any dimension the tree supports.
//
// Purpose: every vertex of the quadtree mesh (2D) and the octree mesh (3D) that is not an
// input point is a vertex of the exact 2^52 grid of the tree's box. This header turns grid
// coordinates into doubles the same way everywhere, so that a vertex named twice gets the
// same bits, and states which point sets those doubles resolve.
// Coordinates: the grid vertex g (0..2^52 per axis) is o + g·(L·2^−52) in IEEE double, one
// multiplication and one addition; g = 0 gives o and g = 2^52 gives fl(o + L).
// Resolution: grid vertices are exact when the box is dyadic (L a power of two, o a multiple
// of L·2^−52 with |o| ≤ L; then R is kExactLimit). Otherwise they round, and the mesh needs its
// deepest cells to span many ulps: resolution_level() is the deepest level R at which the vertices two levels deeper
// are 2^12 ulps apart, and a point is rejected (Resolution) when another point lies in its
// level-R neighbourhood or when it lies within one level-R cell of a box side it is not on.
// Then every leaf of the refined trees has level ≤ R + 1.
// Invariants: coord(a, g) is monotone in g; resolution_level(b) ≤ kExactLimit ≤ 50.
// Complexity: O(d) per call; check_mesh_resolution O(3^d).
// Paper: none (the arithmetic of this project's meshes).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh::detail {

template <std::size_t d>
struct BasicMeshGrid {
  Box<d> box;
  double unit = 0;      // L·2^−52
  int level_limit = 0;  // R (see the header comment)

  explicit BasicMeshGrid(const Box<d>& b) : box(b), unit(b.side * 0x1p-52), level_limit(resolution_level(b)) {}

  double coord(unsigned axis, std::uint64_t g) const noexcept {
    return box.origin[axis] + static_cast<double>(g) * unit;
  }
  Point<d> vertex(const std::array<std::uint64_t, d>& g) const noexcept {
    Point<d> p;
    for (unsigned a = 0; a < d; ++a) p[a] = coord(a, g[a]);
    return p;
  }
  /// Does p lie on the box side where grid coordinate `g` of `axis` is 0 or 2^52?
  bool on_line(const Point<d>& p, unsigned axis, std::uint64_t g) const noexcept {
    return p[axis] == coord(axis, g);
  }

  static int resolution_level(const Box<d>& b) {
    const double unit = b.side * 0x1p-52;
    bool exact = std::exp2(std::ilogb(b.side)) == b.side;
    for (unsigned a = 0; a < d && exact; ++a)
      exact = std::fmod(b.origin[a], unit) == 0.0 && std::fabs(b.origin[a]) <= b.side;
    if (exact) return kExactLimit;
    double m = 0;
    for (unsigned a = 0; a < d; ++a)
      m = std::fmax(m, std::fmax(std::fabs(b.origin[a]), std::fabs(b.origin[a] + b.side)));
    // L·2^−(R+2) ≥ 2^12·ulp(m), ulp(m) = 2^(ilogb(m) − 52).
    const int r = std::ilogb(b.side) - std::ilogb(m) + 52 - 12 - 2;
    return r > kExactLimit ? kExactLimit : r;
  }

  /// R in a dyadic box. A point's located position may be off by a quarter grid unit (the
  /// rounded x − o), which the octree mesh's proved bound allows for (a margin of 2^−10 of a
  /// block's side, docs/OCTREE_MESH.md) while its blocks, of level ≤ R + 1, are at least 2^8
  /// grid units wide: R ≤ 42 in 3D keeps them 2^9 wide. The 2D mesh has no such margin.
  static constexpr int kExactLimit = d == 3 ? 42 : kMaxLevel - 2;
};

/// The rejection rules of the header comment for inserting p (located at q). `present(c)`
/// tells whether another point lies in the level-R cell c; `fail(text)` throws.
template <std::size_t d, class Present, class Fail>
void check_mesh_resolution(const BasicMeshGrid<d>& grid, const Position<d>& q, const Point<d>& p, Present&& present,
                           Fail&& fail) {
  const int r = grid.level_limit;
  if (r < 2) fail("the domain box is too small for its offset: double coordinates cannot resolve its cells");
  const CellId<d> c = cell_of(q, r);
  bool near = present(c);
  for_each_neighbour(c, [&](const CellId<d>& nb) { near = near || present(nb); });
  if (near)
    fail("another point lies in a neighbouring cell of level " + std::to_string(r) + " (L/2^" + std::to_string(r) +
         "): spread beyond the resolution of the mesh's double coordinates");
  const std::uint64_t n = cells_per_axis(r);
  for (unsigned a = 0; a < d; ++a) {
    if ((c.index[a] == 0 && !grid.on_line(p, a, 0)) || (c.index[a] + 1 == n && !grid.on_line(p, a, kResolution)))
      fail("the point lies within L/2^" + std::to_string(r) + " of a box side: beyond the resolution of the mesh");
  }
}

}  // namespace dynmesh::detail
