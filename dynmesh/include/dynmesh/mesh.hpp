// dynmesh/mesh.hpp — 2D triangle meshes: triangles named by their corners, the canonical
// mesh of docs/FORMATS.md, and the change feed of one update.
//
// Purpose: the value types every mesher (static or self-adjusting, quadtree or off-center)
// produces and every consumer (writers, checker, tests, the command) reads.
//   Triangle   – three corners by coordinates, counter-clockwise, rotated so that the
//                corner with the smallest (x, y) comes first (docs/FORMATS.md, "`dynmesh mesh` (2D)", the feed's rule).
//                Ordered lexicographically on the six coordinates.
//   Mesh       – the canonical form: vertices sorted by (x, y) (0-based here, written from
//                1), triangles as vertex-index triples, each starting at its smallest index
//                and counter-clockwise, sorted lexicographically. Two equal meshes have equal
//                Mesh values, so files written from them compare with `cmp`.
//   MeshChange – the triangles removed and added by one update (each group sorted).
// Invariants: canonical_triangle(t) is the identity on a canonical t; make_mesh(ts) depends
// only on the set of triangles, not on their order; triangles_of(make_mesh(ts)) == sorted ts
// (for distinct ts).
// Complexity: make_mesh O(t log t); the rest O(1) per triangle.
// Paper: none (formats: docs/FORMATS.md, "`dynmesh mesh` (2D)"; Triangle's .node/.ele).
#pragma once

#include <array>
#include <compare>
#include <cstdint>
#include <span>
#include <vector>

#include "dynmesh/point.hpp"

namespace dynmesh {

struct Triangle {
  std::array<Point<2>, 3> v;  // counter-clockwise, v[0] the smallest (x, y)

  friend bool operator==(const Triangle&, const Triangle&) = default;
  friend auto operator<=>(const Triangle&, const Triangle&) = default;
};

/// (x, y) lexicographic order of points (the vertex order of a canonical mesh).
inline bool xy_less(const Point<2>& a, const Point<2>& b) noexcept {
  return a[0] < b[0] || (a[0] == b[0] && a[1] < b[1]);
}

/// The triangle a, b, c (already counter-clockwise) rotated to start at its smallest corner.
inline Triangle canonical_triangle(const Point<2>& a, const Point<2>& b, const Point<2>& c) noexcept {
  const Point<2>& low = xy_less(b, a) ? b : a;
  if (xy_less(c, low)) return Triangle{{c, a, b}};
  if (&low == &b) return Triangle{{b, c, a}};
  return Triangle{{a, b, c}};
}

struct Mesh {
  std::vector<Point<2>> vertices;                    // sorted by (x, y), distinct
  std::vector<std::array<std::uint32_t, 3>> triangles;  // canonical, sorted

  friend bool operator==(const Mesh&, const Mesh&) = default;
  std::size_t num_vertices() const noexcept { return vertices.size(); }
  std::size_t num_triangles() const noexcept { return triangles.size(); }
  Triangle triangle(std::size_t i) const noexcept {
    const auto& t = triangles[i];
    return Triangle{{vertices[t[0]], vertices[t[1]], vertices[t[2]]}};
  }
};

/// The canonical mesh of a set of counter-clockwise triangles (any rotation, any order).
/// Duplicate triangles are kept (the checker reports them).
Mesh make_mesh(std::span<const Triangle> triangles);

/// The triangles of a mesh, canonical, in the mesh's (sorted) order.
std::vector<Triangle> triangles_of(const Mesh& mesh);

/// One update's change: remove `removed` from the mesh before it and add `added` to get the
/// mesh after it. Both sorted, canonical triangles, and disjoint.
struct MeshChange {
  std::vector<Triangle> removed;
  std::vector<Triangle> added;
  friend bool operator==(const MeshChange&, const MeshChange&) = default;
};

/// Applies a change to a sorted triangle list; returns false (and leaves `tris` unspecified)
/// when a removed triangle is absent or an added one is already present.
bool apply_change(std::vector<Triangle>& tris, const MeshChange& change);

}  // namespace dynmesh
