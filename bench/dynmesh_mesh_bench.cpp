// dynmesh_mesh_bench — the self-adjusting meshes (tree and postprocess in one trace) against
// their static twins, for bench/RESULTS.md: in 2D DynamicMesh against HpuMesh
// (--postprocess hpu) or QuadtreeMesh (quadtree); in 3D (--dim 3, the octree's tetrahedral
// mesh, --postprocess quadtree) DynamicOctreeMesh against OctreeMesh, and TetGen as a peer.
//
// Method (as dynmesh_bench): the static twin's build is the median of three; the
// self-adjusting build follows one untimed warm-up and is the median of `--reps`. Then U
// updates alternate the deletion of a random present point and the insertion of a fresh
// point of the same distribution; each propagate()'s time and trace distance, and the
// cells (triangles, tetrahedra) its change feed removes and adds, are recorded. The final
// mesh is compared with the static twin's on the final point set (verified = 1 when equal).
// Ratios come from one process run. Output: a table, or CSV with --csv:
//   dist,n,static_s,scratch_s,overhead,update_us,median_update_us,max_update_us,speedup,
//   mean_distance,changed_per_update,bytes_per_point,vertices_per_point,cells_per_point,
//   verified
// and in 3D after these
//   min_dihedral,max_dihedral,peer_s,peer_cells_per_point,peer_min_dihedral,
//   peer_max_dihedral,update_speedup_vs_peer
// speedup = static twin's build / mean update (a user's alternative is re-meshing);
// cells_per_point = triangles (2D) or tetrahedra (3D) of the initial mesh per input point;
// the dihedral angles are the final mesh's, in degrees. The peer (--peer tetgen, the 3D
// default; tetgen_peer.hpp) meshes the initial points in the same box, median of three:
// peer_s is TetGen's own total time, update_speedup_vs_peer = peer_s / mean update. Without
// the program the peer's columns are nan and a note goes to stderr.
// --tail K prints the K updates of largest trace distance to stderr (op, point, distance,
// cells changed): where the mean's tail comes from. --no-twin never builds the static twin,
// for sizes whose sorted tetrahedra do not fit in memory (uniform 10^5 in 3D: about 14 GB,
// twice that while the list grows): static_s, overhead, speedup, vertices_per_point,
// verified and the final angles are then nan, and cells_per_point is the self-adjusting
// mesh's count. --breakdown prints, after each row, the engine's trace by record kind
// (sac::MemoryBreakdown) after the build.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <sac/chunk_cache.hpp>

#include "bench_stats.hpp"

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/dynamic_octree_mesh.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/octree_mesh.hpp"
#include "dynmesh/quadtree_mesh.hpp"
#include "dynmesh/tet_mesh_check.hpp"
#include "tetgen_peer.hpp"

namespace {

using namespace dynmesh;

using bench::mean;
using bench::median;
using bench::seconds;

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

struct Row {
  std::string dist;
  std::size_t n = 0;
  double static_s = 0, scratch_s = 0, update_us = 0, median_us = 0, max_us = 0, distance = 0, changed = 0;
  double bytes_pp = 0, vertices_pp = 0, cells_pp = 0;
  double verified = kNan;  // 1: the final mesh is the twin's; 0: it is not; nan: not compared
  // 3D only: the final mesh's dihedral angles, and the peer's figures (nan without one).
  double min_dihedral = kNan, max_dihedral = kNan;
  double peer_s = kNan, peer_cells_pp = kNan, peer_min_dihedral = kNan, peer_max_dihedral = kNan;
  std::string breakdown;  // --breakdown: printed after the row
};

/// What the bench needs of one dimension's meshes: the self-adjusting mesh and the number of
/// its cells, its static twin (kept whole in 3D: a copy of its tetrahedra would double the
/// peak memory) and the twin's cells, and the vertices of a set of cells.
template <int d>
struct Meshes;

template <>
struct Meshes<2> {
  using Dynamic = DynamicMesh;
  using Twin = std::vector<Triangle>;
  static const Twin& cells_of(const Twin& twin) { return twin; }
  static std::size_t num_cells(const Dynamic& m) { return m.num_triangles(); }
  static Twin twin(const Box<2>& box, const std::vector<Point<2>>& pts, const MeshOptions& o) {
    if (o.postprocess == Postprocess::Hpu) return HpuMesh(box, pts, o.min_angle).triangles();
    return QuadtreeMesh(box, pts).triangles();
  }
  static void build(std::optional<Dynamic>& m, const Box<2>& box, const std::vector<Point<2>>& pts,
                    const MeshOptions& o) {
    m.emplace(box, pts, o);
  }
  static std::vector<Triangle> cells(const Dynamic& m) { return m.triangles(); }
  static std::size_t vertices(const std::vector<Triangle>& cells) { return make_mesh(cells).num_vertices(); }
};

template <>
struct Meshes<3> {
  using Dynamic = DynamicOctreeMesh;
  using Twin = OctreeMesh;
  static const std::vector<Tetrahedron>& cells_of(const Twin& twin) { return twin.tetrahedra(); }
  static std::size_t num_cells(const Dynamic& m) { return m.num_tetrahedra(); }
  static Twin twin(const Box<3>& box, const std::vector<Point<3>>& pts, const MeshOptions&) {
    return OctreeMesh(box, pts);
  }
  static void build(std::optional<Dynamic>& m, const Box<3>& box, const std::vector<Point<3>>& pts,
                    const MeshOptions&) {
    m.emplace(box, pts);
  }
  static std::vector<Tetrahedron> cells(const Dynamic& m) { return m.tetrahedra(); }
  static std::size_t vertices(const std::vector<Tetrahedron>& cells) { return make_tet_mesh(cells).num_vertices(); }
};

template <int d>
struct Costly {
  double distance;
  bool insert;
  Point<d> p;
  std::size_t changed;
};

/// The smallest and largest dihedral angle of the tetrahedra, in degrees.
void dihedral_range(const std::vector<Tetrahedron>& tets, double& lo, double& hi) {
  lo = 180;
  hi = 0;
  for (const Tetrahedron& t : tets)
    for (double a : dihedral_angles_deg(t)) {
      lo = std::min(lo, a);
      hi = std::max(hi, a);
    }
}

/// The peer's figures on the initial points, median of three runs (its own time).
void measure_peer(const std::string& tetgen, const Box<3>& box, const std::vector<Point<3>>& pts, Row& row) {
  std::vector<double> times;
  for (int i = 0; i < 3; ++i) {
    const bench::TetgenResult r = bench::tetgen_quality_mesh(tetgen, box, pts);
    if (!r.ran) {
      std::fprintf(stderr, "dynmesh_mesh_bench: %s; the peer's columns are nan\n", r.note.c_str());
      return;
    }
    if (i == 0) {
      if (r.vertices < pts.size() + 8)
        std::fprintf(stderr, "dynmesh_mesh_bench: tetgen kept %zu vertices of %zu points and 8 corners\n",
                     r.vertices, pts.size());
      std::fprintf(stderr, "tetgen (n = %zu): %zu vertices, %zu tetrahedra, %s time %.4f s, wall %.4f s\n",
                   pts.size(), r.vertices, r.tetrahedra, r.own_time ? "its own" : "no own time, wall", r.seconds,
                   r.wall_seconds);
      row.peer_cells_pp = static_cast<double>(r.tetrahedra) / static_cast<double>(pts.size());
      row.peer_min_dihedral = r.min_dihedral;
      row.peer_max_dihedral = r.max_dihedral;
    }
    times.push_back(r.seconds);
  }
  row.peer_s = median(times);
}

/// One size's row. With `with_twin` false the static twin is never built (the sizes whose
/// twin does not fit in memory): its time, the vertex count, the final comparison and the
/// final mesh's angles are nan, and the cells per point are the self-adjusting mesh's count.
template <int d>
Row measure(Distribution dist, std::size_t n, std::size_t updates, int reps, std::uint64_t seed,
            const MeshOptions& options, std::size_t tail, const std::string& tetgen, bool with_twin,
            bool breakdown) {
  using M = Meshes<d>;
  Row row;
  row.dist = std::string(distribution_name(dist));
  row.n = n;
  const auto pool = generate<d>(dist, n + updates, seed);
  const std::vector<Point<d>> initial(pool.begin(), pool.begin() + static_cast<std::ptrdiff_t>(n));
  const Box<d> box = derive_box<d>(pool);

  if (with_twin) {
    std::vector<double> st;
    std::optional<typename M::Twin> twin;
    for (int i = 0; i < 3; ++i) {
      twin.reset();
      st.push_back(seconds([&] { twin.emplace(M::twin(box, initial, options)); }));
    }
    row.static_s = median(st);
    const auto& cells = M::cells_of(*twin);
    row.vertices_pp = static_cast<double>(M::vertices(cells)) / static_cast<double>(n);
    row.cells_pp = static_cast<double>(cells.size()) / static_cast<double>(n);
  } else {
    row.static_s = row.vertices_pp = kNan;
  }
  if constexpr (d == 3)
    if (!tetgen.empty()) measure_peer(tetgen, box, initial, row);

  { std::optional<typename M::Dynamic> warm; M::build(warm, box, initial, options); }
  std::vector<double> sc;
  std::optional<typename M::Dynamic> mesh;
  for (int i = 0; i < reps; ++i) {
    mesh.reset();
    sc.push_back(seconds([&] { M::build(mesh, box, initial, options); }));
  }
  row.scratch_s = median(sc);
  row.bytes_pp = static_cast<double>(mesh->trace_bytes()) / static_cast<double>(n);
  if (breakdown) {
    std::ostringstream os;
    os << mesh->memory_breakdown();
    row.breakdown = os.str();
  }
  if (!with_twin) row.cells_pp = static_cast<double>(M::num_cells(*mesh)) / static_cast<double>(n);

  Rng rng(seed ^ 0x5eed);
  std::vector<PointId> ids;
  for (const auto& [id, p] : mesh->points()) ids.push_back(id);
  std::vector<double> all, dist_all, changed;
  std::vector<Costly<d>> costly;
  std::size_t next = n;
  for (std::size_t u = 0; u < updates; ++u) {
    Point<d> at{};
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
  std::sort(costly.begin(), costly.end(), [](const auto& a, const auto& b) { return a.distance > b.distance; });
  for (std::size_t i = 0; i < std::min(tail, costly.size()); ++i) {
    // The point and the box's origin and side, each coordinate exactly (%.17g).
    std::string where, origin;
    char buf[32];
    for (int k = 0; k < d; ++k) {
      std::snprintf(buf, sizeof buf, "%.17g ", costly[i].p[k]);
      where += buf;
      std::snprintf(buf, sizeof buf, "%.17g ", box.origin[k]);
      origin += buf;
    }
    std::fprintf(stderr, "costly: %s %s(box %s%.17g): distance %.0f, %zu %s changed\n",
                 costly[i].insert ? "insert" : "delete", where.c_str(), origin.c_str(), box.side, costly[i].distance,
                 costly[i].changed, d == 2 ? "triangles" : "tetrahedra");
  }
  row.update_us = mean(all) * 1e6;
  row.median_us = median(all) * 1e6;
  row.max_us = all.empty() ? 0 : *std::max_element(all.begin(), all.end()) * 1e6;
  row.distance = mean(dist_all);
  row.changed = mean(changed);

  if (!with_twin) return row;
  std::vector<Point<d>> cur;
  for (const auto& [id, p] : mesh->points()) cur.push_back(p);
  const auto final_cells = M::cells(*mesh);
  row.verified = M::cells_of(M::twin(box, cur, options)) == final_cells ? 1 : 0;
  if constexpr (d == 3) dihedral_range(final_cells, row.min_dihedral, row.max_dihedral);
  return row;
}

void print_header(bool csv, int dim) {
  if (csv) {
    std::printf("dist,n,static_s,scratch_s,overhead,update_us,median_update_us,max_update_us,speedup,"
                "mean_distance,changed_per_update,bytes_per_point,vertices_per_point,cells_per_point,verified");
    if (dim == 3)
      std::printf(",min_dihedral,max_dihedral,peer_s,peer_cells_per_point,peer_min_dihedral,peer_max_dihedral,"
                  "update_speedup_vs_peer");
  } else {
    std::printf("%-9s %8s %9s %9s %8s %9s %9s %9s %9s %8s %8s %11s %6s %6s %8s", "dist", "n", "static_s",
                "scratch_s", "overhead", "update_us", "median_us", "max_us", "speedup", "distance", "changed",
                "bytes/point", "V/pt", "C/pt", "verified");
    if (dim == 3)
      std::printf(" %7s %7s %9s %7s %9s %9s %9s", "min_dih", "max_dih", "peer_s", "peer_C", "peer_min",
                  "peer_max", "vs_peer");
  }
  std::printf("\n");
}

void print_row(const Row& r, bool csv, int dim) {
  const double overhead = r.scratch_s / r.static_s;
  const double speedup = r.static_s / (r.update_us * 1e-6);
  const double vs_peer = r.peer_s / (r.update_us * 1e-6);
  if (csv) {
    std::printf("%s,%zu,%.6f,%.6f,%.3f,%.2f,%.2f,%.2f,%.1f,%.1f,%.1f,%.1f,%.3f,%.3f,%.0f", r.dist.c_str(), r.n,
                r.static_s, r.scratch_s, overhead, r.update_us, r.median_us, r.max_us, speedup, r.distance, r.changed,
                r.bytes_pp, r.vertices_pp, r.cells_pp, r.verified);
    if (dim == 3)
      std::printf(",%.2f,%.2f,%.6f,%.3f,%.2f,%.2f,%.1f", r.min_dihedral, r.max_dihedral, r.peer_s, r.peer_cells_pp,
                  r.peer_min_dihedral, r.peer_max_dihedral, vs_peer);
  } else {
    std::printf("%-9s %8zu %9.4f %9.4f %8.2f %9.1f %9.1f %9.0f %9.0f %8.1f %8.1f %11.0f %6.2f %6.2f %8.0f",
                r.dist.c_str(), r.n, r.static_s, r.scratch_s, overhead, r.update_us, r.median_us, r.max_us, speedup,
                r.distance, r.changed, r.bytes_pp, r.vertices_pp, r.cells_pp, r.verified);
    if (dim == 3)
      std::printf(" %7.2f %7.2f %9.4f %7.2f %9.2f %9.2f %9.0f", r.min_dihedral, r.max_dihedral, r.peer_s,
                  r.peer_cells_pp, r.peer_min_dihedral, r.peer_max_dihedral, vs_peer);
  }
  std::printf("\n");
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  // Engines are built one after another: keep their freed chunks warm, so that every
  // measurement starts alike (sac/chunk_cache.hpp; a user's default is 64 MiB).
  sac::set_chunk_cache_limit(std::size_t{1} << 30);
  CLI::App app{"dynmesh_mesh_bench: self-adjusting meshes vs their static twins"};
  std::string dist_name = "uniform";
  std::vector<std::size_t> sizes{1000, 10000, 100000};
  std::size_t updates = 1000;
  int reps = 3;
  int dim = 2;
  std::uint64_t seed = 1;
  bool csv = false;
  bool no_twin = false;
  bool breakdown = false;
  std::string postprocess;
  std::string peer;
  double min_angle = kHpuDefaultMinAngle;
  std::size_t tail = 0;
  app.add_option("--dim", dim, "2 (triangles) or 3 (tetrahedra)")->check(CLI::IsMember({2, 3}));
  app.add_option("--postprocess", postprocess, "hpu (2D, the default) or quadtree (3D's only)")
      ->check(CLI::IsMember({"hpu", "quadtree"}));
  app.add_option("--peer", peer, "tetgen (3D's default) or none")->check(CLI::IsMember({"tetgen", "none"}));
  app.add_option("--min-angle", min_angle, "hpu's angle bound (1 to 30)");
  app.add_option("--tail", tail, "print the K costliest updates to stderr");
  app.add_option("--dist", dist_name, "point distribution");
  app.add_option("--n", sizes, "sizes (several allowed)")->delimiter(',');
  app.add_option("--updates", updates, "updates measured per size");
  app.add_option("--reps", reps, "timed from-scratch builds (median)")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed");
  app.add_flag("--csv", csv, "CSV output");
  app.add_flag("--breakdown", breakdown, "after each row, the engine's trace by record kind after the build");
  app.add_flag("--no-twin", no_twin,
               "never build the static twin (no static_s, vertices, verified, final angles): for sizes whose "
               "twin does not fit in memory: in 3D its tetrahedra take 96 bytes each, about 140 MB per 1,000 "
               "uniform points, and the final comparison holds two such lists");
  CLI11_PARSE(app, argc, argv);
  const auto dist = parse_distribution(dist_name);
  if (!dist) {
    std::fprintf(stderr, "dynmesh_mesh_bench: unknown distribution '%s'\n", dist_name.c_str());
    return 1;
  }
  if (postprocess.empty()) postprocess = dim == 3 ? "quadtree" : "hpu";
  if (peer.empty()) peer = dim == 3 ? "tetgen" : "none";
  if (dim == 3 && postprocess != "quadtree") {
    std::fprintf(stderr, "dynmesh_mesh_bench: in 3D the mesh is the octree's (--postprocess quadtree)\n");
    return 1;
  }
  if (dim == 2 && peer != "none") {
    std::fprintf(stderr, "dynmesh_mesh_bench: --peer tetgen is 3D's (2D's peer is in dynmesh_hpu_bench)\n");
    return 1;
  }
  std::string tetgen;
  if (peer == "tetgen") {
    tetgen = bench::find_tetgen();
    if (tetgen.empty())
      std::fprintf(stderr, "dynmesh_mesh_bench: no tetgen on PATH (bash dev.sh deps installs it); "
                           "the peer's columns are nan\n");
  }
  print_header(csv, dim);
  const MeshOptions options{.postprocess = postprocess == "hpu" ? Postprocess::Hpu : Postprocess::Quadtree,
                            .min_angle = min_angle};
  for (std::size_t n : sizes) {
    const Row r = dim == 3 ? measure<3>(*dist, n, updates, reps, seed, options, tail, tetgen, !no_twin, breakdown)
                           : measure<2>(*dist, n, updates, reps, seed, options, tail, tetgen, !no_twin, breakdown);
    print_row(r, csv, dim);
    std::fputs(r.breakdown.c_str(), stdout);
    if (r.verified == 0) return 1;
  }
  return 0;
}
