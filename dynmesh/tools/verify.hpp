// dynmesh/tools/verify.hpp — checking a dynamic tree against a from-scratch static build.
//
// Purpose: `quadtree --check`, `stability` and `demo` verify the dynamic tree after its updates:
//   1. the static oracle StaticQuadtree::from_points on the tree's final points, in the
//      same box, must give the same `.cells` text (format_cells, byte for byte);
//   2. check_tree on the dynamic leaves and the located points must pass
//      (require_valid_tree: tiling, occupancy, separation, grading, crowding, minimality);
//   3. the tree's own check_invariants() (engine, indexes, directory) must pass.
// The meshes likewise: verify(DynamicMesh) for the 2D meshes, verify(DynamicOctreeMesh) for
// the 3D one (`mesh --check` and `stability --postprocess quadtree` in 3D).
// The first failure is reported as one line (multi-line checker summaries are folded).
// Invariants: verify() does not modify the tree.
// Complexity: one static build and one check_tree on the final points, plus
// check_invariants(): O(n lg n + |T*| lg |T*|) expected, plus the size of the trace.
// Paper: none; docs/DESIGN.md, "The correctness contract" (after propagate(), outputs equal a from-scratch
// run on the current input).
#pragma once

#include <chrono>
#include <cstddef>
#include <exception>
#include <string>
#include <vector>

#include <sac/errors.hpp>

#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/dynamic_octree_mesh.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/io.hpp"
#include "dynmesh/mesh_check.hpp"
#include "dynmesh/octree_mesh.hpp"
#include "dynmesh/quadtree_mesh.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace dynmesh::tool {

/// The message folded onto one line ("a\nb" -> "a; b"), trailing newlines dropped, and every
/// other control byte escaped as \xNN (escape_control_bytes): a message that quotes binary
/// junk or a strange file name cannot drive the terminal.
inline std::string one_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    if (c == '\n')
      out += "; ";
    else if (c != '\r')
      out += c;
  }
  return escape_control_bytes(out);
}

struct Verification {
  bool ok = false;
  std::string problem;          // why not, one line (empty when ok)
  double static_seconds = 0.0;  // time of the static from-scratch build
};

/// Runs `check` (invariant checkers); false, with the one-line reason in v.problem, when one
/// of the library's or the runtime's checkers throws.
template <class Check>
bool invariants_hold(Verification& v, Check&& check) {
  try {
    check();
  } catch (const dynmesh::InvariantError& e) {
    v.problem = "invariant check failed: " + one_line(e.what());
    return false;
  } catch (const sac::InvariantError& e) {
    v.problem = "runtime invariant check failed: " + one_line(e.what());
    return false;
  }
  return true;
}

template <std::size_t d>
Verification verify(const DynamicQuadtree<d>& tree) {
  Verification v;
  const std::vector<Leaf<d>> leaves = tree.leaves();
  std::vector<Point<d>> pts;
  for (const auto& entry : tree.points()) pts.push_back(entry.second);

  const auto t0 = std::chrono::steady_clock::now();
  const StaticQuadtree<d> oracle = StaticQuadtree<d>::from_points(tree.box(), pts);
  v.static_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const std::string dynamic_text = format_cells<d>(tree.box(), leaves);
  const std::string static_text = format_cells<d>(tree.box(), oracle.leaves());
  if (dynamic_text != static_text) {
    // Name the first differing line of the two `.cells` texts.
    std::size_t line = 1, pos = 0;
    while (pos < dynamic_text.size() && pos < static_text.size() && dynamic_text[pos] == static_text[pos]) {
      if (dynamic_text[pos] == '\n') ++line;
      ++pos;
    }
    auto line_at = [](const std::string& text, std::size_t at) {
      const std::size_t begin = text.rfind('\n', at == 0 ? 0 : at - 1);
      const std::size_t from = begin == std::string::npos || at == 0 ? 0 : begin + 1;
      const std::size_t end = text.find('\n', from);
      return end == std::string::npos ? text.substr(from) : text.substr(from, end - from);
    };
    v.problem = "the dynamic tree differs from a from-scratch build on the final " + std::to_string(pts.size()) +
                " points (" + std::to_string(leaves.size()) + " vs " + std::to_string(oracle.leaves().size()) +
                " leaves; first difference at .cells line " + std::to_string(line) + ": '" +
                line_at(dynamic_text, pos) + "' vs '" + line_at(static_text, pos) + "')";
    return v;
  }
  if (!invariants_hold(v, [&] {
        require_valid_tree<d>(tree.positions(), leaves);
        tree.check_invariants();
      }))
    return v;
  v.ok = true;
  return v;
}

/// The mesh's counterpart, for `mesh --check` and `stability --postprocess`: the engine's
/// and the mesh's invariants, check_mesh with `min_angle_deg` on the final mesh (hpu:
/// Delaunay too), then the static twin (HpuMesh or QuadtreeMesh) on the final points must
/// give the same canonical mesh; static_seconds is the twin's time.
inline Verification verify(const DynamicMesh& dynamic, double min_angle_deg) {
  Verification v;
  std::vector<Point<2>> pts;
  for (const auto& entry : dynamic.points()) pts.push_back(entry.second);
  const Mesh mesh = dynamic.mesh();
  if (!invariants_hold(v, [&] { dynamic.check_invariants(); })) return v;
  const bool hpu = dynamic.options().postprocess == Postprocess::Hpu;
  MeshCheckOptions check_options;
  check_options.min_angle_deg = min_angle_deg;
  check_options.delaunay = hpu;
  const MeshReport report = check_mesh(mesh, dynamic.box(), pts, check_options);
  if (!report.ok()) {
    v.problem = "mesh check failed: " + one_line(report.summary());
    return v;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const Mesh fresh = hpu ? HpuMesh(dynamic.box(), pts, dynamic.options().min_angle).mesh() : QuadtreeMesh(dynamic.box(), pts).mesh();
  v.static_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (fresh != mesh) {
    v.problem = "the dynamic mesh differs from a from-scratch mesh of the final " + std::to_string(pts.size()) +
                " points (" + std::to_string(mesh.num_triangles()) + " vs " + std::to_string(fresh.num_triangles()) +
                " triangles)";
    return v;
  }
  v.ok = true;
  return v;
}

/// The 3D counterpart: the engine's and the mesh's invariants (DynamicOctreeMesh's checker
/// includes require_valid_tet_mesh with the proved dihedral bounds), then the static twin
/// OctreeMesh on the final points must give the same canonical mesh (hence the same `.node`
/// and `.ele`); static_seconds is its time.
inline Verification verify(const DynamicOctreeMesh& dynamic) {
  Verification v;
  std::vector<Point<3>> pts;
  for (const auto& entry : dynamic.points()) pts.push_back(entry.second);
  if (!invariants_hold(v, [&] { dynamic.check_invariants(); })) return v;
  const TetMesh mesh = dynamic.mesh();
  const auto t0 = std::chrono::steady_clock::now();
  const TetMesh fresh = OctreeMesh(dynamic.box(), pts).mesh();
  v.static_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (fresh != mesh) {
    v.problem = "the dynamic mesh differs from a from-scratch mesh of the final " + std::to_string(pts.size()) +
                " points (" + std::to_string(mesh.num_tetrahedra()) + " vs " +
                std::to_string(fresh.num_tetrahedra()) + " tetrahedra)";
    return v;
  }
  v.ok = true;
  return v;
}

}  // namespace dynmesh::tool
