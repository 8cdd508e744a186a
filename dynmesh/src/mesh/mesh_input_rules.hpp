// mesh_input_rules.hpp (private) — the meshes' own input rule (mesh_grid.hpp's resolution
// rule) over the present points and a batch of edits, in 2D and 3D.
//
// Purpose: the quadtree's validate() (quadtree_core.hpp) checks its own rules and calls an
// extra checker's insert/erase in batch order; MeshChecks is that checker for the meshes, on
// the counts of present points per cell of the mesh's resolution level, which the mesher
// keeps up to date with count_edits() after each committed update.
// Invariants: counts holds exactly the present points per level-R cell, no zero entries.
// Complexity: O(3^d) hash probes per edit.
// Paper: none.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <unordered_map>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/detail/mesh_grid.hpp"
#include "dynmesh/edit.hpp"

namespace dynmesh::detail {

/// Points per cell of the mesh's resolution level.
template <std::size_t d>
using CellCounts = std::unordered_map<CellId<d>, std::int64_t, CellHash>;

/// The batch's changes to the counts live in `delta`.
template <std::size_t d>
struct MeshChecks {
  const BasicMeshGrid<d>& grid;
  const CellCounts<d>& counts;
  CellCounts<d> delta{};

  int level() const { return std::max(grid.level_limit, 0); }
  std::int64_t count(const CellId<d>& c) const {
    std::int64_t k = 0;
    if (auto it = counts.find(c); it != counts.end()) k += it->second;
    if (auto it = delta.find(c); it != delta.end()) k += it->second;
    return k;
  }
  template <class Fail>
  void insert(const Position<d>& q, const Point<d>& p, Fail&& fail) {
    check_mesh_resolution(grid, q, p, [&](const CellId<d>& c) { return count(c) > 0; }, fail);
    ++delta[cell_of(q, level())];
  }
  void erase(const Position<d>& q) { --delta[cell_of(q, level())]; }
};

/// Applies committed edits to the counts.
template <std::size_t d>
void count_edits(const BasicMeshGrid<d>& grid, const Box<d>& box, std::span<const Edit<d>> edits, CellCounts<d>& counts) {
  const int level = std::max(grid.level_limit, 0);
  for (const Edit<d>& e : edits) {
    const CellId<d> c = cell_of(*try_locate(box, e.point), level);
    auto& k = counts[c];
    k += e.op == EditOp::Insert ? 1 : -1;
    if (k == 0) counts.erase(c);
  }
}

}  // namespace dynmesh::detail
