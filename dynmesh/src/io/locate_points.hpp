// locate_points.hpp (private) — the static meshers' first validation of their input.
//
// Purpose: checks the box, then each point (finite, inside the box) and returns the points'
// grid positions, with InputError naming the failing point's index as DynamicMesh does;
// check_separated() then rejects what the quadtree rejects after that, without building it;
// check_resolution() what the meshes' double arithmetic cannot resolve (detail/
// quadtree_mesh_rules.hpp: points in neighbouring cells of level R, or within L/2^R of a box
// side they are not on).
// Invariants: on return, positions[i] is try_locate(box, points[i]) for every i.
// Complexity: locate_all O(n); check_separated O(n log n); check_resolution O(n) expected.
// Paper: none.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/detail/cell_table.hpp"
#include "dynmesh/detail/mesh_grid.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh::detail {

template <std::size_t d>
std::vector<Position<d>> locate_all(const Box<d>& box, std::type_identity_t<std::span<const Point<d>>> points) {
  validate_box(box);
  std::vector<Position<d>> qs(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (unsigned a = 0; a < d; ++a)
      if (!std::isfinite(points[i][a]))
        throw InputError(InputError::Kind::NotFinite, "point " + std::to_string(i) + " has a NaN or infinite coordinate")
            .with_points({i});
    const auto q = try_locate(box, points[i]);
    if (!q)
      throw InputError(InputError::Kind::OutsideBox, "point " + std::to_string(i) + " is outside the domain box")
          .with_points({i});
    qs[i] = *q;
  }
  return qs;
}

/// The quadtree's own rules on positions (static_quadtree.cpp), as errors naming the two
/// points: two equal positions are duplicates (InputError::Duplicate); two positions within
/// one grid unit per axis would need a cell below level 52 (InputError::Resolution).
inline void check_separated(std::span<const Position<2>> qs) {
  // The positions themselves sorted, with their indices (an index sort compared through qs,
  // a cache miss per comparison at 10^5 points).
  std::vector<std::pair<Position<2>, std::uint32_t>> order(qs.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = {qs[i], i};
  std::sort(order.begin(), order.end());
  const auto report = [&](std::uint32_t a, std::uint32_t b) {
    const std::size_t i = std::min(a, b), j = std::max(a, b);
    if (qs[a] == qs[b])
      throw InputError(InputError::Kind::Duplicate,
                       "points " + std::to_string(i) + " and " + std::to_string(j) + " have the same located position (duplicate point)")
          .with_points({i, j});
    throw InputError(InputError::Kind::Resolution,
                     "points " + std::to_string(i) + " and " + std::to_string(j) +
                         " are within one grid unit of each other: the spread L/s is beyond the resolution of 2^52")
        .with_points({i, j});
  };
  // Sorted by (x, y): a close pair has x' in {x, x + 1}; search each run for y' within 1.
  // The first position at or after (x + 1, y − 1) only moves forward as k does, so one
  // cursor finds it for every k.
  std::size_t at = 0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Position<2>& q = order[k].first;
    if (k + 1 < order.size() && order[k + 1].first[0] == q[0] && order[k + 1].first[1] <= q[1] + 1)
      report(order[k].second, order[k + 1].second);
    if (q[0] == UINT64_MAX) continue;
    const Position<2> from{q[0] + 1, q[1] == 0 ? 0 : q[1] - 1};
    at = std::max(at, k);
    while (at < order.size() && order[at].first < from) ++at;
    if (at < order.size() && order[at].first[0] == from[0] && order[at].first[1] <= q[1] + 1)
      report(order[k].second, order[at].second);
  }
}

/// The mesh's resolution rules (detail/quadtree_mesh_rules.hpp) over a whole point set.
template <std::size_t d>
void check_resolution(const BasicMeshGrid<d>& grid, std::type_identity_t<std::span<const Point<d>>> points,
                      std::type_identity_t<std::span<const Position<d>>> qs) {
  detail::CellTable<d, std::uint32_t> count;
  for (const auto& q : qs) ++*count.try_emplace(cell_of(q, std::max(grid.level_limit, 0)), 0u).first;
  for (std::size_t i = 0; i < qs.size(); ++i) {
    const CellId<d> own = cell_of(qs[i], std::max(grid.level_limit, 0));
    detail::check_mesh_resolution(
        grid, qs[i], points[i],
        [&](const CellId<d>& c) {
          const std::uint32_t* k = count.find(c);
          return k && *k > (c == own ? 1u : 0u);
        },
        [&](const std::string& text) {
          throw InputError(InputError::Kind::Resolution, "point " + std::to_string(i) + ": " + text).with_points({i});
        });
  }
}

}  // namespace dynmesh::detail
