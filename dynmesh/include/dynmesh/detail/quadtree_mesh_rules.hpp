// dynmesh/detail/quadtree_mesh_rules.hpp — the rules of the quadtree mesh, shared by the
// static twin (QuadtreeMesh) and the self-adjusting program (DynamicMesh), so that the two
// compute the same triangles bit for bit.
//
// Purpose. The quadtree postprocess (docs/DESIGN.md, "The quadtree mesh"), with this project's closure rule:
//   * Target of a point p. Let l be the level of p's leaf in T*. p's leaf in T' is c_t, the
//     cell of level t holding p, where t is the least level > l at which the corner of c_t
//     nearest to p (ties: lowest corner number) may move onto p: it lies on no side of the
//     box that p is not on. (A box corner moves only onto a point equal to it.)
//   * Closure T' of T*: split every level-(t−1) cell touching c_t (these are the parents of
//     c_t's 3x3 block), for every point, then split whatever grading then forces (a level
//     m−1 cell touching a split level-m cell). This is the "always one level
//     deeper" variant of (C3)/(EQ): c_t's block of 3x3 same-size leaves exists by
//     construction, and nothing splits inside it: T* has no split cell there (the block lies
//     in p's T* neighbourhood, which holds no other point, and T* is graded around p's
//     leaf), and the closure only adds cells at levels < t or around other points, whose
//     blocks are disjoint from p's. The checkers (QuadtreeMesh::check_invariants,
//     DynamicMesh::check_invariants) verify it on every mesh the tests build.
//   * Warp: the corner v of c_t nearest to p moves onto p. The four leaves around v are
//     c_t's block's cells, so each leaf has at most one warped corner.
//   * Triangulation of a leaf from its corners (one maybe warped) and the midpoints of its
//     sides that are corners of smaller neighbours: no midpoint and no warp, the diagonal
//     0-2; a midpoint, a fan from the centre; a warped corner, the valid choice with the
//     largest smallest angle among {diagonal 0-2, diagonal 1-3, fan from the centre, fan
//     from the centroid of the four corners} (with midpoints: the two fans), ties to the
//     first. Valid means every triangle strictly counter-clockwise (exact orient2d).
// Bound: no angle below arctan(1/3) = 18.43° (the enumeration of docs/DESIGN.md, "The quadtree mesh"; the checker verifies
// kQuadtreeMinAngle = 18.4° on every output).
// Coordinates and resolution: detail/mesh_grid.hpp (the grid vertices in double; points the
// mesh cannot resolve are rejected, so every leaf of T' has level ≤ R + 1).
// Complexity: every function is O(1).
// Paper: Bern, Eppstein & Gilbert, "Provably good mesh generation" (1994), the warped
// quadtree; Acar & Hudson, Section 5.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/detail/mesh_grid.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/predicates.hpp"

namespace dynmesh::detail {

/// Corner k of a square cell, counter-clockwise from the lower left: its offsets in cells.
constexpr unsigned corner_dx(unsigned k) noexcept { return k == 1 || k == 2; }
constexpr unsigned corner_dy(unsigned k) noexcept { return k >= 2; }

/// The 2D grid, with the corner names of a square cell.
struct MeshGrid : BasicMeshGrid<2> {
  using BasicMeshGrid<2>::BasicMeshGrid;
  using BasicMeshGrid<2>::vertex;

  Point<2> vertex(std::uint64_t gx, std::uint64_t gy) const noexcept { return vertex({gx, gy}); }
  /// Grid coordinate of corner k of cell c on `axis`.
  static std::uint64_t corner_grid(const CellId<2>& c, unsigned k, unsigned axis) noexcept {
    const unsigned off = axis == 0 ? corner_dx(k) : corner_dy(k);
    return (c.index[axis] + off) << (kMaxLevel - c.level);
  }
  Point<2> corner(const CellId<2>& c, unsigned k) const noexcept {
    return vertex(corner_grid(c, k, 0), corner_grid(c, k, 1));
  }
};

/// Where p goes in T': its leaf c_t and the corner of c_t that moves onto p.
struct WarpTarget {
  CellId<2> leaf;
  unsigned corner = 0;
};

/// `tree_level`: the level of p's leaf in T*.
inline WarpTarget warp_target(const MeshGrid& grid, const Position<2>& q, const Point<2>& p, int tree_level) {
  for (int t = tree_level + 1;; ++t) {
    const CellId<2> c = cell_of(q, t);
    unsigned best = 0;
    double best_d = 0;
    // Distances in a frame scaled by a power of two where the squares could overflow or
    // underflow: the same comparisons (scaling is exact) in every box.
    const double side = grid.unit * std::ldexp(1.0, kMaxLevel - t);
    const int shift = side > 0x1p400 || side < 0x1p-400 ? -std::ilogb(side) : 0;
    for (unsigned k = 0; k < 4; ++k) {
      const Point<2> v = grid.corner(c, k);
      const double dx = std::ldexp(v[0] - p[0], shift), dy = std::ldexp(v[1] - p[1], shift);
      const double dist = dx * dx + dy * dy;
      if (k == 0 || dist < best_d) best = k, best_d = dist;
    }
    bool movable = true;
    for (unsigned a = 0; a < 2; ++a) {
      const std::uint64_t g = MeshGrid::corner_grid(c, best, a);
      if ((g == 0 || g == kResolution) && !grid.on_line(p, a, g)) movable = false;
    }
    if (movable || t == kMaxLevel) return WarpTarget{c, best};
  }
}

/// A leaf's mark in its slot's `split`: low two bits 0 (a leaf), bit 2 set, bits 3-4 the
/// warped corner k of the leaf, bits 5-6 where c_t lies: one cell towards corner k on x
/// (bit 5) and on y (bit 6).
inline constexpr std::uint8_t kWarpedLeaf = 4;
constexpr std::uint8_t warp_mark(unsigned k, unsigned ox, unsigned oy) noexcept {
  return static_cast<std::uint8_t>(kWarpedLeaf | (k << 3) | (ox << 5) | (oy << 6));
}
constexpr bool is_warped(std::uint8_t v) noexcept { return (v & 3u) == 0 && (v & kWarpedLeaf); }
constexpr unsigned warped_corner(std::uint8_t v) noexcept { return (v >> 3) & 3u; }

/// The cell holding the warping point, for a leaf with mark v.
inline CellId<2> warp_source(const CellId<2>& leaf, std::uint8_t v) noexcept {
  const unsigned k = warped_corner(v);
  CellId<2> c = leaf;
  if ((v >> 5) & 1u) c.index[0] = corner_dx(k) ? c.index[0] + 1 : c.index[0] - 1;
  if ((v >> 6) & 1u) c.index[1] = corner_dy(k) ? c.index[1] + 1 : c.index[1] - 1;
  return c;
}

/// Calls f(cell, mark) for each cell of the leaf's level around the warped vertex (corner
/// `target.corner` of `target.leaf`) that lies in the box: target.leaf itself and up to 3.
template <class F>
void for_each_marked(const WarpTarget& target, F&& f) {
  const CellId<2>& c = target.leaf;
  const unsigned k = target.corner;
  const std::uint64_t n = cells_per_axis(c.level);
  for (unsigned ox = 0; ox < 2; ++ox)
    for (unsigned oy = 0; oy < 2; ++oy) {
      // The cell one step (ox, oy) towards corner k; its own corner at v is the opposite one.
      CellId<2> x = c;
      if (ox) {
        if (corner_dx(k) ? c.index[0] + 1 >= n : c.index[0] == 0) continue;
        x.index[0] = corner_dx(k) ? c.index[0] + 1 : c.index[0] - 1;
      }
      if (oy) {
        if (corner_dy(k) ? c.index[1] + 1 >= n : c.index[1] == 0) continue;
        x.index[1] = corner_dy(k) ? c.index[1] + 1 : c.index[1] - 1;
      }
      // v seen from x: flip the axes on which x stepped.
      const unsigned vx = corner_dx(k) ^ ox, vy = corner_dy(k) ^ oy;
      const unsigned kx = vy ? (vx ? 2u : 3u) : (vx ? 1u : 0u);
      f(x, warp_mark(kx, ox, oy));
    }
}

/// The same-level neighbour across side s (0 bottom, 1 right, 2 top, 3 left), if in the box.
inline bool side_neighbour(const CellId<2>& c, unsigned s, CellId<2>& out) noexcept {
  const std::uint64_t n = cells_per_axis(c.level);
  out = c;
  switch (s) {
    case 0: if (c.index[1] == 0) return false; out.index[1] -= 1; return true;
    case 1: if (c.index[0] + 1 >= n) return false; out.index[0] += 1; return true;
    case 2: if (c.index[1] + 1 >= n) return false; out.index[1] += 1; return true;
    default: if (c.index[0] == 0) return false; out.index[0] -= 1; return true;
  }
}

/// What the triangulation of a leaf depends on.
struct LeafShape {
  using Grid = MeshGrid;
  using Simplex = Triangle;
  const CellId<2>& key() const noexcept { return cell; }
  friend bool operator==(const LeafShape&, const LeafShape&) = default;

  CellId<2> cell;
  std::uint8_t midpoints = 0;  // bit s: side s has a midpoint (a smaller neighbour there)
  std::int8_t warped = -1;     // the warped corner, or −1
  Point<2> warp_to{};          // where it moves (the point)
};

/// Smallest angle of triangle abc in radians (atan2 of |cross| and dot at each corner). The
/// differences are scaled by a power of two first (exact; the angle does not change), so the
/// products neither overflow nor underflow in a box of any side double precision allows.
inline double min_angle(const Point<2>& a, const Point<2>& b, const Point<2>& c) noexcept {
  auto angle = [](const Point<2>& o, const Point<2>& u, const Point<2>& v) {
    double ux = u[0] - o[0], uy = u[1] - o[1], vx = v[0] - o[0], vy = v[1] - o[1];
    const double m = std::fmax(std::fmax(std::fabs(ux), std::fabs(uy)), std::fmax(std::fabs(vx), std::fabs(vy)));
    if (m > 0 && std::isfinite(m) && (m < 0x1p-400 || m > 0x1p400)) {
      const int e = std::ilogb(m);
      ux = std::ldexp(ux, -e), uy = std::ldexp(uy, -e), vx = std::ldexp(vx, -e), vy = std::ldexp(vy, -e);
    }
    return std::atan2(std::fabs(ux * vy - uy * vx), ux * vx + uy * vy);
  };
  return std::fmin(angle(a, b, c), std::fmin(angle(b, c, a), angle(c, a, b)));
}

/// Appends the leaf's triangles (canonical) to `out`.
inline void triangulate_leaf(const MeshGrid& grid, const LeafShape& s, std::vector<Triangle>& out) {
  const CellId<2>& c = s.cell;
  std::array<Point<2>, 4> corner;
  std::array<std::uint64_t, 4> gx, gy;
  for (unsigned k = 0; k < 4; ++k) {
    gx[k] = MeshGrid::corner_grid(c, k, 0);
    gy[k] = MeshGrid::corner_grid(c, k, 1);
    corner[k] = grid.vertex(gx[k], gy[k]);
  }
  if (s.warped >= 0) corner[static_cast<unsigned>(s.warped)] = s.warp_to;
  // The boundary polygon, counter-clockwise.
  std::array<Point<2>, 8> poly;
  unsigned np = 0;
  for (unsigned k = 0; k < 4; ++k) {
    poly[np++] = corner[k];
    if ((s.midpoints >> k) & 1u) {
      const unsigned j = (k + 1) & 3u;
      poly[np++] = grid.vertex((gx[k] + gx[j]) / 2, (gy[k] + gy[j]) / 2);
    }
  }
  const Point<2> centre = grid.vertex((gx[0] + gx[2]) / 2, (gy[0] + gy[2]) / 2);
  auto emit = [&](const Point<2>& a, const Point<2>& b, const Point<2>& d) { out.push_back(canonical_triangle(a, b, d)); };
  if (s.warped < 0 && s.midpoints == 0) {
    emit(corner[0], corner[1], corner[2]);
    emit(corner[0], corner[2], corner[3]);
    return;
  }
  if (s.warped < 0) {
    for (unsigned i = 0; i < np; ++i) emit(centre, poly[i], poly[(i + 1) % np]);
    return;
  }
  // Each corner quartered first: the same bits as quartering the sum (a power of two
  // commutes with rounding) in every box whose coordinates stay clear of the subnormals, and
  // no overflow near the largest doubles.
  const auto quarter_sum = [&](unsigned a) {
    return (corner[0][a] * 0.25 + corner[1][a] * 0.25) + (corner[2][a] * 0.25 + corner[3][a] * 0.25);
  };
  const Point<2> centroid = {quarter_sum(0), quarter_sum(1)};
  // Candidates: 0 diagonal 0-2, 1 diagonal 1-3, 2 fan from the centre, 3 fan from the centroid.
  auto evaluate = [&](int which, bool commit) {
    double worst = 10.0;
    auto tri = [&](const Point<2>& a, const Point<2>& b, const Point<2>& d) {
      if (commit) return emit(a, b, d);
      if (orient2d(a, b, d) <= 0) worst = -1.0;
      else if (worst >= 0) worst = std::fmin(worst, min_angle(a, b, d));
    };
    switch (which) {
      case 0: tri(corner[0], corner[1], corner[2]); tri(corner[0], corner[2], corner[3]); break;
      case 1: tri(corner[1], corner[2], corner[3]); tri(corner[1], corner[3], corner[0]); break;
      default: {
        const Point<2>& hub = which == 2 ? centre : centroid;
        for (unsigned i = 0; i < np; ++i) tri(hub, poly[i], poly[(i + 1) % np]);
      }
    }
    return worst;
  };
  int best = -1;
  double best_q = -1.0;
  for (int which = s.midpoints ? 2 : 0; which < 4; ++which) {
    const double q = evaluate(which, false);
    if (q > best_q) best = which, best_q = q;
  }
  if (best_q < 0) throw InvariantError("dynmesh: no valid triangulation of warped leaf " + to_string(c));
  evaluate(best, true);
}

/// The triangles of a leaf, for the change feed's blocks; a changed leaf
/// gives all of its triangles, old and new.
inline void emit_simplices(const MeshGrid& grid, const LeafShape& s, std::vector<Triangle>& out) {
  triangulate_leaf(grid, s, out);
}
inline void emit_difference(const MeshGrid& grid, const LeafShape& before, const LeafShape& after,
                            std::vector<Triangle>& removed, std::vector<Triangle>& added) {
  triangulate_leaf(grid, before, removed);
  triangulate_leaf(grid, after, added);
}

}  // namespace dynmesh::detail
