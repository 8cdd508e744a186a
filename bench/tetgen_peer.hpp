// tetgen_peer.hpp — Si's TetGen as a peer of the octree mesh, run on the same points in the
// same box, for dynmesh_mesh_bench --dim 3.
//
// Purpose: the 3D counterpart of triangle_peer.hpp. TetGen's licence (AGPL) keeps it out of
// the build, so the bench runs the installed program (Debian's `tetgen` 1.5, which
// `bash dev.sh deps` installs) as a separate process: it writes the problem as a .poly file
// into a fresh temporary directory, runs `tetgen -pqFV` on it and reads the .node/.ele it
// wrote back. The problem is the octree mesh's: the box as a piecewise linear complex (its
// 8 corners and 6 square facets) with the input points as extra nodes inside it; TetGen 1.5
// keeps such isolated nodes as vertices of its mesh (the result's vertices count them, and
// the bench checks vertices >= n + 8). Switches: p, a PLC; q, quality with TetGen's default
// bounds (radius-edge ratio 2, no dihedral bound, then its optimization pass); F, no .face or
// .edge output; V, the stage times, whose "Total running seconds" is the time reported (it
// starts after the input was read and includes writing the .node/.ele).
// Invariants: a failure of any kind (no program, a non-zero exit, unreadable output) is
// reported in `note` with ran == false, never thrown; the temporary directory is removed.
// Complexity: TetGen's, O(n log n) expected for the Delaunay stage plus the refinement; the
// files cost O(n + t) to write and read.
#pragma once

#include <cstddef>
#include <span>
#include <string>

#include "dynmesh/box.hpp"
#include "dynmesh/point.hpp"

namespace bench {

struct TetgenResult {
  bool ran = false;         // false: the other fields are unset and `note` says why
  double seconds = 0;       // TetGen's own "Total running seconds", else the process's wall time
  bool own_time = false;    // seconds is TetGen's own figure
  double wall_seconds = 0;  // the process's wall time (reading the .poly, writing the output)
  std::size_t vertices = 0;
  std::size_t tetrahedra = 0;
  double min_dihedral = 0;  // degrees, over all its tetrahedra (dihedral_angles_deg)
  double max_dihedral = 0;
  std::string note;
};

/// The `tetgen` program on PATH, or empty when there is none.
std::string find_tetgen();

/// TetGen's quality mesh of `points` in `box` (see the header), by the program `tetgen`.
TetgenResult tetgen_quality_mesh(const std::string& tetgen, const dynmesh::Box<3>& box,
                                 std::span<const dynmesh::Point<3>> points);

}  // namespace bench
