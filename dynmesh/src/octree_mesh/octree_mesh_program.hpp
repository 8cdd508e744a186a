// octree_mesh_program.hpp (private) — the octree mesh written as static code on sac-runtime,
// run after QuadTreeRefine in the same run() (DynamicOctreeMesh).
//
// Purpose: the rules of detail/octree_mesh_rules.hpp as a program whose trace is local, so
// that a point update changes O(lg L/s) of it:
//
//   main:        place(each input point); then gather(the root); then emit(the root)
//   place(p):    descend to p's leaf in T*; p's block target; SPLIT' the parent of each
//                block cell; mark the block's cells; owner.pts := p
//   split'(c):   unless c is split: c.split := kRefineSplit; split' each coarser cell
//                touching c (grading)
//   gather(c):   c split: read its eight children's split values as one event, write them to
//                c.kids; gather each split child
//   emit(c):     read c.kids; emit each split child; if c has a leaf child, read the kids of
//                c's neighbours (two events) and make the block of c's leaf children's
//                tetrahedra (the owner's block cone included, with its point read from
//                owner.pts)
//
// Why two walks: a leaf's tetrahedra depend on the split state of its 26 same-size
// neighbours, all children of its parent's 3x3x3 neighbourhood. Reading those 27 cells' kids
// (one 64-bit value each) once per split cell costs about a third of what reading each leaf's
// neighbours would, and the unit of output, a split cell's leaf children, is coarse.
// How it is made stable and order independent: as the quadtree mesh's program
// (quadtree_mesh_program.hpp): T' and the marks are later versions of the same `split`
// modifiables that QuadTreeRefine reads earlier in the trace; p's T* level is found from the
// T* bit alone; T' is a least closure, a set; each point's work is memoized on its list node;
// the walks are memoized per cell. The kids are written in the first walk, which precedes the
// second in the trace, so every read of them sees the final T'. A cell no longer split has no
// write of its kids left, so they read as zero: no child split.
// Complexity: from scratch O(Σ_p depth(p) + |T'|) events; per update O(lg L/s) expected.
// Paper: Acar & Hudson, Section 4 (dynamizing by change propagation) and Section 2.2.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <sac/engine.hpp>
#include <sac/fn.hpp>

#include "dynmesh/detail/octree_mesh_rules.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/tet_mesh.hpp"
#include "mesh/block_feed.hpp"
#include "mesh/point_placement.hpp"
#include "quadtree/quadtree_core.hpp"

namespace dynmesh::detail {

/// The tetrahedra of a split cell's leaf children (or of the root, when it is a leaf).
struct OctreeGroupShape {
  using Grid = OctreeGrid;
  using Simplex = Tetrahedron;
  static constexpr std::uint32_t kNone = ~std::uint32_t{0};  // a child that emits nothing here

  CellId<3> cell;                  // the split cell, or the root leaf
  std::array<std::uint32_t, 8> masks{kNone, kNone, kNone, kNone, kNone, kNone, kNone, kNone};
  std::uint64_t block = 0;         // the owner's block mask
  Point<3> point{};                // the owner's point
  std::int8_t owner = -1;          // the child that owns a block, or −1
  std::uint8_t corner = 0;         // the owner's block corner
  bool root_leaf = false;

  const CellId<3>& key() const noexcept { return cell; }
  friend bool operator==(const OctreeGroupShape&, const OctreeGroupShape&) = default;
};

/// The tetrahedra child w contributes to the group.
inline void emit_child(const OctreeGrid& grid, const OctreeGroupShape& s, unsigned w, std::vector<Tetrahedron>& out) {
  if (static_cast<int>(w) == s.owner) tetrahedralize_block(grid, child(s.cell, w), s.corner, s.point, s.block, out);
  else if (s.masks[w] != OctreeGroupShape::kNone) tetrahedralize_leaf(grid, child(s.cell, w), s.masks[w], out);
}

inline void emit_simplices(const OctreeGrid& grid, const OctreeGroupShape& s, std::vector<Tetrahedron>& out) {
  if (s.root_leaf) return tetrahedralize_leaf(grid, s.cell, 0, out);
  for (unsigned w = 0; w < 8; ++w) emit_child(grid, s, w, out);
}

/// Only the children whose own shape changed: a leaf's tetrahedra depend on its mask alone,
/// the owner's on its block mask, corner and point.
inline void emit_difference(const OctreeGrid& grid, const OctreeGroupShape& before, const OctreeGroupShape& after,
                            std::vector<Tetrahedron>& removed, std::vector<Tetrahedron>& added) {
  if (before.root_leaf || after.root_leaf) {
    emit_simplices(grid, before, removed);
    emit_simplices(grid, after, added);
    return;
  }
  for (unsigned w = 0; w < 8; ++w) {
    const bool was_owner = static_cast<int>(w) == before.owner, is_owner = static_cast<int>(w) == after.owner;
    const bool same = was_owner == is_owner && before.masks[w] == after.masks[w] &&
                      (!is_owner || (before.block == after.block && before.corner == after.corner &&
                                     before.point == after.point));
    if (same) continue;
    emit_child(grid, before, w, removed);
    emit_child(grid, after, w, added);
  }
}

/// The split value of child w in a kids word.
constexpr std::uint8_t kid(std::uint64_t kids, unsigned w) noexcept {
  return static_cast<std::uint8_t>(kids >> (8 * w));
}

/// The shape of c's leaf children from the kids of c's 3x3x3 neighbourhood (`near`, by
/// leaf_bit offset; zero outside the box). `point` is the owner's point when there is one.
inline OctreeGroupShape group_shape(const CellId<3>& c, const std::array<std::uint64_t, 27>& near,
                                    const Point<3>& point) {
  // Is the level-(c.level + 1) cell x split? Its parent is c or one of c's neighbours.
  auto split = [&](const CellId<3>& cell) {
    const CellId<3> p = parent(cell);
    int off[3];
    for (unsigned a = 0; a < 3; ++a) off[a] = static_cast<int>(p.index[a] - c.index[a]);
    unsigned w = 0;
    for (unsigned a = 0; a < 3; ++a) w |= static_cast<unsigned>(cell.index[a] & 1u) << a;
    return any_split(kid(near[leaf_bit(off[0], off[1], off[2])], w));
  };
  OctreeGroupShape s;
  s.cell = c;
  s.point = point;
  const std::uint64_t own = near[leaf_bit(0, 0, 0)];
  for (unsigned w = 0; w < 8; ++w) {
    const std::uint8_t v = kid(own, w);
    if (any_split(v)) continue;
    const CellId<3> x = child(c, w);
    if (is_block_owner(v)) {
      s.owner = static_cast<std::int8_t>(w);
      s.corner = static_cast<std::uint8_t>(block_corner(v));
      s.block = block_mask(x, s.corner, split);
    } else if (!is_block_cell(v)) {
      s.masks[w] = leaf_mask(x, split);
    }
  }
  return s;
}

using OctreeFeed = BlockFeed<OctreeGroupShape>;
using OctreeBlock = FeedBlock<OctreeGroupShape>;

struct OctreeMeshProgram {
  using Node = PNode<3>;
  using Kids = sac::Mod<std::uint64_t>;
  Directory<3>* dir;
  sac::Mod<Node*>* input;
  OctreeFeed* log;

  using Placement = PointPlacement<3, OctreeMeshProgram>;

  Slot<3>& slot(sac::Engine& rt, const CellId<3>& c) { return dir->get(rt, c); }
  const OctreeGrid& grid() const { return log->grid; }

  static void main(sac::Engine& rt, OctreeMeshProgram* program) {
    rt.memo_read(*program->input, sac::fn<&Placement::place>(program));
    rt.memo(sac::fn<&gather_root>(program));
    rt.memo(sac::fn<&emit_root>(program));
  }

  // ------------------------------------------------------------------ the points
  static void settle(sac::Engine& rt, OctreeMeshProgram* program, Node* n, int tree_level) {
    const auto* in = static_cast<const InputNode<3>*>(n);
    const BlockTarget t = block_target(program->grid(), n->q, in->point, tree_level);
    for_each_block_parent(t, [&](const CellId<3>& u) { Placement::split(rt, program, u); });
    for_each_block_cell(t, [&](const CellId<3>& cell, std::uint8_t mark) { Placement::mark(rt, program, cell, mark); });
    rt.write(program->slot(rt, t.owner).pts, n);
  }

  // ------------------------------------------------------------------ first walk: the kids
  static void gather_root(sac::Engine& rt, OctreeMeshProgram* program) {
    rt.read(program->slot(rt, CellId<3>::root()).split, [program](sac::Engine& rt2, std::uint8_t v) {
      if (any_split(v)) rt2.memo(sac::fn<&gather>(program, CellId<3>::root()));
    });
  }

  static void gather(sac::Engine& rt, OctreeMeshProgram* program, CellId<3> c) {
    std::array<const sac::Mod<std::uint8_t>*, 8> kids;
    for (unsigned w = 0; w < 8; ++w) kids[w] = &program->slot(rt, child(c, w)).split;
    // The closures hold their cell packed (24 bytes, not 32): a split cell of T' makes two.
    rt.read_many(std::span<const sac::Mod<std::uint8_t>* const>(kids), [program, k = pack_cell<3>(c)](sac::Engine& rt2, std::span<const std::uint8_t* const> v) {
      const CellId<3> cell = unpack_cell<3>(k);
      std::uint64_t word = 0;
      for (unsigned w = 0; w < 8; ++w) word |= std::uint64_t{*v[w]} << (8 * w);
      rt2.write(program->slot(rt2, cell).kids, word);
      for (unsigned w = 0; w < 8; ++w)
        if (any_split(*v[w])) rt2.memo(sac::fn<&gather>(program, child(cell, w)));
    });
  }

  // ------------------------------------------------------------------ second walk: the blocks
  static void emit_root(sac::Engine& rt, OctreeMeshProgram* program) {
    rt.read(program->slot(rt, CellId<3>::root()).split, [program](sac::Engine& rt2, std::uint8_t v) {
      if (any_split(v)) {
        rt2.memo(sac::fn<&emit>(program, CellId<3>::root()));
      } else {
        OctreeGroupShape s;
        s.root_leaf = true;
        rt2.make<OctreeBlock>(program->log, s);
      }
    });
  }

  static void emit(sac::Engine& rt, OctreeMeshProgram* program, CellId<3> c) {
    rt.read(program->slot(rt, c).kids, [program, k = pack_cell<3>(c)](sac::Engine& rt2, std::uint64_t own) {
      const CellId<3> cell = unpack_cell<3>(k);
      bool leaves = false;
      for (unsigned w = 0; w < 8; ++w) {
        if (any_split(kid(own, w))) rt2.memo(sac::fn<&emit>(program, child(cell, w)));
        else leaves = true;
      }
      if (leaves) group(rt2, program, cell, own);
    });
  }

  /// The neighbours of c in the box whose kids the group reads, in for_each_neighbour's
  /// order, with their offsets: the 18 across c's faces and edges (every face and edge
  /// neighbour of a child lies in one of them), and the 8 across its corners too when a child
  /// owns a block (its ring reaches them).
  struct Near {
    std::array<const Kids*, 26> mods{};
    std::array<std::uint8_t, 26> bit{};
    unsigned n = 0;
  };
  static Near near_of(sac::Engine& rt, OctreeMeshProgram* program, const CellId<3>& c, bool corners) {
    Near out;
    for_each_neighbour(c, [&](const CellId<3>& nb) {
      int off[3];
      for (unsigned a = 0; a < 3; ++a) off[a] = static_cast<int>(nb.index[a] - c.index[a]);
      if (!corners && off[0] != 0 && off[1] != 0 && off[2] != 0) return;
      out.bit[out.n] = static_cast<std::uint8_t>(leaf_bit(off[0], off[1], off[2]));
      out.mods[out.n++] = &program->slot(rt, nb).kids;
    });
    return out;
  }
  static bool has_owner(std::uint64_t own) noexcept {
    for (unsigned w = 0; w < 8; ++w)
      if (is_block_owner(kid(own, w))) return true;
    return false;
  }

  /// Two events of at most 13 (Engine::read_many reads 16 at most).
  static void group(sac::Engine& rt, OctreeMeshProgram* program, const CellId<3>& c, std::uint64_t own) {
    const Near nb = near_of(rt, program, c, has_owner(own));
    if (nb.n == 0) return finish(rt, program, c, own, nb);  // the root has no neighbours
    const unsigned first = (nb.n + 1) / 2;
    rt.read_many(std::span<const Kids* const>(nb.mods.data(), first),
                 [program, k = pack_cell<3>(c), own](sac::Engine& rt2, std::span<const std::uint64_t* const>) {
                   const CellId<3> cell = unpack_cell<3>(k);
                   const Near all = near_of(rt2, program, cell, has_owner(own));
                   const unsigned half = (all.n + 1) / 2;
                   if (all.n == half) return finish(rt2, program, cell, own, all);
                   rt2.read_many(std::span<const Kids* const>(all.mods.data() + half, all.n - half),
                                 [program, k, own](sac::Engine& rt3, std::span<const std::uint64_t* const>) {
                                   const CellId<3> at = unpack_cell<3>(k);
                                   finish(rt3, program, at, own, near_of(rt3, program, at, has_owner(own)));
                                 });
                 });
  }

  /// Every neighbour's kids has been read by an enclosing event of this body: current().
  static void finish(sac::Engine& rt, OctreeMeshProgram* program, const CellId<3>& c, std::uint64_t own, const Near& nb) {
    std::array<std::uint64_t, 27> near{};
    near[leaf_bit(0, 0, 0)] = own;
    for (unsigned i = 0; i < nb.n; ++i) near[nb.bit[i]] = rt.current(*nb.mods[i]);
    int owner = -1;
    for (unsigned w = 0; w < 8; ++w)
      if (is_block_owner(kid(own, w))) owner = static_cast<int>(w);
    if (owner < 0) {
      rt.make<OctreeBlock>(program->log, group_shape(c, near, Point<3>{}));
      return;
    }
    rt.read(program->slot(rt, child(c, static_cast<unsigned>(owner))).pts, [program, c, near](sac::Engine& rt2, Node* p) {
      if (!p) throw InvariantError("dynmesh: a block owner without its point");
      rt2.make<OctreeBlock>(program->log, group_shape(c, near, static_cast<const InputNode<3>*>(p)->point));
    });
  }
};

}  // namespace dynmesh::detail
