// `dynmesh mesh` (2D): mesh a point file in its box, apply an edit script dynamically, write
// the final mesh as .node/.ele (and optionally the change feed, VTK, MSH, SVG), docs/
// FORMATS.md "dynmesh mesh (2D)". `--postprocess hpu` (the default) is DynHPU's off-center
// Delaunay mesh: without --edits, its static twin HpuMesh (no trace: a fraction of the
// memory); with --edits, the self-adjusting DynamicMesh, whose output is the same bytes as a
// from-scratch run on the final points. `--postprocess quadtree` is the self-adjusting
// quadtree mesh (DynamicMesh). Every error names the file and line it
// comes from, as `dynmesh quadtree` does; every output is written aside and renamed into place
// only after all of them were written (atomic_file.hpp), so a failed run leaves old files
// untouched. Before anything is read, the memory guard (memory_guard.hpp) refuses a mesh that
// cannot fit in memory, unless --force; the long phases (reading, building, --check) show
// their elapsed time on stderr (progress.hpp). With --edits, --stats also reports the
// propagations (count, time, trace distance, triangles changed: propagation_log.hpp).
// Complexity: construction O(n lg n + |T'|) expected, then O(lg L/s) expected trace distance
// per edit (DynamicMesh); hpu O(n lg n + m) expected for m vertices; the outputs are linear
// in the mesh (the SVG O(t log t)); --check adds a from-scratch mesh and check_mesh,
// O((t + n) log t).
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
#include "initial_points.hpp"
#include "input_labels.hpp"
#include "postprocess_option.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/detail/quadtree_mesh_rules.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/io.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/mesh_check.hpp"
#include "dynmesh/mesh_io.hpp"
#include "dynmesh/quadtree_mesh.hpp"
#include "dynmesh/svg.hpp"
#include "memory_guard.hpp"
#include "progress.hpp"
#include "propagation_log.hpp"
#include "verify.hpp"

namespace dynmesh::tool {
namespace {

using Kind = InputError::Kind;

// The postprocess and angle options, checked before any file is read.
PostprocessChoice check_mesh_options(const MeshCommandOptions& o) {
  const PostprocessChoice choice = check_postprocess(
      o.postprocess, /*allow_none=*/false, o.min_angle_given ? std::optional<double>(o.min_angle) : std::nullopt);
  if (o.outbase.empty()) throw InputError(Kind::Malformed, "-o needs a non-empty OUTBASE");
  return choice;
}

/// Writes the outputs aside and renames them into place together (atomic_file.hpp); then
/// the duplicate count and --stats. `feed` is empty unless --feed was given; `propagations`
/// is the log of the edits' propagations, null without --edits (--stats reports them after
/// the quality report).
void write_outputs(const MeshCommandOptions& o, const Mesh& mesh, const Box<2>& box, std::span<const Point<2>> inputs,
                   const std::string& feed, std::size_t duplicates_skipped,
                   const PropagationLog* propagations = nullptr, std::size_t edits = 0) {
  AtomicOutputs out;
  out.add(o.outbase + ".node", format_node(mesh, box));
  out.add(o.outbase + ".ele", format_ele(mesh));
  if (!o.feed.empty()) out.add(o.feed, feed);
  if (!o.vtk.empty()) out.add(o.vtk, format_vtk(mesh));
  if (!o.msh.empty()) out.add(o.msh, format_msh(mesh));
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
  out.commit();

  // After the outputs are in place, so that a failed run prints only its error line.
  if (o.skip_duplicates) std::printf("duplicates: skipped %zu later copies\n", duplicates_skipped);
  if (o.stats) {
    std::string report = format_stats(mesh_stats(mesh));
    if (propagations) report += format_propagation_stats(*propagations, edits);
    std::fflush(stdout);
    std::fputs(report.c_str(), stderr);
    std::fflush(stderr);
  }
}

/// --postprocess hpu: HpuMesh of the points, from scratch. --check meshes the points again in
/// reverse order (the mesh is a function of the point set) and checks the contract: Delaunay,
/// every angle at least the bound, tiling, every point a vertex.
int run_hpu_mesh(const MeshCommandOptions& o) {
  const double bound = o.min_angle_given ? o.min_angle : kHpuDefaultMinAngle;
  if (!o.force) {
    const std::uint64_t points = points_held(o.points, o.edits);
    guard_memory("building the hpu mesh of " + std::to_string(points) + " points" + (o.check ? " with --check" : ""),
                 estimated_bytes(hpu_mesh_cost(bound), points, o.check));
  }
  std::optional<Phase> reading(std::in_place, "reading " + o.points);
  const InitialPoints<2> initial = read_initial_points<2>(o.points, o.box, o.skip_duplicates);
  const std::vector<Point<2>>& points = initial.file.points;
  const Box<2>& box = initial.box;
  reading.reset();

  std::optional<HpuMesh> built;
  {
    const Phase building("building the hpu mesh of " + std::to_string(points.size()) + " points");
    try {
      built.emplace(box, std::span<const Point<2>>(points), bound);
    } catch (const InputError& e) {
      const int level = dynmesh::detail::MeshGrid::resolution_level(box);
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
  write_outputs(o, mesh, box, points, o.feed.empty() ? std::string() : feed_header(), initial.duplicates_skipped);
  return 0;
}

std::vector<Point<2>> current_points(const DynamicMesh& mesh) {
  std::vector<Point<2>> pts;
  for (const auto& entry : mesh.points()) pts.push_back(entry.second);
  return pts;
}

}  // namespace

int run_mesh(const MeshCommandOptions& o) {
  const bool hpu = check_mesh_options(o) == PostprocessChoice::Hpu;
  if (hpu && o.edits.empty()) return run_hpu_mesh(o);
  const double bound = o.min_angle_given ? o.min_angle : hpu ? kHpuDefaultMinAngle : kQuadtreeMinAngle;
  const std::string what = hpu ? "hpu mesh" : "quadtree mesh";
  if (!o.force) {
    const std::uint64_t points = points_held(o.points, o.edits);
    guard_memory("building the " + what + " of " + std::to_string(points) + " points" +
                     (o.check ? " with --check" : ""),
                 estimated_bytes(hpu ? hpu_dynamic_cost(bound) : kQuadtreeMeshCost, points, o.check));
  }

  std::optional<Phase> reading(std::in_place, "reading " + o.points);
  const InitialPoints<2> initial = read_initial_points<2>(o.points, o.box, o.skip_duplicates);
  const PointFile<2>& file = initial.file;
  const Box<2>& box = initial.box;
  // Read the whole script before meshing, so a malformed script fails fast.
  const EditScript<2> script = o.edits.empty() ? EditScript<2>{} : read_edits_file<2>(o.edits);
  const std::vector<Edit<2>>& edits = script.edits;
  reading.reset();

  MeshOptions mesh_options;
  mesh_options.postprocess = hpu ? Postprocess::Hpu : Postprocess::Quadtree;
  if (hpu) mesh_options.min_angle = bound;
  std::optional<DynamicMesh> built;
  {
    const Phase building("building the " + what + " of " + std::to_string(file.points.size()) + " points");
    try {
      built.emplace(box, std::span<const Point<2>>(file.points), mesh_options);
    } catch (const InputError& e) {
      // The mesh resolves points only down to its level R (none below 2: the box is unusable).
      const int level = dynmesh::detail::MeshGrid::resolution_level(box);
      rethrow_construction_error<2>(e, initial, level >= 2 ? level : -1);
    }
  }
  DynamicMesh& dm = *built;

  const bool want_feed = !o.feed.empty();
  std::string feed;
  if (want_feed) feed = feed_header();
  PropagationLog propagations;  // for --stats
  auto record = [&] {
    propagations.record(dm.last_update(), dm.last_change());
    if (want_feed) feed += format_feed_update(propagations.count(), dm.last_change());
  };

  if (!edits.empty()) {
    const std::span<const Edit<2>> all(edits);
    Progress progress("edits", edits.size());
    if (o.batch == 0) {
      for (std::size_t i = 0; i < edits.size(); ++i) {
        const Edit<2>& e = edits[i];
        try {
          if (e.op == EditOp::Insert)
            dm.insert(e.point);
          else
            dm.erase(e.point);
        } catch (const InputError& err) {
          throw edit_error<2>(script, i, err);
        }
        record();
        progress.tick(i + 1);
      }
    } else {
      for (std::size_t i = 0; i < edits.size(); i += o.batch) {
        const std::size_t k = std::min(o.batch, edits.size() - i);
        try {
          dm.apply(all.subspan(i, k));
        } catch (const InputError& err) {
          // apply() names the failing edit by its index in the batch.
          if (err.point_indices().empty()) rethrow_in(err, o.edits);
          throw edit_error<2>(script, i + err.point_indices().back(), err);
        }
        record();
        progress.tick(i + k);
      }
    }
  }

  const Mesh mesh = dm.mesh();
  const std::vector<Point<2>> inputs = current_points(dm);

  if (o.check) {
    // Everything is checked before any output is written: a failed check leaves old files.
    Verification v;
    {
      const Phase checking("checking against a from-scratch mesh of the " + std::to_string(inputs.size()) +
                           " final points");
      v = verify(dm, bound);
    }
    if (!v.ok) throw InvariantError("--check failed: " + v.problem);
  }

  built.reset();  // as in `dynmesh quadtree`: the outputs are formatted without the trace
  write_outputs(o, mesh, box, inputs, feed, initial.duplicates_skipped, o.edits.empty() ? nullptr : &propagations,
                edits.size());
  return 0;
}

}  // namespace dynmesh::tool
