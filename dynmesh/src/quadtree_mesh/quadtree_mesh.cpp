// quadtree_mesh.cpp — the static twin of the quadtree mesh: T* from StaticQuadtree, the
// closure T' by a work list, the warps, and the leaves triangulated by the shared rules.
#include "dynmesh/quadtree_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "dynmesh/detail/cell_table.hpp"
#include "dynmesh/detail/quadtree_mesh_rules.hpp"
#include "dynmesh/errors.hpp"
#include "io/locate_points.hpp"

namespace dynmesh {
namespace {

using detail::CellTable;
using detail::MeshGrid;

}  // namespace

QuadtreeMesh::QuadtreeMesh(const Box<2>& box, std::span<const Point<2>> points)
    : box_(box), points_(points.begin(), points.end()), tree_(detail::locate_all(box, points)) {
  const MeshGrid grid(box);
  const auto qs = tree_.points();
  detail::check_resolution(grid, points, qs);
  validate_mesh_box(box);

  // T': T*'s split cells, then every point's seeds and what grading forces.
  CellTable<2> split(tree_.num_split() * 2);
  for (const CellId<2>& c : tree_.split_cells()) split.try_emplace(c);
  std::vector<CellId<2>> work;
  auto refine = [&](const CellId<2>& seed) {
    if (!split.try_emplace(seed).second) return;
    work.push_back(seed);
    while (!work.empty()) {
      const CellId<2> c = work.back();
      work.pop_back();
      if (c.level == 0) continue;
      for_each_coarser_touching(c, [&](const CellId<2>& u) {
        if (split.try_emplace(u).second) work.push_back(u);
      });
    }
  };
  std::vector<detail::WarpTarget> targets(qs.size());
  for (std::size_t i = 0; i < qs.size(); ++i) {
    targets[i] = detail::warp_target(grid, qs[i], points_[i], tree_.locate(qs[i]).level);
    for_each_coarser_touching(targets[i].leaf, refine);
  }
  // The marks: which leaf has which corner warped onto which point.
  struct Mark {
    unsigned corner;
    std::size_t point;
  };
  CellTable<2, Mark> marks(qs.size() * 4);
  for (std::size_t i = 0; i < qs.size(); ++i)
    detail::for_each_marked(targets[i], [&](const CellId<2>& cell, std::uint8_t v) {
      if (!marks.try_emplace(cell, Mark{detail::warped_corner(v), i}).second)
        throw InvariantError("dynmesh: leaf " + to_string(cell) + " has two warped corners");
    });

  auto is_split = [&](const CellId<2>& c) { return split.contains(c); };
  std::vector<CellId<2>> stack{CellId<2>::root()};
  while (!stack.empty()) {
    const CellId<2> c = stack.back();
    stack.pop_back();
    if (is_split(c)) {
      for (unsigned w = 4; w-- > 0;) stack.push_back(child(c, w));
      continue;
    }
    detail::LeafShape shape{c, 0, -1, {}};
    for (unsigned s = 0; s < 4; ++s) {
      CellId<2> nb;
      if (detail::side_neighbour(c, s, nb) && is_split(nb)) shape.midpoints |= static_cast<std::uint8_t>(1u << s);
    }
    std::uint32_t held = 0;
    if (const Mark* m = marks.find(c)) {
      shape.warped = static_cast<std::int8_t>(m->corner);
      shape.warp_to = points_[m->point];
      held = contains(c, qs[m->point]) ? 1 : 0;
    }
    leaves_.push_back(Leaf<2>{c, held});
    detail::triangulate_leaf(grid, shape, triangles_);
  }
  std::sort(leaves_.begin(), leaves_.end());
  std::sort(triangles_.begin(), triangles_.end());
}

void validate_mesh_box(const Box<2>& box) {
  if (MeshGrid(box).level_limit < 2)
    throw InputError(InputError::Kind::Resolution,
                     "the domain box is too small for its offset: double coordinates cannot resolve its cells");
}

void require_refined_tree(std::span<const Leaf<2>> leaves, std::size_t npoints) {
  CellTable<2> leaf_set(leaves.size());
  for (const Leaf<2>& l : leaves)
    if (!leaf_set.try_emplace(l.cell).second) throw InvariantError("dynmesh: leaf " + to_string(l.cell) + " meshed twice");
  std::size_t holding = 0;
  for (const Leaf<2>& l : leaves) {
    if (l.npoints == 0) continue;
    ++holding;
    for_each_neighbour(l.cell, [&](const CellId<2>& nb) {
      if (!leaf_set.contains(nb))
        throw InvariantError("dynmesh: point leaf " + to_string(l.cell) + " has a neighbour " + to_string(nb) +
                             " that is not a leaf of its size");
    });
  }
  if (holding != npoints) throw InvariantError("dynmesh: the refined tree lost a point leaf");
}

void QuadtreeMesh::check_invariants() const { require_refined_tree(leaves_, points_.size()); }

}  // namespace dynmesh
