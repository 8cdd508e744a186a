// dynmesh/tools/postprocess_option.hpp — the `--postprocess` and `--min-angle` options of
// `dynmesh mesh` and `dynmesh stability` (docs/FORMATS.md), checked in one place, and the
// options of the 2D mesh alone that `dynmesh mesh` refuses in 3D.
//
// Purpose: both commands name a postprocess and may ask for an angle bound; the names, the
// defaults and the bound each postprocess guarantees are stated once here so the two
// commands cannot drift apart.
// Invariants: check_postprocess either returns a choice whose bound is >= the requested
// angle, or throws InputError (Malformed) before any file is read.
// Complexity: O(1).
// Paper: Acar & Hudson, Section 5 (the postprocesses); Bern, Eppstein & Gilbert (the
// quadtree mesh's arctan(1/3) bound).
#pragma once

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "dynmesh/errors.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/octree_mesh.hpp"
#include "dynmesh/quadtree_mesh.hpp"

namespace dynmesh::tool {

enum class PostprocessChoice { None, Quadtree, Hpu };

inline std::string angle_text(double deg) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", deg);
  return buf;
}

/// `name` is the option's value ("" is the command's default: `hpu` for mesh, `none` for
/// stability, as `allow_none` says); `min_angle` is --min-angle when given.
inline PostprocessChoice check_postprocess(const std::string& name, bool allow_none,
                                           std::optional<double> min_angle) {
  using Kind = InputError::Kind;
  const std::string value = name.empty() ? (allow_none ? "none" : "hpu") : name;
  const std::string known = allow_none ? "none, quadtree or hpu" : "hpu or quadtree";
  PostprocessChoice choice;
  if (value == "hpu") {
    choice = PostprocessChoice::Hpu;
  } else if (value == "quadtree") {
    choice = PostprocessChoice::Quadtree;
  } else if (value == "none" && allow_none) {
    choice = PostprocessChoice::None;
  } else {
    throw InputError(Kind::Malformed, "unknown --postprocess '" + value + "' (" + known + ")");
  }
  if (min_angle) {
    if (choice == PostprocessChoice::None)
      throw InputError(Kind::Malformed, "--min-angle needs a mesh: pass --postprocess hpu or quadtree");
    if (choice == PostprocessChoice::Hpu) {
      if (!(*min_angle >= kHpuMinAngleLow && *min_angle <= kHpuMinAngleHigh))
        throw InputError(Kind::Malformed, "--min-angle for hpu must be between " + angle_text(kHpuMinAngleLow) +
                                              " and " + angle_text(kHpuMinAngleHigh) + " degrees, got " +
                                              angle_text(*min_angle));
      return choice;
    }
    if (!std::isfinite(*min_angle) || *min_angle < 0)
      throw InputError(Kind::Malformed, "--min-angle must be a finite angle of at least 0 degrees");
    if (*min_angle > kQuadtreeMinAngle)
      throw InputError(Kind::Malformed, "--min-angle " + angle_text(*min_angle) +
                                            " is above the quadtree mesh's bound of " +
                                            angle_text(kQuadtreeMinAngle) + " degrees");
  }
  return choice;
}

/// Why `dynmesh mesh` cannot take these options for 3D points (empty: it can): the 3D mesh
/// is the octree's (`quadtree`, the 3D default), whose angle bounds are fixed, and there is
/// no 3D picture. `postprocess` and `min_angle_given` as for check_postprocess; `svg`: --svg
/// was given.
inline std::string mesh_options_2d_only(const std::string& postprocess, bool min_angle_given, bool svg) {
  if (postprocess == "hpu")
    return "--postprocess hpu is 2D only; the 3D mesh is the octree's (--postprocess quadtree)";
  if (min_angle_given)
    return "--min-angle is 2D only; the 3D mesh is the octree's, whose dihedral angles lie between " +
           angle_text(kOctreeMinDihedral) + " and " + angle_text(kOctreeMaxDihedral) + " degrees";
  if (svg) return "--svg draws 2D meshes only; for a 3D mesh, write --vtk or --msh and view it in ParaView or Gmsh";
  return {};
}

/// check_postprocess at parse time: a bad value is CLI11's ValidationError, so that the
/// command exits with status 2 (a malformed command line) before reading anything.
inline void check_postprocess_option(const std::string& name, bool allow_none, const CLI::Option* min_angle_opt,
                                     double min_angle) {
  try {
    (void)check_postprocess(name, allow_none,
                            min_angle_opt && min_angle_opt->count() > 0 ? std::optional<double>(min_angle)
                                                                         : std::nullopt);
  } catch (const InputError& e) {
    throw CLI::ValidationError(e.text());
  }
}

}  // namespace dynmesh::tool
