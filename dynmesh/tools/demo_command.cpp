// `dynmesh demo`: the README's main job, with an embedded input (no files needed). Meshes N
// points of the `clusters` distribution (fixed seed) with DynHPU, the self-adjusting
// off-center Delaunay mesh (DynamicMesh, Postprocess::Hpu, 20.7 degrees), applies U
// single-point updates (alternating deletions and insertions, one propagation each), prints
// the figures (led by the speedup of an update over re-meshing the points from scratch with
// the static twin HpuMesh; the update figures as `mesh --stats` measures them,
// propagation_log.hpp), verifies the final mesh against a from-scratch mesh and the
// checkers, and draws the final mesh as SVG.
// Complexity: the build O(n lg n + m) expected; each update O(lg L/s) expected trace
// distance plus the driver's O(n) spread bookkeeping (untimed); the check O(m lg m).
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/mesh_io.hpp"
#include "dynmesh/svg.hpp"
#include "progress.hpp"
#include "propagation_log.hpp"
#include "update_driver.hpp"
#include "verify.hpp"

namespace dynmesh::tool {

int run_demo(const DemoOptions& o) {
  constexpr Distribution kDist = Distribution::Clusters;
  if (o.n < 2) throw InputError(InputError::Kind::Count, "--n must be at least 2");

  std::vector<Point<2>> initial = generate<2>(kDist, o.n + o.updates, o.seed);
  std::vector<Point<2>> pool(initial.begin() + static_cast<std::ptrdiff_t>(o.n), initial.end());
  initial.resize(o.n);
  const Box<2> box = derive_box<2>(initial);
  const MeshOptions options{.postprocess = Postprocess::Hpu, .min_angle = kHpuDefaultMinAngle};

  double build_s = 0;
  std::optional<DynamicMesh> built;
  {
    const Phase building("meshing " + std::to_string(o.n) + " points");
    const auto t0 = std::chrono::steady_clock::now();
    built.emplace(box, std::span<const Point<2>>(initial), options);
    build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  DynamicMesh& mesh = *built;

  UpdateDriver<2, DynamicMesh> driver(mesh, std::move(pool), o.seed);
  const double spread = driver.log2_spread();
  PropagationLog log;
  std::size_t deletions = 0;
  {
    Progress progress("updates", o.updates);
    for (std::size_t u = 0; u < o.updates; ++u) {
      const auto step = driver.step();
      log.record(step.stats, mesh.last_change());
      deletions += step.op == EditOp::Delete;
      progress.tick(u + 1);
    }
  }

  Verification v;
  {
    const Phase checking("checking against a from-scratch mesh of the " + std::to_string(mesh.size()) +
                         " final points");
    v = verify(mesh, options.min_angle);
  }
  const Mesh final_mesh = mesh.mesh();
  const MeshStats stats = mesh_stats(final_mesh);
  if (!o.svg.empty()) {
    const std::vector<Point<2>> pts = driver.coordinates();
    SvgMeshOptions svg_options;
    svg_options.point_radius_px = default_point_radius_px(pts.size(), svg_options.width_px, svg_options.point_radius_px);
    AtomicOutputs out;
    out.add(o.svg, format_svg(final_mesh, box, pts, svg_options));
    out.commit();
  }

  const double mean_s = mean(log.seconds());
  std::printf("dynmesh demo: a quality Delaunay mesh (DynHPU, smallest angle >= %.1f degrees) kept up to date by "
              "change propagation\n",
              options.min_angle);
  // The headline: what an update saves over the alternative, re-meshing the points from
  // scratch with the static twin (the self-adjusting build, slower, would flatter the ratio).
  if (o.updates > 0 && mean_s > 0)
    std::printf("  speedup            %.0fx: an update vs re-meshing from scratch (%.3f s static mesher / %.1f us "
                "mean update)\n",
                v.static_seconds / mean_s, v.static_seconds, mean_s * 1e6);
  std::printf("  points             %zu (clusters distribution, 2D, seed %llu), log2(L/s) = %.1f\n", o.n,
              static_cast<unsigned long long>(o.seed), spread);
  std::printf("  mesh               %zu vertices, %zu triangles, smallest angle %.2f degrees\n", stats.vertices,
              stats.triangles, stats.min_angle_deg);
  std::printf("  build              %.3f s self-adjusting, %.3f s static twin (HpuMesh)\n", build_s,
              v.static_seconds);
  std::printf("  updates            %zu (%zu deletions, %zu insertions), one propagation each\n", o.updates,
              deletions, o.updates - deletions);
  if (o.updates > 0) {
    std::printf("  update time        mean %.1f us, median %.1f us\n", mean_s * 1e6, median(log.seconds()) * 1e6);
    std::printf("  trace distance     mean %.0f, median %.0f per update\n", mean(log.distances()),
                median(log.distances()));
    std::printf("  triangles changed  mean %.1f, median %.0f per update (removed + added)\n", mean(log.changed()),
                median(log.changed()));
  }
  std::printf("  live trace         %.0f bytes per point\n",
              static_cast<double>(mesh.trace_bytes()) / static_cast<double>(std::max<std::size_t>(1, mesh.size())));
  if (v.ok)
    std::printf("verified: yes (invariants and mesh checks hold; equal to a from-scratch mesh of the final %zu "
                "points)\n",
                mesh.size());
  else
    std::printf("verified: no\n");
  if (!o.svg.empty()) std::printf("picture: %s\n", o.svg.c_str());
  std::fflush(stdout);
  if (!v.ok) throw InvariantError("verification failed: " + v.problem);
  return 0;
}

}  // namespace dynmesh::tool
