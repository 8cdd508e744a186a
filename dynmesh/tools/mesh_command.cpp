// `dynmesh mesh`: mesh a point file in its box, apply an edit script dynamically, write the
// final mesh as .node/.ele (and optionally the change feed, VTK, MSH, and in 2D SVG):
// docs/FORMATS.md, "`dynmesh mesh` (2D)" and "`dynmesh mesh` in 3D". The dimension is the points'
// (--dim, a .node header, or the count of numbers on the first line of plain text:
// initial_points.hpp points_shape).
// 2D: `--postprocess hpu` (the default) is DynHPU's off-center Delaunay mesh: without --edits,
// its static twin HpuMesh (no trace: a fraction of the memory); with --edits, the
// self-adjusting DynamicMesh, whose output is the same bytes as a from-scratch run on the
// final points. `--postprocess quadtree` is the self-adjusting quadtree mesh (DynamicMesh).
// 3D: the octree's tetrahedral mesh (DynamicOctreeMesh; `quadtree`, the only 3D postprocess);
// --postprocess hpu, --min-angle and --svg are malformed command lines there (exit status 2).
// The self-adjusting meshes of both dimensions run through one template (run_dynamic): read,
// build, apply the edits (edit_runner.hpp), --check, write.
// Every error names the file and line it comes from, as `dynmesh quadtree` does; every output
// is written aside and renamed into place only after all of them were written
// (atomic_file.hpp), so a failed run leaves old files untouched. The change feed grows with
// the session, not with the mesh: it streams to its temporary as the edits propagate, so a
// long session's feed never has to fit in memory. Before anything is read, the
// memory guard (memory_guard.hpp) refuses a mesh that cannot fit in memory, unless --force;
// the long phases (reading, building, --check) show their elapsed time on stderr
// (progress.hpp). With --edits, --stats also reports the propagations (count, time, trace
// distance, triangles or tetrahedra changed: propagation_log.hpp).
// Complexity: construction O(n lg n + |T'|) expected, then O(lg L/s) expected trace distance
// per edit (DynamicMesh, DynamicOctreeMesh); hpu O(n lg n + m) expected for m vertices; the
// outputs are linear in the mesh (the SVG O(t log t)), the feed linear in the changes it lists
// and written as they come (memory O(1) for it beyond the largest single update); --check adds
// a from-scratch mesh and the mesh checker, O((t + n) log t).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "edit_runner.hpp"
#include "initial_points.hpp"
#include "input_labels.hpp"
#include "postprocess_option.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/detail/mesh_grid.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/dynamic_octree_mesh.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/io.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/mesh_check.hpp"
#include "dynmesh/mesh_io.hpp"
#include "dynmesh/quadtree_mesh.hpp"
#include "dynmesh/svg.hpp"
#include "dynmesh/tet_mesh.hpp"
#include "dynmesh/tet_mesh_io.hpp"
#include "memory_guard.hpp"
#include "progress.hpp"
#include "propagation_log.hpp"
#include "verify.hpp"

namespace dynmesh::tool {
namespace {

using Kind = InputError::Kind;

/// The angle bound of a 2D mesh: --min-angle, else the postprocess's own.
double angle_bound(const MeshCommandOptions& o, bool hpu) {
  return o.min_angle_given ? o.min_angle : hpu ? kHpuDefaultMinAngle : kQuadtreeMinAngle;
}

/// The options checked against the points' dimension, before any file is read as points: in
/// 3D, those of the 2D mesh alone are a malformed command line (CommandLineError, exit
/// status 2); in 2D, --postprocess and --min-angle as check_postprocess takes them. Returns
/// whether the 2D mesh is hpu's.
bool check_mesh_options(const MeshCommandOptions& o, int dim) {
  if (dim == 3) {
    const std::string why = mesh_options_2d_only(o.postprocess, o.min_angle_given, !o.svg.empty());
    if (!why.empty()) throw CommandLineError(why);
    if (!o.postprocess.empty() && o.postprocess != "quadtree")
      throw CommandLineError("unknown --postprocess '" + o.postprocess + "' (quadtree, the 3D default)");
    return false;
  }
  return check_postprocess(o.postprocess, /*allow_none=*/false,
                           o.min_angle_given ? std::optional<double>(o.min_angle) : std::nullopt) ==
         PostprocessChoice::Hpu;
}

/// The memory guard (memory_guard.hpp) for the mesh `dynmesh mesh` builds in `dim`.
void guard_mesh_memory(const MeshCommandOptions& o, int dim) {
  if (o.force) return;
  const bool hpu = dim == 2 && check_mesh_options(o, dim);
  const double bound = angle_bound(o, hpu);
  const MemoryCost cost = dim == 3          ? kOctreeMeshCost
                          : !hpu            ? kQuadtreeMeshCost
                          : o.edits.empty() ? hpu_mesh_cost(bound)
                                            : hpu_dynamic_cost(bound);
  const std::uint64_t points = points_held(o.points, o.edits);
  guard_memory(std::string("building the ") + (dim == 3 ? "octree mesh" : hpu ? "hpu mesh" : "quadtree mesh") +
                   " of " + std::to_string(points) + " points" + (o.check ? " with --check" : ""),
               estimated_bytes(cost, points, o.check));
}

/// The quality report of --stats (mesh_io.hpp, tet_mesh_io.hpp).
std::string quality_report(const Mesh& mesh, std::size_t) { return format_stats(mesh_stats(mesh)); }
std::string quality_report(const TetMesh& mesh, std::size_t inputs) {
  return format_stats(tet_mesh_stats(mesh), inputs);
}

/// Writes the mesh's outputs aside, then renames them into place together with whatever
/// `out` already holds (the feed, written as the run went: atomic_file.hpp); then the
/// duplicate count and --stats. `mesh` is a Mesh (2D) or a TetMesh (3D); `propagations` is
/// the log of the edits' propagations, null without --edits (--stats reports them after the
/// quality report).
template <std::size_t d, class Canonical>
void write_outputs(const MeshCommandOptions& o, AtomicOutputs& out, const Canonical& mesh, const Box<d>& box,
                   std::span<const Point<d>> inputs, std::size_t duplicates_skipped,
                   const PropagationLog* propagations = nullptr, std::size_t edits = 0) {
  out.add(o.outbase + ".node", format_node(mesh, box));
  out.add(o.outbase + ".ele", format_ele(mesh));
  if (!o.vtk.empty()) out.add(o.vtk, format_vtk(mesh));
  if (!o.msh.empty()) out.add(o.msh, format_msh(mesh));
  if constexpr (d == 2) {
    if (!o.svg.empty()) {
      // Dots shrink with density as in the quadtree's picture (svg.hpp), from the mesh's own
      // default radius down.
      SvgMeshOptions svg_options;
      const double largest_px = svg_options.point_radius_px;
      svg_options.point_radius_px = o.svg_point_radius > 0
                                        ? o.svg_point_radius
                                        : default_point_radius_px(inputs.size(), svg_options.width_px, largest_px);
      svg_options.max_marked_inputs = o.svg_max_points;
      out.add(o.svg, format_svg(mesh, box, inputs, svg_options));
    }
  }
  out.commit();

  // After the outputs are in place, so that a failed run prints only its error line.
  if (o.skip_duplicates) std::printf("duplicates: skipped %zu later copies\n", duplicates_skipped);
  if (o.stats) {
    std::string report = quality_report(mesh, inputs.size());
    if (propagations) report += format_propagation_stats(*propagations, edits, d == 2 ? "triangles" : "tetrahedra");
    std::fflush(stdout);
    std::fputs(report.c_str(), stderr);
    std::fflush(stderr);
  }
}

/// --postprocess hpu without --edits: HpuMesh of the points, from scratch. --check meshes the
/// points again in reverse order (the mesh is a function of the point set) and checks the
/// contract: Delaunay, every angle at least the bound, tiling, every point a vertex.
int run_hpu_mesh(const MeshCommandOptions& o, Columns columns) {
  const double bound = angle_bound(o, /*hpu=*/true);
  std::optional<Phase> reading(std::in_place, "reading " + o.points);
  const InitialPoints<2> initial = read_initial_points<2>(o.points, o.box, o.skip_duplicates, columns);
  const std::vector<Point<2>>& points = initial.file.points;
  const Box<2>& box = initial.box;
  reading.reset();

  std::optional<HpuMesh> built;
  {
    const Phase building("building the hpu mesh of " + std::to_string(points.size()) + " points");
    try {
      built.emplace(box, std::span<const Point<2>>(points), bound);
    } catch (const InputError& e) {
      const int level = dynmesh::detail::BasicMeshGrid<2>::resolution_level(box);
      rethrow_construction_error<2>(e, initial, level >= 2 ? level : -1);
    }
  }
  const Mesh mesh = built->mesh();
  if (o.check) {
    const Phase checking("checking against a from-scratch mesh of the " + std::to_string(points.size()) +
                         " points in reverse order");
    const std::vector<Point<2>> reversed(points.rbegin(), points.rend());
    if (HpuMesh(box, reversed, bound).mesh() != mesh)
      throw InvariantError("--check failed: meshing the points in reverse order gives another mesh");
    MeshCheckOptions options;
    options.min_angle_deg = bound;
    options.delaunay = true;
    const MeshReport report = check_mesh(mesh, box, points, options);
    if (!report.ok()) throw InvariantError("--check failed: " + report.summary());
  }
  AtomicOutputs out;
  if (!o.feed.empty()) out.add(o.feed, feed_header());  // no edits: the header alone
  write_outputs<2>(o, out, mesh, box, std::span<const Point<2>>(points), initial.duplicates_skipped);
  return 0;
}

/// The self-adjusting mesh of either dimension (`Structure`: DynamicMesh, DynamicOctreeMesh):
/// reads the points and the script, builds with build(box, points), applies the edits (one
/// feed update and one PropagationLog entry per propagation), checks with check(structure)
/// under --check, and writes the outputs. `what` names the mesh in messages ("quadtree mesh").
template <std::size_t d, class Structure, class Build, class Check>
int run_dynamic(const MeshCommandOptions& o, Columns columns, const std::string& what, Build&& build,
                Check&& check) {
  std::optional<Phase> reading(std::in_place, "reading " + o.points);
  const InitialPoints<d> initial = read_initial_points<d>(o.points, o.box, o.skip_duplicates, columns);
  const Box<d>& box = initial.box;
  // Read the whole script before meshing, so a malformed script fails fast.
  const EditScript<d> script = o.edits.empty() ? EditScript<d>{} : read_edits_file<d>(o.edits);
  reading.reset();

  std::optional<Structure> built;
  {
    const Phase building("building the " + what + " of " + std::to_string(initial.file.points.size()) + " points");
    try {
      built.emplace(build(box, std::span<const Point<d>>(initial.file.points)));
    } catch (const InputError& e) {
      // The mesh resolves points only down to its level R (none below 2: the box is unusable).
      const int level = dynmesh::detail::BasicMeshGrid<d>::resolution_level(box);
      rethrow_construction_error<d>(e, initial, level >= 2 ? level : -1);
    }
  }
  Structure& dynamic = *built;

  // The feed goes to its temporary as the edits propagate; a failure from here on removes it
  // with the outputs not yet written, and the target stays as it was.
  AtomicOutputs out;
  AtomicOutputs::Stream* feed = o.feed.empty() ? nullptr : &out.open_stream(o.feed);
  if (feed) feed->append(feed_header());
  std::string update;  // one update's lines; reused, so that it stops allocating once grown
  PropagationLog propagations;  // for --stats
  apply_edits<d>(dynamic, script, o.batch, [&] {
    propagations.record(dynamic.last_update(), dynamic.last_change());
    if (feed) {
      update.clear();
      append_feed_update(update, propagations.count(), dynamic.last_change());
      feed->append(update);
    }
  });

  const auto mesh = dynamic.mesh();
  std::vector<Point<d>> inputs;
  for (const auto& entry : dynamic.points()) inputs.push_back(entry.second);

  if (o.check) {
    // Everything is checked before any output is written: a failed check leaves old files.
    Verification v;
    {
      const Phase checking("checking against a from-scratch mesh of the " + std::to_string(inputs.size()) +
                           " final points");
      v = check(dynamic);
    }
    if (!v.ok) throw InvariantError("--check failed: " + v.problem);
  }

  built.reset();  // as in `dynmesh quadtree`: the outputs are formatted without the trace
  write_outputs<d>(o, out, mesh, box, std::span<const Point<d>>(inputs), initial.duplicates_skipped,
                   o.edits.empty() ? nullptr : &propagations, script.edits.size());
  return 0;
}

}  // namespace

int run_mesh(const MeshCommandOptions& o) {
  if (o.outbase.empty()) throw InputError(Kind::Malformed, "-o needs a non-empty OUTBASE");
  const PointFileShape shape = points_shape(o.points, o.dim_given ? o.dim : 0, [&o](int dim) {
    (void)check_mesh_options(o, dim);
    guard_mesh_memory(o, dim);
  });
  const bool hpu = check_mesh_options(o, shape.dim);  // again: a pipe's dimension is known only now
  if (shape.dim == 3) {
    return run_dynamic<3, DynamicOctreeMesh>(
        o, shape.columns, "octree mesh",
        [](const Box<3>& box, std::span<const Point<3>> pts) { return DynamicOctreeMesh(box, pts); },
        [](const DynamicOctreeMesh& dynamic) { return verify(dynamic); });
  }
  if (hpu && o.edits.empty()) return run_hpu_mesh(o, shape.columns);
  const double bound = angle_bound(o, hpu);
  MeshOptions mesh_options;
  mesh_options.postprocess = hpu ? Postprocess::Hpu : Postprocess::Quadtree;
  if (hpu) mesh_options.min_angle = bound;
  return run_dynamic<2, DynamicMesh>(
      o, shape.columns, hpu ? "hpu mesh" : "quadtree mesh",
      [&mesh_options](const Box<2>& box, std::span<const Point<2>> pts) { return DynamicMesh(box, pts, mesh_options); },
      [bound](const DynamicMesh& dynamic) { return verify(dynamic, bound); });
}

}  // namespace dynmesh::tool
