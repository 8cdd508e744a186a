// locate_points.hpp (private) — the static meshers' first validation of their input.
//
// Purpose: checks the box, then each point (finite, inside the box) and returns the points'
// grid positions, with InputError naming the failing point's index as DynamicMesh does.
// Invariants: on return, positions[i] is try_locate(box, points[i]) for every i.
// Complexity: O(n).
// Paper: none.
#pragma once

#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh::detail {

inline std::vector<Position<2>> locate_all(const Box<2>& box, std::span<const Point<2>> points) {
  validate_box(box);
  std::vector<Position<2>> qs(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (unsigned a = 0; a < 2; ++a)
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

}  // namespace dynmesh::detail
