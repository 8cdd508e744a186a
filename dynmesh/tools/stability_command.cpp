// `dynmesh stability`: the trace-distance experiment of shared/FORMATS.md. Builds the tree on
// N points of a distribution, then measures U single-point updates (alternating deletions of
// a present point and insertions of a new point of the same distribution, one propagation
// each) and appends one CSV row per update. With `--postprocess quadtree` (2D) the structure
// is a DynamicMesh: QuadTreeRefine and the quadtree mesh run in one trace, so each row's
// trace_distance and seconds are the whole update, tree and mesh (FORMATS.md).
//
// The N initial points and the insertion pool come from one call generate(dist, N + U, seed,
// spread): the generators return their points in a seeded random order, so the first N are
// a sample of the distribution and the rest are fresh points of the same distribution,
// distinct from them. log2_spread is exact for every row (UpdateDriver keeps the closest-pair
// distance up to date; see update_driver.hpp).
//
// Before generating anything, the memory guard (memory_guard.hpp) refuses a run whose
// structure (N points and the U/2 insertions, plus the final from-scratch check) cannot fit in
// memory, unless --force; the build and the final check show their elapsed time on stderr
// (progress.hpp).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <numeric>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/errors.hpp"
#include "memory_guard.hpp"
#include "postprocess_option.hpp"
#include "progress.hpp"
#include "update_driver.hpp"
#include "verify.hpp"

namespace dynmesh::tool {
namespace {

using Kind = InputError::Kind;

constexpr const char* kCsvHeader = "dist,dim,n,log2_spread,op,trace_distance,seconds";

std::string known_distributions() {
  std::string s;
  for (const Distribution dist : all_distributions()) {
    if (!s.empty()) s += ", ";
    s += distribution_name(dist);
  }
  return s;
}

// Appends the rows to the CSV, with the header first when the file is new or empty, and
// refuses a non-empty file whose first line is not the header (it is some other file). The
// old content and the rows are written aside and renamed into place (atomic_file.hpp), so a
// failed write leaves the old file whole.
void append_csv(const std::string& path, const std::string& rows) {
  std::string text = AtomicOutputs::read_existing(path).value_or(std::string{});
  if (text.empty()) {
    text = std::string(kCsvHeader) + '\n';
  } else {
    std::string_view first = std::string_view(text).substr(0, text.find('\n'));
    if (first.ends_with('\r')) first.remove_suffix(1);
    if (first != kCsvHeader)
      throw InputError(Kind::Malformed, "exists and is not a stability CSV (its first line is not '" +
                                            std::string(kCsvHeader) + "'); not appending to it",
                       path, 1);
    if (text.back() != '\n') text += '\n';  // a last row without its line end
  }
  text += rows;
  AtomicOutputs out;
  out.add(path, text);
  out.commit();
}

// The structure a run measures: the tree alone, or the tree and its mesh.
template <std::size_t d>
DynamicQuadtree<d> build(const Box<d>& box, std::span<const Point<d>> pts, const DynamicQuadtree<d>*) {
  return DynamicQuadtree<d>(box, pts);
}
inline DynamicMesh build(const Box<2>& box, std::span<const Point<2>> pts, const DynamicMesh*,
                         const MeshOptions& options) {
  return DynamicMesh(box, pts, options);
}
template <std::size_t d>
DynamicQuadtree<d> build(const Box<d>& box, std::span<const Point<d>> pts, const DynamicQuadtree<d>* t,
                         const MeshOptions&) {
  return build(box, pts, t);
}

template <std::size_t d>
Verification verify_final(const DynamicQuadtree<d>& tree, double) {
  return verify(tree);
}
inline Verification verify_final(const DynamicMesh& mesh, double min_angle) { return verify(mesh, min_angle); }

// `what` names the structure on stdout ("quadtree", "quadtree mesh"); `cost` is its memory.
template <std::size_t d, class Structure>
int run(const StabilityOptions& o, Distribution dist, const char* what, const MemoryCost& cost,
        const MeshOptions& mesh_options = {}) {
  // On stderr, a 3D tree is called what it is.
  const char* structure_name = d == 3 ? "octree" : what;
  if (!o.force) {
    // Deletions and insertions alternate, so the structure never holds more than N + ⌈U/2⌉.
    const std::uint64_t points = std::uint64_t{o.n} + (std::uint64_t{o.updates} + 1) / 2;
    guard_memory(std::string("building the ") + structure_name + " of " + std::to_string(points) + " points",
                 estimated_bytes(cost, points, /*check=*/true));
  }
  std::optional<Phase> building(std::in_place, std::string("building the ") + structure_name + " of " +
                                                   std::to_string(o.n) + " points");
  std::vector<Point<d>> all = generate<d>(dist, o.n + o.updates, o.seed, o.spread);
  std::vector<Point<d>> pool(all.begin() + static_cast<std::ptrdiff_t>(o.n), all.end());
  all.resize(o.n);
  const Box<d> box = derive_box<d>(all);
  Structure structure =
      build(box, std::span<const Point<d>>(all), static_cast<const Structure*>(nullptr), mesh_options);
  UpdateDriver<d, Structure> driver(structure, std::move(pool), o.seed);
  building.reset();
  const double initial_spread = driver.log2_spread();
  const std::string prefix =
      std::string(distribution_name(dist)) + ',' + std::to_string(d) + ',' + std::to_string(o.n) + ',';
  std::string rows;
  std::uint64_t total_distance = 0;
  {
    Progress progress("updates", o.updates);
    for (std::size_t u = 0; u < o.updates; ++u) {
      const auto step = driver.step();
      char buf[160];
      std::snprintf(buf, sizeof buf, "%.4f,%s,%llu,%.9g\n", step.log2_spread,
                    step.op == EditOp::Insert ? "insert" : "delete",
                    static_cast<unsigned long long>(step.stats.trace_distance), step.stats.seconds);
      rows += prefix;
      rows += buf;
      total_distance += step.stats.trace_distance;
      progress.tick(u + 1);
    }
  }
  append_csv(o.csv, rows);

  // History independence on every run: the updated structure must equal a from-scratch build
  // on the final points (the rows are written first, so a failure keeps them for inspection).
  Verification v;
  {
    const Phase checking("checking against a from-scratch build of the " + std::to_string(structure.size()) +
                         " final points");
    const double bound = mesh_options.postprocess == Postprocess::Hpu ? mesh_options.min_angle : kQuadtreeMinAngle;
    v = verify_final(structure, o.min_angle_given ? o.min_angle : bound);
  }
  if (!v.ok) throw InvariantError("verification failed after the updates: " + v.problem);

  std::printf("stability: %s, %s %zuD, n = %zu, log2(L/s) = %.2f, %zu updates, mean trace distance %.1f, "
              "verified against a from-scratch build; rows appended to %s\n",
              what, std::string(distribution_name(dist)).c_str(), d, o.n, initial_spread, o.updates,
              o.updates ? static_cast<double>(total_distance) / static_cast<double>(o.updates) : 0.0,
              o.csv.c_str());
  if (!o.plot.empty()) {
    plot_stability_csv(o.csv, o.plot);
    std::printf("plot: %s\n", o.plot.c_str());
  }
  return 0;
}

}  // namespace

int run_stability(const StabilityOptions& o) {
  const auto dist = parse_distribution(o.dist);
  if (!dist)
    throw InputError(Kind::Malformed, "unknown distribution '" + o.dist + "' (known: " + known_distributions() + ")");
  if (o.n < 2) throw InputError(Kind::Count, "--n must be at least 2 (the spread needs a closest pair)");
  if (!(std::isfinite(o.spread) && o.spread >= 2))
    throw InputError(Kind::Malformed, "--spread must be a finite number >= 2");
  const PostprocessChoice choice = check_postprocess(
      o.postprocess, /*allow_none=*/true, o.min_angle_given ? std::optional<double>(o.min_angle) : std::nullopt);
  if (choice == PostprocessChoice::None)
    return o.dim == 3 ? run<3, DynamicQuadtree<3>>(o, *dist, "quadtree", kOctree3dCost)
                      : run<2, DynamicQuadtree<2>>(o, *dist, "quadtree", kQuadtree2dCost);
  if (o.dim != 2) throw InputError(Kind::Malformed, "--postprocess " + o.postprocess + " meshes in 2D only (--dim 2)");
  if (choice == PostprocessChoice::Quadtree)
    return run<2, DynamicMesh>(o, *dist, "quadtree mesh", kQuadtreeMeshCost,
                               MeshOptions{.postprocess = Postprocess::Quadtree});
  return run<2, DynamicMesh>(o, *dist, "hpu mesh", kHpuDynamicCost,
                             MeshOptions{.postprocess = Postprocess::Hpu,
                                         .min_angle = o.min_angle_given ? o.min_angle : kHpuDefaultMinAngle});
}

}  // namespace dynmesh::tool
