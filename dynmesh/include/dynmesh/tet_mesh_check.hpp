// dynmesh/tet_mesh_check.hpp — the checker of the 3D (tetrahedral) mesh contract.
//
// Purpose: decides whether a TetMesh meshes a domain box for an input point set as
// docs/FORMATS.md, "`dynmesh mesh` in 3D", states (the eight corners and every input point are
// vertices, positively oriented tetrahedra tile the box with no hanging vertex, canonical
// order), and says what is wrong when it does not. Every 3D mesher's tests run it, and a
// caller may run it after every update (require_valid_tet_mesh throws). The 3D counterpart
// of mesh_check.hpp. The closed domain is B = [o1, fl(o1+L)] x [o2, fl(o2+L)] x [o3, fl(o3+L)].
//
// What is checked, each reported as its own TetMeshDefect:
//   Canonical      vertices strictly sorted by xyz_less; each tetrahedron in the canonical
//                  rotation of tet_mesh.hpp; tetrahedra sorted (equal neighbours are left to
//                  FaceTwice).
//   BadIndex       a tetrahedron names a vertex that does not exist, or one vertex twice.
//   Orientation    a tetrahedron is not positively oriented (exact orient3d > 0).
//   OutsideBox     a vertex lies outside the closed box B.
//   IsolatedVertex a vertex belongs to no tetrahedron (it would sit unseen inside one).
//   MissingCorner  a corner of B is not a vertex.
//   FaceTwice      an oriented face is used by two tetrahedra (overlap or duplicate).
//   OpenFace       a face used in one orientation only does not lie in a face plane of B
//                  (its three vertices on one plane x == o1, x == fl(o1+L), y == ..., z ==
//                  ...): a hole, or a vertex hanging in a face or an edge of a neighbour.
//   Volume         the tetrahedra's total volume differs from the box's by more than 1e-9
//                  relative: a cheap cross-check in double, not the main test.
//   MissingInput   an input point is not a vertex.
//   SmallDihedral  a tetrahedron has a dihedral angle below TetMeshCheckOptions::min_dihedral_deg.
//   LargeDihedral  a tetrahedron has a dihedral angle above TetMeshCheckOptions::max_dihedral_deg.
// A face of a positively oriented tetrahedron is oriented with its normal pointing inside,
// so a face shared by two tetrahedra on its two sides appears once in each orientation.
// Orientation, exactly matched faces and lone faces on the box's planes make the tetrahedra
// cover B a whole number of times, and the volume makes it once. Faces are matched by vertex
// indices, exactly: a vertex hanging inside a neighbour's face or edge leaves faces inside
// the box that do not match, which OpenFace reports; one hanging inside a face on the box's
// boundary would make the tetrahedra there cover B twice, which the volume reports. So the
// contract needs no vertex-in-face search (2D states its VertexInEdge directly).
//
// Invariants: the report depends only on the arguments; problems lists at most
// max_problems messages (in check order) and counts every defect found.
// Complexity: O((t + p) log(t + n)) for t tetrahedra, n vertices and p input points: the 4t
// oriented faces are sorted once, and corners and inputs are found by binary search.
// Paper: none (the contract is docs/FORMATS.md, "`dynmesh mesh` in 3D"; orient3d is Shewchuk's via CGAL).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/tet_mesh.hpp"

namespace dynmesh {

enum class TetMeshDefect : std::uint8_t {
  Canonical,
  BadIndex,
  Orientation,
  OutsideBox,
  IsolatedVertex,
  MissingCorner,
  FaceTwice,
  OpenFace,
  Volume,
  MissingInput,
  SmallDihedral,
  LargeDihedral,
};
inline constexpr std::size_t kTetMeshDefectKinds = 12;

/// A short lower-case name ("orientation", "open-face", ...), the prefix of messages.
std::string_view defect_name(TetMeshDefect defect) noexcept;

struct TetMeshCheckOptions {
  double min_dihedral_deg = 0;    // every dihedral angle must be >= this (0: no bound)
  double max_dihedral_deg = 180;  // and <= this (180: no bound)
  std::size_t max_problems = 32;  // messages kept in the report (all are counted)
};

struct TetMeshReport {
  std::vector<std::string> problems;                      // "<defect name>: <details>", at most max_problems
  bool truncated = false;                                 // more defects were found than problems lists
  std::array<std::size_t, kTetMeshDefectKinds> counts{};  // defects found, per kind, all of them
  double min_dihedral_deg = 0;                            // over all well-formed tetrahedra (0 when none)
  double max_dihedral_deg = 0;

  bool ok() const noexcept;
  bool has(TetMeshDefect defect) const noexcept { return counts[static_cast<std::size_t>(defect)] != 0; }
  /// One line when ok ("tetrahedral mesh ok: ..."), otherwise a count per kind and the
  /// problems, one a line.
  std::string summary() const;
};

/// The six dihedral angles of the tetrahedron, in degrees in [0, 180], at its edges v0v1,
/// v0v2, v0v3, v1v2, v1v3, v2v3 in that order: the one definition the checker's bounds and
/// the quality statistics (tet_mesh_io.hpp) share. Computed in double in a frame scaled by a
/// power of two (no overflow or underflow at any box size), as
/// atan2(|det(e, u, w)|·|e|, (e × u)·(e × w)) for the edge e and the other two corners u, w
/// seen from its start: accurate near 0 and 180 degrees, where acos is not. A degenerate
/// tetrahedron's angles are 0 or 180 (0 at an edge of zero length).
std::array<double, 6> dihedral_angles_deg(const Tetrahedron& tet) noexcept;

/// The circumradius over the shortest edge (sqrt(6)/4 ≈ 0.612 for the regular tetrahedron,
/// its minimum); +infinity for a degenerate (coplanar) tetrahedron. Scale-free, computed in
/// the same frame as the dihedral angles.
double radius_edge_ratio(const Tetrahedron& tet) noexcept;

/// Checks `mesh` against the contract for the domain `box` and the input points `inputs`.
/// Never throws on a bad mesh (only std::bad_alloc).
TetMeshReport check_tet_mesh(const TetMesh& mesh, const Box<3>& box, std::span<const Point<3>> inputs,
                             const TetMeshCheckOptions& options = {});

/// check_tet_mesh, throwing InvariantError with the report's summary (the first
/// options.max_problems problems) unless it is ok.
void require_valid_tet_mesh(const TetMesh& mesh, const Box<3>& box, std::span<const Point<3>> inputs,
                            const TetMeshCheckOptions& options = {});

}  // namespace dynmesh
