// dynmesh/edit.hpp — one point insertion or deletion, as the dynamic structures take it.
//
// Purpose: the unit of change of DynamicQuadtree::apply and DynamicMesh::apply. An edit
// names its point by coordinates; where it came from (a script line) is the caller's
// business: a failing batch reports the index of the failing edit in
// InputError::point_indices(), and the command maps that index to a line.
// Invariants: none beyond the point being what the caller passed.
// Complexity: value type.
// Paper: none.
#pragma once

#include <cstddef>

#include "dynmesh/point.hpp"

namespace dynmesh {

enum class EditOp { Insert, Delete };

template <std::size_t d>
  requires SupportedDim<d>
struct Edit {
  EditOp op;
  Point<d> point;
  friend bool operator==(const Edit&, const Edit&) = default;
};

}  // namespace dynmesh
