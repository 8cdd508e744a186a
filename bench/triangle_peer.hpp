// triangle_peer.hpp — Shewchuk's Triangle as a peer of the hpu mesh, timed on the same points
// in the same process, for the benches' "against Triangle" figures.
//
// Purpose: the static twin's time and size against Triangle's, measured in the same run. Triangle's licence forbids bundling it, so the project never ships it: a user
// who has its source points the build at it (-DDYNMESH_TRIANGLE_SOURCE=/path/triangle.c, with
// triangle.h beside it; bench/CMakeLists.txt) and the benches then call it. Without it,
// kHaveTriangle is false and the benches print quoted peer figures instead.
// The mesh asked of Triangle is the twin's problem: the points and the box's corners, the
// box's four sides as segments (a .poly), minimum angle `min_angle_deg` (switches -pzq<angle>,
// quiet, no output segments or markers).
// Invariants: the result counts every vertex of Triangle's mesh (inputs, corners, Steiner
// points) and its triangles. Triangle exits the process on an error of its own.
// Complexity: Triangle's, O(n log n) expected for the Delaunay stage plus the refinement.
#pragma once

#include <cstddef>
#include <span>

#include "dynmesh/box.hpp"
#include "dynmesh/point.hpp"

namespace bench {

struct TriangleMeshSize {
  std::size_t vertices = 0;
  std::size_t triangles = 0;
};

/// Is Triangle linked into this build (DYNMESH_TRIANGLE_SOURCE)?
extern const bool kHaveTriangle;

/// Triangle's quality mesh of the points in the box (see the header); throws std::logic_error
/// when the build has no Triangle.
TriangleMeshSize triangle_quality_mesh(const dynmesh::Box<2>& box, std::span<const dynmesh::Point<2>> points,
                                       double min_angle_deg);

}  // namespace bench
