// octree_mesh.cpp — the static twin of the octree mesh: T* from StaticQuadtree<3>, the
// closure T' by a work list, the blocks, and the leaves tetrahedralized by the shared rules.
#include "dynmesh/octree_mesh.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "dynmesh/detail/cell_table.hpp"
#include "dynmesh/detail/octree_mesh_rules.hpp"
#include "dynmesh/errors.hpp"
#include "io/locate_points.hpp"

namespace dynmesh {
namespace {

using detail::CellTable;
using detail::OctreeGrid;

}  // namespace

OctreeMesh::OctreeMesh(const Box<3>& box, std::span<const Point<3>> points)
    : box_(box), points_(points.begin(), points.end()), tree_(detail::locate_all<3>(box, points)) {
  const OctreeGrid grid(box);
  const auto qs = tree_.points();
  detail::check_resolution<3>(grid, points, qs);
  validate_mesh_box(box);

  // T': T*'s split cells, then every block's parents and what grading forces.
  CellTable<3> split(tree_.num_split() * 2 + 16 * qs.size());
  for (const CellId<3>& c : tree_.split_cells()) split.try_emplace(c);
  std::vector<CellId<3>> work;
  auto refine = [&](const CellId<3>& seed) {
    if (!split.try_emplace(seed).second) return;
    work.push_back(seed);
    while (!work.empty()) {
      const CellId<3> c = work.back();
      work.pop_back();
      if (c.level == 0) continue;
      for_each_coarser_touching(c, [&](const CellId<3>& u) {
        if (split.try_emplace(u).second) work.push_back(u);
      });
    }
  };
  std::vector<detail::BlockTarget> targets(qs.size());
  for (std::size_t i = 0; i < qs.size(); ++i) {
    targets[i] = detail::block_target(grid, qs[i], points_[i], tree_.locate(qs[i]).level);
    detail::for_each_block_parent(targets[i], refine);
  }
  // The marks: which leaf belongs to which point's block.
  struct Mark {
    std::uint8_t mark;
    std::uint32_t point;
  };
  CellTable<3, Mark> marks(qs.size() * 8);
  for (std::size_t i = 0; i < qs.size(); ++i)
    detail::for_each_block_cell(targets[i], [&](const CellId<3>& cell, std::uint8_t v) {
      if (!marks.try_emplace(cell, Mark{v, static_cast<std::uint32_t>(i)}).second)
        throw InvariantError("dynmesh: cell " + to_string(cell) + " lies in two points' blocks");
    });

  auto is_split = [&](const CellId<3>& c) { return split.contains(c); };
  std::vector<CellId<3>> stack{CellId<3>::root()};
  while (!stack.empty()) {
    const CellId<3> c = stack.back();
    stack.pop_back();
    if (is_split(c)) {
      for (unsigned w = 8; w-- > 0;) stack.push_back(child(c, w));
      continue;
    }
    const Mark* m = marks.find(c);
    leaves_.push_back(Leaf<3>{c, m && detail::is_block_owner(m->mark) ? 1u : 0u});
    if (!m) {
      detail::tetrahedralize_leaf(grid, c, detail::leaf_mask(c, is_split), tets_);
    } else if (detail::is_block_owner(m->mark)) {
      const unsigned corner = detail::block_corner(m->mark);
      detail::tetrahedralize_block(grid, c, corner, points_[m->point], detail::block_mask(c, corner, is_split), tets_);
    }
  }
  std::sort(leaves_.begin(), leaves_.end());
  std::sort(tets_.begin(), tets_.end());
}

void validate_mesh_box(const Box<3>& box) {
  if (OctreeGrid(box).level_limit < 2)
    throw InputError(InputError::Kind::Resolution,
                     "the domain box is too small for its offset: double coordinates cannot resolve its cells");
}

void require_refined_tree(std::span<const Leaf<3>> leaves, std::span<const Position<3>> points) {
  CellTable<3, std::uint32_t> leaf_set(leaves.size());
  std::size_t holding = 0;
  for (const Leaf<3>& l : leaves) {
    if (!leaf_set.try_emplace(l.cell, l.npoints).second)
      throw InvariantError("dynmesh: leaf " + to_string(l.cell) + " meshed twice");
    holding += l.npoints;
  }
  if (holding != points.size()) throw InvariantError("dynmesh: the refined tree's point leaves do not match the points");
  for (const Position<3>& q : points) {
    // The owner: the leaf holding q; its block's corner is on q's side of its centre.
    int t = 0;
    const std::uint32_t* held = nullptr;
    for (; t <= kMaxLevel && !(held = leaf_set.find(cell_of(q, t))); ++t) {
    }
    if (!held || *held != 1)
      throw InvariantError("dynmesh: the leaf holding a point does not say so");
    const CellId<3> owner = cell_of(q, t);
    unsigned corner = 0;
    if (t < kMaxLevel)
      for (unsigned a = 0; a < 3; ++a) corner |= static_cast<unsigned>((q[a] >> (kMaxLevel - t - 1)) & 1u) << a;
    detail::for_each_block_cell(detail::BlockTarget{owner, corner}, [&](const CellId<3>& cell, std::uint8_t mark) {
      const std::uint32_t* k = leaf_set.find(cell);
      if (!k) throw InvariantError("dynmesh: block cell " + to_string(cell) + " of point leaf " + to_string(owner) + " is not a leaf");
      if (!detail::is_block_owner(mark) && *k != 0)
        throw InvariantError("dynmesh: block cell " + to_string(cell) + " of point leaf " + to_string(owner) + " holds a point");
    });
  }
}

void OctreeMesh::check_invariants() const { require_refined_tree(leaves_, tree_.points()); }

}  // namespace dynmesh
