// dynmesh_mesh_bench — the self-adjusting meshes (DynamicMesh, tree and postprocess in one
// trace) against their static twins (HpuMesh for --postprocess hpu, QuadtreeMesh for
// quadtree), for bench/RESULTS.md.
//
// Method (as dynmesh_bench): the static twin's build is the median of three; the
// self-adjusting build follows one untimed warm-up and is the median of `--reps`. Then U
// updates alternate the deletion of a random present point and the insertion of a fresh
// point of the same distribution; each propagate()'s time and trace distance, and the
// triangles its change feed removes and adds, are recorded. The final mesh is compared with
// the static twin's on the final point set (verified = 1 when equal). Ratios come from one
// process run. Output: a table, or CSV with --csv:
//   dist,n,static_s,scratch_s,overhead,update_us,median_update_us,max_update_us,speedup,
//   mean_distance,changed_per_update,bytes_per_point,vertices_per_point,triangles_per_point,
//   verified
// speedup = static twin's build / mean update (a user's alternative is re-meshing).
// --tail K prints the K updates of largest trace distance to stderr (op, point, distance,
// triangles changed): where the mean's tail comes from.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <sac/chunk_cache.hpp>

#include "bench_stats.hpp"

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/quadtree_mesh.hpp"

namespace {

using namespace dynmesh;

using bench::mean;
using bench::median;
using bench::seconds;

struct Row {
  std::string dist;
  std::size_t n = 0;
  double static_s = 0, scratch_s = 0, update_us = 0, median_us = 0, max_us = 0, distance = 0, changed = 0;
  double bytes_pp = 0, vertices_pp = 0, triangles_pp = 0;
  bool verified = false;
};

/// The static twin's triangles of `pts`.
std::vector<Triangle> twin_triangles(const Box<2>& box, const std::vector<Point<2>>& pts, const MeshOptions& o) {
  if (o.postprocess == Postprocess::Hpu) return HpuMesh(box, pts, o.min_angle).triangles();
  return QuadtreeMesh(box, pts).triangles();
}

struct Costly {
  double distance;
  bool insert;
  Point<2> p;
  std::size_t changed;
};

Row measure(Distribution dist, std::size_t n, std::size_t updates, int reps, std::uint64_t seed,
            const MeshOptions& options, std::size_t tail) {
  Row row;
  row.dist = std::string(distribution_name(dist));
  row.n = n;
  const auto pool = generate<2>(dist, n + updates, seed);
  const std::vector<Point<2>> initial(pool.begin(), pool.begin() + static_cast<std::ptrdiff_t>(n));
  const Box<2> box = derive_box<2>(pool);

  std::vector<double> st;
  std::vector<Triangle> tris;
  for (int i = 0; i < 3; ++i) st.push_back(seconds([&] { tris = twin_triangles(box, initial, options); }));
  row.static_s = median(st);
  const Mesh m0 = make_mesh(tris);
  row.vertices_pp = static_cast<double>(m0.num_vertices()) / static_cast<double>(n);
  row.triangles_pp = static_cast<double>(m0.num_triangles()) / static_cast<double>(n);
  tris = {};

  { DynamicMesh warm(box, initial, options); }
  std::vector<double> sc;
  std::optional<DynamicMesh> mesh;
  for (int i = 0; i < reps; ++i) {
    mesh.reset();
    sc.push_back(seconds([&] { mesh.emplace(box, initial, options); }));
  }
  row.scratch_s = median(sc);
  row.bytes_pp = static_cast<double>(mesh->trace_bytes()) / static_cast<double>(n);

  Rng rng(seed ^ 0x5eed);
  std::vector<PointId> ids;
  for (const auto& [id, p] : mesh->points()) ids.push_back(id);
  std::vector<double> all, dist_all, changed;
  std::vector<Costly> costly;
  std::size_t next = n;
  for (std::size_t u = 0; u < updates; ++u) {
    Point<2> at{};
    const bool erase = u % 2 == 0 && !ids.empty();
    if (erase) {
      const std::size_t k = static_cast<std::size_t>(rng.below(ids.size()));
      at = mesh->point(ids[k]);
      mesh->erase(ids[k]);
      ids[k] = ids.back();
      ids.pop_back();
    } else {
      bool done = false;
      while (!done && next < pool.size()) {
        try {
          at = pool[next];
          ids.push_back(mesh->insert(pool[next++]));
          done = true;
        } catch (const InputError&) {  // too close for the resolution: take the next one
        }
      }
      if (!done) continue;
    }
    all.push_back(mesh->last_update().seconds);
    dist_all.push_back(static_cast<double>(mesh->last_update().trace_distance));
    changed.push_back(static_cast<double>(mesh->last_change().removed.size() + mesh->last_change().added.size()));
    if (tail) costly.push_back({dist_all.back(), !erase, at, static_cast<std::size_t>(changed.back())});
  }
  std::sort(costly.begin(), costly.end(), [](const Costly& a, const Costly& b) { return a.distance > b.distance; });
  for (std::size_t i = 0; i < std::min(tail, costly.size()); ++i)
    std::fprintf(stderr, "costly: %s %.17g %.17g (box %.17g %.17g %.17g): distance %.0f, %zu triangles changed\n",
                 costly[i].insert ? "insert" : "delete", costly[i].p[0], costly[i].p[1], box.origin[0], box.origin[1],
                 box.side, costly[i].distance, costly[i].changed);
  row.update_us = mean(all) * 1e6;
  row.median_us = median(all) * 1e6;
  row.max_us = all.empty() ? 0 : *std::max_element(all.begin(), all.end()) * 1e6;
  row.distance = mean(dist_all);
  row.changed = mean(changed);

  std::vector<Point<2>> cur;
  for (const auto& [id, p] : mesh->points()) cur.push_back(p);
  row.verified = twin_triangles(box, cur, options) == mesh->triangles();
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  // Engines are built one after another: keep their freed chunks warm, as the figures in
  // RESULTS.md were measured (sac/chunk_cache.hpp; a user's default is 64 MiB).
  sac::set_chunk_cache_limit(std::size_t{1} << 30);
  CLI::App app{"dynmesh_mesh_bench: self-adjusting meshes vs their static twins"};
  std::string dist_name = "uniform";
  std::vector<std::size_t> sizes{1000, 10000, 100000};
  std::size_t updates = 1000;
  int reps = 3;
  std::uint64_t seed = 1;
  bool csv = false;
  std::string postprocess = "hpu";
  double min_angle = kHpuDefaultMinAngle;
  std::size_t tail = 0;
  app.add_option("--postprocess", postprocess, "hpu or quadtree")->check(CLI::IsMember({"hpu", "quadtree"}));
  app.add_option("--min-angle", min_angle, "hpu's angle bound (1 to 30)");
  app.add_option("--tail", tail, "print the K costliest updates to stderr");
  app.add_option("--dist", dist_name, "point distribution");
  app.add_option("--n", sizes, "sizes (several allowed)")->delimiter(',');
  app.add_option("--updates", updates, "updates measured per size");
  app.add_option("--reps", reps, "timed from-scratch builds (median)")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed");
  app.add_flag("--csv", csv, "CSV output");
  CLI11_PARSE(app, argc, argv);
  const auto dist = parse_distribution(dist_name);
  if (!dist) {
    std::fprintf(stderr, "dynmesh_mesh_bench: unknown distribution '%s'\n", dist_name.c_str());
    return 1;
  }
  if (csv)
    std::printf("dist,n,static_s,scratch_s,overhead,update_us,median_update_us,max_update_us,speedup,"
                "mean_distance,changed_per_update,bytes_per_point,vertices_per_point,triangles_per_point,verified\n");
  else
    std::printf("%-9s %8s %9s %9s %8s %9s %9s %9s %9s %8s %8s %11s %6s %6s %8s\n", "dist", "n", "static_s",
                "scratch_s", "overhead", "update_us", "median_us", "max_us", "speedup", "distance", "changed",
                "bytes/point", "V/pt", "T/pt", "verified");
  for (std::size_t n : sizes) {
    const MeshOptions options{.postprocess = postprocess == "hpu" ? Postprocess::Hpu : Postprocess::Quadtree,
                              .min_angle = min_angle};
    const Row r = measure(*dist, n, updates, reps, seed, options, tail);
    const double overhead = r.scratch_s / r.static_s;
    const double speedup = r.static_s / (r.update_us * 1e-6);
    if (csv)
      std::printf("%s,%zu,%.6f,%.6f,%.3f,%.2f,%.2f,%.2f,%.1f,%.1f,%.1f,%.1f,%.3f,%.3f,%d\n", r.dist.c_str(), r.n,
                  r.static_s, r.scratch_s, overhead, r.update_us, r.median_us, r.max_us, speedup, r.distance,
                  r.changed, r.bytes_pp, r.vertices_pp, r.triangles_pp, r.verified ? 1 : 0);
    else
      std::printf("%-9s %8zu %9.4f %9.4f %8.2f %9.1f %9.1f %9.0f %9.0f %8.1f %8.1f %11.0f %6.2f %6.2f %8d\n",
                  r.dist.c_str(), r.n, r.static_s, r.scratch_s, overhead, r.update_us, r.median_us, r.max_us,
                  speedup, r.distance, r.changed, r.bytes_pp, r.vertices_pp, r.triangles_pp, r.verified ? 1 : 0);
    std::fflush(stdout);
    if (!r.verified) return 1;
  }
  return 0;
}
