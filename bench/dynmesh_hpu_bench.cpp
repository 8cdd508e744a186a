// dynmesh_hpu_bench — the hpu mesh (HpuMesh, DynHPU's static twin) against its peers on the
// peers' benchmark inputs, for bench/RESULTS.md and docs/EXPERIMENTS.md.
//
// Method: unif1e4 and unif1e5 are python_uniform(n, 1) (CPython's random.Random(1)), in
// FORMATS.md's default box, the inputs on which Triangle 1.6 (-pq) and CGAL 5.5 Mesh_2 were
// measured (their figures below were measured on this kind of machine). With
// --dist D the inputs are generate(D, n, 1) instead (spiral, curves, ...: data along curves,
// where a mesher's point location and cavities meet long thin triangles), in the box
// derive_box gives them, at 20.7 and 30 degrees; no earlier peer figures exist for them, so
// vs_Tri needs Triangle in the build and vs_CGAL is empty. Each
// mesh is built `--reps` times (median time), checked against the contract (Delaunay, every
// angle >= the bound, tiling, inputs present: checked = 1), and reported with its size, its
// ratio to the peers' sizes, and its angle histogram (10-degree bins, every angle of every
// triangle). Times are in steady state: one untimed build of each first, and freed memory
// kept in the heap (glibc's mallopt), so that neither mesher's time is the kernel's page
// faults (see main()).
// When the build has Triangle (DYNMESH_TRIANGLE_SOURCE, triangle_peer.hpp), each rep also
// builds Triangle's mesh of the same points and box right after the twin's, so that both
// medians come from the same run: tri_s is its median time, twin/Tri the ratio of the
// medians, and vs_Tri uses the vertices Triangle made here instead of the quoted figure.
// Without it those columns are empty ("-"; CSV: empty). Output: a table, or CSV with --csv:
//   input,angle,seconds,vertices,triangles,vs_triangle,vs_cgal,min_angle,rounds,entries_per_vertex,checked,
//   triangle_seconds,twin_over_triangle,triangle_vertices
#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "bench_stats.hpp"
#include "triangle_peer.hpp"

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/mesh_check.hpp"
#include "dynmesh/mesh_io.hpp"

namespace {

using namespace dynmesh;

struct Peer {
  std::size_t n;
  double angle;
  double triangle_vertices, cgal_vertices;
};

// The quoted peer table (vertices): Triangle 1.6 -pq and CGAL 5.5 Mesh_2 at 20.7 and 30 degrees.
constexpr Peer kPeers[] = {
    {10000, 20.7, 16462, 19773},
    {10000, 30.0, 28427, 46426},
    {100000, 20.7, 160302, 189985},
    {100000, 30.0, 276933, 436638},
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynmesh_hpu_bench: the hpu mesh against Triangle's and CGAL's sizes"};
  std::vector<std::size_t> ns{10000, 100000};
  int reps = 3;
  bool csv = false, histogram = false;
  std::string dist_name;
  app.add_option("--n", ns, "input sizes (python_uniform(n, 1), or generate(--dist, n, 1))")->delimiter(',');
  app.add_option("--dist", dist_name, "a distribution instead of unif1e4 and unif1e5 (e.g. spiral, curves)")
      ->check([](const std::string& s) {
        if (parse_distribution(s)) return std::string{};
        std::string msg = "unknown distribution '";
        msg.append(s).append("'");
        return msg;
      });
  app.add_option("--reps", reps, "builds per mesh (median time)")->check(CLI::Range(1, 100));
  app.add_flag("--csv", csv, "CSV instead of a table");
  app.add_flag("--histogram", histogram, "print each mesh's angle histogram");
  CLI11_PARSE(app, argc, argv);
#if defined(__GLIBC__)
  // Both meshers in steady state: freed memory stays in the heap, already touched, instead
  // of going back to the kernel and faulting in again (on this kind of VM a fresh page costs
  // more than the work on it, and which mesher met fresh pages depended on the other's
  // frees: Triangle took 0.21 or 0.34 s on the same points).
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
#endif

  if (!bench::kHaveTriangle && !csv)
    std::printf("# no Triangle in this build: vs_Tri uses Triangle 1.6's sizes on these inputs, measured before "
                "(configure with -DDYNMESH_TRIANGLE_SOURCE=.../triangle.c to run it here)\n");
  if (csv)
    std::printf(
        "input,angle,seconds,vertices,triangles,vs_triangle,vs_cgal,min_angle,rounds,entries_per_vertex,checked,"
        "triangle_seconds,twin_over_triangle,triangle_vertices\n");
  else
    std::printf("%-11s %6s %9s %9s %9s %8s %8s %9s %6s %8s %7s %9s %8s %9s\n", "input", "angle", "seconds", "vertices",
                "triangles", "vs_Tri", "vs_CGAL", "min_angle", "rounds", "entries", "checked", "tri_s", "twin/Tri",
                "tri_V");
  bool all_ok = true;
  const std::optional<Distribution> dist =
      dist_name.empty() ? std::nullopt : parse_distribution(dist_name);
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  for (const std::size_t n : ns) {
    const auto pts = dist ? generate<2>(*dist, n, 1) : python_uniform(n, 1);
    const Box<2> box = derive_box<2>(pts);
    // unif1e4 and unif1e5 with their peers' figures, or the distribution's at both angles
    // without them.
    std::vector<Peer> peers;
    if (dist)
      peers = {{n, 20.7, kNaN, kNaN}, {n, 30.0, kNaN, kNaN}};
    else
      for (const Peer& peer : kPeers)
        if (peer.n == n) peers.push_back(peer);
    for (const Peer& peer : peers) {
      std::vector<double> times, tri_times;
      std::vector<Triangle> tris;
      HpuStats stats;
      bench::TriangleMeshSize tri_size;
      for (int r = -1; r < reps; ++r) {  // r = -1: a warm-up of each, not timed
        // The build only, as for Triangle: the copy of its output and its destruction are
        // the bench's.
        std::optional<HpuMesh> m;
        const double t = bench::seconds([&] { m.emplace(box, pts, peer.angle); });
        if (r >= 0) times.push_back(t);
        tris = m->triangles();
        stats = m->stats();
        m.reset();  // Triangle then starts from the same heap as the twin did
        if (bench::kHaveTriangle) {
          const double tt = bench::seconds([&] { tri_size = bench::triangle_quality_mesh(box, pts, peer.angle); });
          if (r >= 0) tri_times.push_back(tt);
        }
      }
      const Mesh mesh = make_mesh(tris);
      const MeshReport report =
          check_mesh(mesh, box, pts, MeshCheckOptions{.min_angle_deg = peer.angle, .delaunay = true});
      all_ok = all_ok && report.ok();
      char input_buf[64];
      if (dist)
        std::snprintf(input_buf, sizeof input_buf, "%s%zu", dist_name.c_str(), n);
      else
        std::snprintf(input_buf, sizeof input_buf, "unif1e%d", n == 10000 ? 4 : n == 100000 ? 5 : 0);
      const std::string input = input_buf;
      const double tri_vertices = bench::kHaveTriangle ? double(tri_size.vertices) : peer.triangle_vertices;
      const double tri_s = bench::median(tri_times);
      char tri_cols[96] = ",,,";  // CSV's empty fields without Triangle
      if (bench::kHaveTriangle)
        std::snprintf(tri_cols, sizeof tri_cols, csv ? ",%.4f,%.3f,%zu" : " %9.4f %8.3f %9zu", tri_s,
                      bench::median(times) / tri_s, tri_size.vertices);
      else if (!csv)
        std::snprintf(tri_cols, sizeof tri_cols, " %9s %8s %9s", "-", "-", "-");
      // A ratio to a peer figure this input has none of: empty in CSV, "-" in the table.
      const auto ratio = [&](double peer_vertices) {
        char buf[32];
        if (std::isnan(double(mesh.num_vertices()) / peer_vertices))
          std::snprintf(buf, sizeof buf, "%s", csv ? "" : "-");
        else
          std::snprintf(buf, sizeof buf, "%.3f", double(mesh.num_vertices()) / peer_vertices);
        return std::string(buf);
      };
      const std::string vt = ratio(tri_vertices), vc = ratio(peer.cgal_vertices);
      const double per_vertex = double(stats.entries) / double(mesh.num_vertices());  // queue entries
      if (csv)
        std::printf("%s,%.1f,%.4f,%zu,%zu,%s,%s,%.3f,%zu,%.3f,%d%s\n", input.c_str(), peer.angle,
                    bench::median(times), mesh.num_vertices(), mesh.num_triangles(), vt.c_str(), vc.c_str(),
                    report.min_angle_deg, stats.rounds, per_vertex, report.ok() ? 1 : 0, tri_cols);
      else
        std::printf("%-11s %6.1f %9.4f %9zu %9zu %8s %8s %9.3f %6zu %8.3f %7d%s\n", input.c_str(), peer.angle,
                    bench::median(times), mesh.num_vertices(), mesh.num_triangles(), vt.c_str(), vc.c_str(),
                    report.min_angle_deg, stats.rounds, per_vertex, report.ok() ? 1 : 0, tri_cols);
      if (histogram) {
        const MeshStats ms = mesh_stats(mesh);
        std::printf("  angle histogram (%s, %.1f deg):", input.c_str(), peer.angle);
        for (std::size_t k = 0; k < ms.angle_histogram.size(); ++k)
          if (ms.angle_histogram[k]) std::printf(" [%zu,%zu):%zu", 10 * k, 10 * k + 10, ms.angle_histogram[k]);
        std::printf("\n");
      }
    }
  }
  return all_ok ? 0 : 1;
}
