// dynmesh/detail/octree_mesh_rules.hpp — the rules of the octree's tetrahedral mesh, shared by
// the static twin (OctreeMesh) and the self-adjusting program (DynamicOctreeMesh), so that the
// two compute the same tetrahedra bit for bit.
//
// Purpose. The 3D postprocess of the well-graded octree (docs/OCTREE_MESH.md):
//   * Block of a point p. Let l be the level of p's leaf in T*. The owner of p is c_t, the
//     cell of level t holding p, and v the corner of c_t on p's side of its centre on every
//     axis (by the bit of p's located position one level below t), where t is the least
//     level > l at which v lies on no box face that p is not on. p's block is the 2x2x2
//     cells of level t around v that lie in the box; |p − v|∞ ≤ s/2 for the side s of c_t.
//   * Closure T' of T*: split the parent of every block cell, for every point, then whatever
//     grading then forces (a level m−1 cell touching a split level-m cell). A block cell is
//     then a leaf: the block lies in p's T* neighbourhood, which holds no other point, and
//     the closure only adds splits below level t or around other points, whose blocks stay
//     clear of p's. The checkers (require_refined_tree) verify it on every output.
//   * Faces. Every square face F of a leaf of level m (a face of a block cell included) is
//     triangulated by the split state of the level-m cells around it alone, so the two cells
//     that share F agree: the cell across F split → F's four quarters, each cut by its
//     diagonal from its lowest to its highest corner; otherwise, when a level-m cell around an
//     edge of F is split, that edge has a midpoint, and F is fanned from its centre over its
//     corners and midpoints; otherwise F is cut by its lowest-to-highest diagonal.
//   * Leaves. A leaf with no split cell across any face or around any edge is cut into the
//     six Kuhn tetrahedra around its lowest-to-highest diagonal (they cut every face by that
//     same diagonal). Any other leaf outside every block is coned from its centre over its
//     faces' triangles. A block is coned from p over the triangles of its outer faces (the
//     faces of block cells whose cell across is not in the block): p takes the place of v, the
//     block's cells get no tetrahedra of their own, and a block face lying in a box face holds
//     v and p and is no outer face.
// Bound: every dihedral angle lies in [kOctreeMinDihedral, kOctreeMaxDihedral]
// (octree_mesh.hpp); tests/dynmesh/octree_mesh_bound_test.cpp proves it for every face type,
// every leaf and every point position in its region, by interval arithmetic.
// Exactness: every vertex is a grid vertex of a level ≤ 52 (mesh_grid.hpp) or an input
// point, so no predicate decides a template; the orientation of each tetrahedron is known
// from its face's outward side (the apex lies strictly inside).
// Complexity: every function is O(1) (at most 24 faces of 8 triangles).
// Paper: Bern, Eppstein & Gilbert (1994); Mitchell & Vavasis (1992); Kuhn's subdivision of
// the cube; Acar & Hudson, Section 2.2 (any standard postprocess of the well-graded tree).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/detail/mesh_grid.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/tet_mesh.hpp"

namespace dynmesh::detail {

using OctreeGrid = BasicMeshGrid<3>;
using GridPoint3 = std::array<std::uint64_t, 3>;

/// Where p goes in T': its owner c_t and the corner v of c_t (bit a set: v is on c_t's upper
/// side on axis a).
struct BlockTarget {
  CellId<3> owner;
  unsigned corner = 0;
};

/// `tree_level`: the level of p's leaf in T*.
inline BlockTarget block_target(const OctreeGrid& grid, const Position<3>& q, const Point<3>& p, int tree_level) {
  for (int t = tree_level + 1;; ++t) {
    const CellId<3> c = cell_of(q, t);
    unsigned k = 0;
    if (t < kMaxLevel)
      for (unsigned a = 0; a < 3; ++a) k |= static_cast<unsigned>((q[a] >> (kMaxLevel - t - 1)) & 1u) << a;
    bool movable = true;
    for (unsigned a = 0; a < 3; ++a) {
      const std::uint64_t g = (c.index[a] + ((k >> a) & 1u)) << (kMaxLevel - t);
      if ((g == 0 || g == kResolution) && !grid.on_line(p, a, g)) movable = false;
    }
    if (movable || t == kMaxLevel) return BlockTarget{c, k};
  }
}

/// A block cell's mark in its slot's `split`: low two bits 0 (a leaf), bit 2 set, bit 3 set
/// on the owner, bits 4-6 its position b in the block (bit 4 + a: upper on axis a; the
/// block's cells have index v − 1 + b, v the level-t index of the block's vertex).
inline constexpr std::uint8_t kBlockCell = 4;
inline constexpr std::uint8_t kBlockOwner = 8;
constexpr std::uint8_t block_mark(unsigned b, bool owner) noexcept {
  return static_cast<std::uint8_t>(kBlockCell | (owner ? kBlockOwner : 0) | (b << 4));
}
constexpr bool is_block_cell(std::uint8_t v) noexcept { return (v & 3u) == 0 && (v & kBlockCell); }
constexpr bool is_block_owner(std::uint8_t v) noexcept { return is_block_cell(v) && (v & kBlockOwner); }
constexpr unsigned block_position(std::uint8_t v) noexcept { return (v >> 4) & 7u; }

/// The owner's position in its block: the owner lies below v on the axes where v is its
/// upper corner.
constexpr unsigned owner_position(unsigned corner) noexcept { return ~corner & 7u; }

/// Calls f(cell, mark) for each cell of the block of `target` that lies in the box.
template <class F>
void for_each_block_cell(const BlockTarget& target, F&& f) {
  const CellId<3>& c = target.owner;
  const std::uint64_t n = cells_per_axis(c.level);
  const unsigned own = owner_position(target.corner);
  for (unsigned b = 0; b < 8; ++b) {
    CellId<3> x = c;
    bool inside = true;
    for (unsigned a = 0; a < 3; ++a) {
      // Index v − 1 + b_a, with v = owner + corner_a: the owner's own index when b_a is its.
      const std::uint64_t v = c.index[a] + ((target.corner >> a) & 1u);
      const unsigned ba = (b >> a) & 1u;
      if (v + ba == 0 || v + ba - 1 >= n) inside = false;
      x.index[a] = v + ba - 1;
    }
    if (inside) f(x, block_mark(b, b == own));
  }
}

/// Calls f(u) once for each distinct parent of the block's cells (the level t−1 cells whose
/// closure holds v): on an axis where v's index is odd, both block cells share a parent.
template <class F>
void for_each_block_parent(const BlockTarget& target, F&& f) {
  std::uint64_t lo[3], hi[3];
  const std::uint64_t n = cells_per_axis(target.owner.level);
  for (unsigned a = 0; a < 3; ++a) {
    const std::uint64_t v = target.owner.index[a] + ((target.corner >> a) & 1u);
    const std::uint64_t first = v == 0 ? 0 : v - 1, last = v >= n ? n - 1 : v;  // the block's cells in the box
    lo[a] = first >> 1;
    hi[a] = last >> 1;
  }
  CellId<3> u;
  u.level = target.owner.level - 1;
  for (std::uint64_t z = lo[2]; z <= hi[2]; ++z)
    for (std::uint64_t y = lo[1]; y <= hi[1]; ++y)
      for (std::uint64_t x = lo[0]; x <= hi[0]; ++x) {
        u.index = {x, y, z};
        f(u);
      }
}

/// The block's target recovered from its owner's cell and mark (the inverse of the owner's
/// entry of for_each_block_cell).
constexpr unsigned block_corner(std::uint8_t owner_mark) noexcept { return ~block_position(owner_mark) & 7u; }

// ---------------------------------------------------------------------------- the templates

/// Neighbourhood split masks. A leaf's: bit (x + 3y + 9z) for the level-m cell at offset
/// (x − 1, y − 1, z − 1). A block's: bit (x + 4y + 16z) for the level-t cell of index
/// v − 2 + (x, y, z). Cells outside the box read as unsplit.
constexpr unsigned leaf_bit(int dx, int dy, int dz) noexcept {
  return static_cast<unsigned>((dx + 1) + 3 * (dy + 1) + 9 * (dz + 1));
}
constexpr unsigned block_bit(int x, int y, int z) noexcept { return static_cast<unsigned>(x + 4 * y + 16 * z); }

namespace octree_detail {

/// Emits the tetrahedra (apex, triangle) of face `axis`/`upper` of the level-m cell whose
/// lowest corner is grid point `lo`, triangulated by the face rule; split(dx, dy, dz) tells
/// whether the level-m cell at that offset from the cell is split. The triangles are wound
/// counter-clockwise seen from outside the cell, so each tetrahedron is positive when the
/// apex lies strictly inside.
template <class Split, class Emit>
void cone_face(const GridPoint3& lo, int level, unsigned axis, bool upper, Split&& split, Emit&& emit) {
  const std::uint64_t s = std::uint64_t{1} << (kMaxLevel - level), h = s / 2;
  const unsigned b = (axis + 1) % 3, c = (axis + 2) % 3;  // e_b × e_c = e_axis
  const int out = upper ? 1 : -1;
  auto offset = [&](int da, int db, int dc) {
    int o[3] = {0, 0, 0};
    o[axis] = da, o[b] = db, o[c] = dc;
    return split(o[0], o[1], o[2]);
  };
  // Face point (u, w) in the face's own coordinates along b and c.
  auto at = [&](std::uint64_t u, std::uint64_t w) {
    GridPoint3 g = lo;
    g[axis] += upper ? s : 0;
    g[b] += u;
    g[c] += w;
    return g;
  };
  auto tri = [&](const GridPoint3& p, const GridPoint3& q, const GridPoint3& r) {
    if (upper) emit(p, q, r);
    else emit(p, r, q);
  };
  if (offset(out, 0, 0)) {  // the cell across is split: four quarters, each by its diagonal
    for (std::uint64_t i = 0; i < 2; ++i)
      for (std::uint64_t j = 0; j < 2; ++j) {
        const std::uint64_t u = i * h, w = j * h;
        tri(at(u, w), at(u + h, w), at(u + h, w + h));
        tri(at(u, w), at(u + h, w + h), at(u, w + h));
      }
    return;
  }
  // Edge k of the polygon (0,0) (s,0) (s,s) (0,s): its three other cells.
  const int side_b[4] = {0, 1, 0, -1}, side_c[4] = {-1, 0, 1, 0};
  unsigned mids = 0;
  for (unsigned k = 0; k < 4; ++k)
    if (offset(0, side_b[k], side_c[k]) || offset(out, side_b[k], side_c[k])) mids |= 1u << k;
  if (mids == 0) {
    tri(at(0, 0), at(s, 0), at(s, s));
    tri(at(0, 0), at(s, s), at(0, s));
    return;
  }
  const std::uint64_t cu[4] = {0, s, s, 0}, cw[4] = {0, 0, s, s};
  std::array<GridPoint3, 8> poly;
  unsigned np = 0;
  for (unsigned k = 0; k < 4; ++k) {
    poly[np++] = at(cu[k], cw[k]);
    if ((mids >> k) & 1u) poly[np++] = at((cu[k] + cu[(k + 1) & 3u]) / 2, (cw[k] + cw[(k + 1) & 3u]) / 2);
  }
  const GridPoint3 centre = at(h, h);
  for (unsigned i = 0; i < np; ++i) tri(centre, poly[i], poly[(i + 1) % np]);
}

inline GridPoint3 cell_corner(const CellId<3>& c) noexcept {
  GridPoint3 g;
  for (unsigned a = 0; a < 3; ++a) g[a] = c.index[a] << (kMaxLevel - c.level);
  return g;
}

}  // namespace octree_detail

/// The leaf mask's bits of the cells across a face or around an edge (one or two offsets
/// nonzero); the vertex neighbours do not touch a face's triangulation.
inline constexpr std::uint32_t kFaceEdgeNeighbours = [] {
  std::uint32_t m = 0;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x) {
        const int nonzero = (x != 0) + (y != 0) + (z != 0);
        if (nonzero == 1 || nonzero == 2) m |= std::uint32_t{1} << leaf_bit(x, y, z);
      }
  return m;
}();

/// Appends the tetrahedra of a leaf outside every block (canonical) to `out`. `mask`: the
/// leaf's neighbourhood split mask.
inline void tetrahedralize_leaf(const OctreeGrid& grid, const CellId<3>& cell, std::uint32_t mask,
                                std::vector<Tetrahedron>& out) {
  auto split = [mask](int dx, int dy, int dz) { return ((mask >> leaf_bit(dx, dy, dz)) & 1u) != 0; };
  const GridPoint3 lo = octree_detail::cell_corner(cell);
  const std::uint64_t s = std::uint64_t{1} << (kMaxLevel - cell.level);
  // Kuhn's six when nothing across a face or around an edge is split.
  if ((mask & kFaceEdgeNeighbours) == 0) {
    static constexpr unsigned kPerm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
    const Point<3> first = grid.vertex(lo), last = grid.vertex({lo[0] + s, lo[1] + s, lo[2] + s});
    for (unsigned i = 0; i < 6; ++i) {
      GridPoint3 g1 = lo;
      g1[kPerm[i][0]] += s;
      GridPoint3 g2 = g1;
      g2[kPerm[i][1]] += s;
      const Point<3> a = grid.vertex(g1), b = grid.vertex(g2);
      // det(e_π0, e_π0 + e_π1, 1) = sign(π): the first three permutations are even.
      out.push_back(i < 3 ? canonical_tetrahedron(first, a, b, last) : canonical_tetrahedron(first, b, a, last));
    }
    return;
  }
  const Point<3> centre = grid.vertex({lo[0] + s / 2, lo[1] + s / 2, lo[2] + s / 2});
  for (unsigned axis = 0; axis < 3; ++axis)
    for (bool upper : {false, true})
      octree_detail::cone_face(lo, cell.level, axis, upper, split,
                               [&](const GridPoint3& a, const GridPoint3& b, const GridPoint3& c) {
                                 out.push_back(canonical_tetrahedron(centre, grid.vertex(a), grid.vertex(b), grid.vertex(c)));
                               });
}

/// Appends the tetrahedra of the block of `owner` (its corner `corner`, its point p) to `out`.
/// `mask`: the block's neighbourhood split mask.
inline void tetrahedralize_block(const OctreeGrid& grid, const CellId<3>& owner, unsigned corner, const Point<3>& p,
                                 std::uint64_t mask, std::vector<Tetrahedron>& out) {
  for_each_block_cell(BlockTarget{owner, corner}, [&](const CellId<3>& cell, std::uint8_t mark) {
    const unsigned b = block_position(mark);
    // x's position in the mask's frame is 1 + b per axis.
    auto split = [mask, b](int dx, int dy, int dz) {
      const int x0 = 1 + static_cast<int>(b & 1u) + dx, y0 = 1 + static_cast<int>((b >> 1) & 1u) + dy,
                z0 = 1 + static_cast<int>((b >> 2) & 1u) + dz;
      return ((mask >> block_bit(x0, y0, z0)) & 1u) != 0;
    };
    const GridPoint3 lo = octree_detail::cell_corner(cell);
    // The outer faces: on axis a, the side away from v.
    for (unsigned axis = 0; axis < 3; ++axis)
      octree_detail::cone_face(lo, cell.level, axis, ((b >> axis) & 1u) != 0, split,
                               [&](const GridPoint3& g0, const GridPoint3& g1, const GridPoint3& g2) {
                                 out.push_back(canonical_tetrahedron(p, grid.vertex(g0), grid.vertex(g1), grid.vertex(g2)));
                               });
  });
}

/// The level-t cell of the block frame's (x, y, z) (0..3 per axis), if it lies in the box.
inline bool block_frame_cell(const CellId<3>& owner, unsigned corner, int x, int y, int z, CellId<3>& out) noexcept {
  const std::uint64_t n = cells_per_axis(owner.level);
  const int f[3] = {x, y, z};
  out.level = owner.level;
  for (unsigned a = 0; a < 3; ++a) {
    const std::uint64_t v = owner.index[a] + ((corner >> a) & 1u);
    // index v − 2 + f
    if (v + static_cast<std::uint64_t>(f[a]) < 2) return false;
    const std::uint64_t i = v + static_cast<std::uint64_t>(f[a]) - 2;
    if (i >= n) return false;
    out.index[a] = i;
  }
  return true;
}

/// The level-m cell at offset (dx, dy, dz) from `cell`, if it lies in the box.
inline bool offset_cell(const CellId<3>& cell, int dx, int dy, int dz, CellId<3>& out) noexcept {
  const std::uint64_t n = cells_per_axis(cell.level);
  const int f[3] = {dx, dy, dz};
  out.level = cell.level;
  for (unsigned a = 0; a < 3; ++a) {
    if (f[a] < 0 && cell.index[a] == 0) return false;
    const std::uint64_t i = cell.index[a] + static_cast<std::uint64_t>(static_cast<std::int64_t>(f[a]));
    if (i >= n) return false;
    out.index[a] = i;
  }
  return true;
}

/// A leaf's neighbourhood split mask from `is_split(cell)`, over the cells across its faces
/// and edges (kFaceEdgeNeighbours; the others never change its tetrahedra).
template <class IsSplit>
std::uint32_t leaf_mask(const CellId<3>& cell, IsSplit&& is_split) {
  std::uint32_t mask = 0;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x) {
        const std::uint32_t bit = std::uint32_t{1} << leaf_bit(x, y, z);
        CellId<3> nb;
        if ((kFaceEdgeNeighbours & bit) && offset_cell(cell, x, y, z, nb) && is_split(nb)) mask |= bit;
      }
  return mask;
}

/// A block's neighbourhood split mask from `is_split(cell)`.
template <class IsSplit>
std::uint64_t block_mask(const CellId<3>& owner, unsigned corner, IsSplit&& is_split) {
  std::uint64_t mask = 0;
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        CellId<3> c;
        if (block_frame_cell(owner, corner, x, y, z, c) && is_split(c)) mask |= std::uint64_t{1} << block_bit(x, y, z);
      }
  return mask;
}

}  // namespace dynmesh::detail
