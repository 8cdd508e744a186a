// dynmesh/mesh_check.hpp — the checker of the 2D mesh contract.
//
// Purpose: decides whether a Mesh satisfies docs/DESIGN.md, "The mesh contract (2D)" for a domain
// box and an input point set, and says what is wrong when it does not. Every mesher's tests
// run it, and a caller may run it after every update (require_valid_mesh throws).
// The closed domain is B = [o1, fl(o1+L)] x [o2, fl(o2+L)] (fl: the IEEE double sum).
//
// What is checked, each reported as its own MeshDefect:
//   Canonical      vertices strictly sorted by (x, y); each triangle starts at its smallest
//                  index; triangles sorted (equal neighbours are left to EdgeTwice).
//   BadIndex       a triangle names a vertex that does not exist, or one vertex twice.
//   Orientation    a triangle is not strictly counter-clockwise (exact orient2d > 0).
//   OutsideBox     a vertex lies outside the closed box B.
//   IsolatedVertex a vertex belongs to no triangle (it would sit unseen inside one).
//   MissingCorner  a corner of B is not a vertex.
//   EdgeTwice      a directed edge is used by two triangles (overlap or duplicate).
//   OpenEdge       an edge used once does not lie on a side of B (both ends on the same
//                  side line x == o1, x == fl(o1+L), y == o2 or y == fl(o2+L)): a hole or a
//                  T-junction.
//   VertexInEdge   a vertex is collinear with an edge and strictly between its ends (exact).
//   Area           the triangles' total area differs from the box's by more than 1e-9
//                  relative: a cheap cross-check in double, not the main test.
//   MissingInput   an input point is not a vertex.
//   SmallAngle     a triangle has an angle below MeshCheckOptions::min_angle_deg.
//   NotDelaunay    (with MeshCheckOptions::delaunay) the vertex opposite an interior edge is
//                  strictly inside the circumcircle of the triangle across it (exact
//                  incircle). Locally Delaunay everywhere implies globally Delaunay.
// Orientation, matched edges and lone edges on the sides make the triangles cover B a whole
// number of times, and the area makes it once; VertexInEdge states "no vertex inside an
// edge" directly, as the contract does.
//
// Invariants: the report depends only on the arguments; problems lists at most
// max_problems messages (in check order), counts every defect found.
// Complexity: O((t + p) log t) for t triangles and p input points. VertexInEdge sorts the
// vertices along a Z-order curve; the vertices in an edge's bounding box lie in one run of
// that order, scanned when short and otherwise searched in a bounding-volume tree pruned by
// the edge's box and line: O(log t) per edge for graded meshes.
// Paper: none (the contract: docs/DESIGN.md, "The mesh contract (2D)"; the exact predicates are Shewchuk's via CGAL).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh {

enum class MeshDefect : std::uint8_t {
  Canonical,
  BadIndex,
  Orientation,
  OutsideBox,
  IsolatedVertex,
  MissingCorner,
  EdgeTwice,
  OpenEdge,
  VertexInEdge,
  Area,
  MissingInput,
  SmallAngle,
  NotDelaunay,
};
inline constexpr std::size_t kMeshDefectKinds = 13;

/// A short lower-case name ("orientation", "vertex-in-edge", ...), the prefix of messages.
std::string_view defect_name(MeshDefect defect) noexcept;

struct MeshCheckOptions {
  double min_angle_deg = 0;  // every angle must be >= this (0: no bound)
  bool delaunay = false;     // also require the Delaunay property
};

struct MeshReport {
  std::vector<std::string> problems;                   // "<defect name>: <details>", at most max_problems
  bool truncated = false;                              // more defects were found than problems lists
  std::array<std::size_t, kMeshDefectKinds> counts{};  // defects found, per kind, all of them
  double min_angle_deg = 0;                            // over all well-formed triangles (0 when none)
  double max_angle_deg = 0;

  bool ok() const noexcept;
  bool has(MeshDefect defect) const noexcept { return counts[static_cast<std::size_t>(defect)] != 0; }
  /// One line when ok ("mesh ok: ..."), otherwise a count per kind and the problems, one a line.
  std::string summary() const;
};

/// The angle at corner `at` of the triangle (at, p, q), in degrees in [0, 180]: the one
/// definition the checker's bound and the quality statistics (mesh_io.hpp) share. Computed
/// in double as atan2(|cross|, dot), accurate near 0 and 180 degrees where acos is not.
double corner_angle_deg(const Point<2>& at, const Point<2>& p, const Point<2>& q) noexcept;

/// Checks `mesh` against the contract for the domain `box` and the input points `inputs`.
/// Never throws on a bad mesh (only std::bad_alloc).
MeshReport check_mesh(const Mesh& mesh, const Box<2>& box, std::span<const Point<2>> inputs,
                      const MeshCheckOptions& options = {}, std::size_t max_problems = 32);

/// check_mesh, throwing InvariantError with the report's summary unless it is ok.
void require_valid_mesh(const Mesh& mesh, const Box<2>& box, std::span<const Point<2>> inputs,
                        const MeshCheckOptions& options = {}, std::size_t max_problems = 32);

}  // namespace dynmesh
