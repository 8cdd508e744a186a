// `dynmesh stability`: the trace-distance experiment of docs/FORMATS.md, "`dynmesh
// stability`", on a distribution or on the user's own data. With `--dist`, builds the tree on N points of a distribution,
// then measures U single-point updates (alternating deletions of a present point and
// insertions of a new point of the same distribution, one propagation each). With
// `--points POINTS --edits FILE`, builds on POINTS (read, boxed and located as `quadtree` and
// `mesh` read them: initial_points.hpp) and measures every edit of FILE as one propagation.
// Either way it appends one CSV row per update. With `--postprocess quadtree` or `hpu` (2D)
// the structure is a DynamicMesh, and with `--postprocess quadtree` in 3D a DynamicOctreeMesh:
// QuadTreeRefine and the mesh run in one trace, so each row's trace_distance and seconds are
// the whole update, tree and mesh (docs/FORMATS.md, "`dynmesh stability`").
//
// The N initial points and the insertion pool come from one call generate(dist, N + U, seed,
// spread): the generators return their points in a seeded random order, so the first N are
// a sample of the distribution and the rest are fresh points of the same distribution,
// distinct from them. log2_spread is exact for every row (SpreadTracker keeps the
// closest-pair distance up to date; see spread_tracker.hpp).
//
// Before generating or reading anything, the memory guard (memory_guard.hpp) refuses a run
// whose structure (N points and the U/2 insertions, or the points of POINTS and the `+` lines
// of FILE; plus the final from-scratch check) cannot fit in memory, unless --force; reading,
// the build and the final check show their elapsed time on stderr (progress.hpp). The rows
// are appended only once every update has been made, so a bad file (one line naming file and
// line) leaves the CSV as it was.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/detail/mesh_grid.hpp"
#include "dynmesh/detail/quadtree_mesh_rules.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/dynamic_octree_mesh.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/io.hpp"
#include "initial_points.hpp"
#include "input_labels.hpp"
#include "memory_guard.hpp"
#include "postprocess_option.hpp"
#include "progress.hpp"
#include "spread_tracker.hpp"
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
inline DynamicOctreeMesh build(const Box<3>& box, std::span<const Point<3>> pts, const DynamicOctreeMesh*,
                               const MeshOptions&) {
  return DynamicOctreeMesh(box, pts);
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
inline Verification verify_final(const DynamicOctreeMesh& mesh, double) { return verify(mesh); }

// One row's fields after `dist,dim,n,`: log2_spread,op,trace_distance,seconds and the line end.
std::string row_tail(double log2_spread, EditOp op, const UpdateStats& stats) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%.4f,%s,%llu,%.9g\n", log2_spread, op == EditOp::Insert ? "insert" : "delete",
                static_cast<unsigned long long>(stats.trace_distance), stats.seconds);
  return buf;
}

// What a run measured, for its summary on stdout.
struct Measured {
  std::string dist;  // the `dist` column: a distribution's name, or POINTS' base name
  std::size_t n = 0;
  double initial_spread = 0;
  std::size_t updates = 0;
  const char* noun = "updates";  // what the updates are called ("updates", "edits")
  std::uint64_t total_distance = 0;
};

// Appends the rows, then verifies the structure against a from-scratch build on its final
// points (history independence, on every run: the rows are written first, so a failure keeps
// them for inspection), prints the summary and draws --plot. `what` names the structure on
// stdout ("quadtree", "quadtree mesh").
template <std::size_t d, class Structure>
int finish(const StabilityOptions& o, const Structure& structure, const char* what, const MeshOptions& mesh_options,
           const Measured& m, const std::string& rows) {
  append_csv(o.csv, rows);
  Verification v;
  {
    const Phase checking("checking against a from-scratch build of the " + std::to_string(structure.size()) +
                         " final points");
    const double bound = mesh_options.postprocess == Postprocess::Hpu ? mesh_options.min_angle : kQuadtreeMinAngle;
    v = verify_final(structure, o.min_angle_given ? o.min_angle : bound);
  }
  if (!v.ok) throw InvariantError("verification failed after the updates: " + v.problem);

  std::printf("stability: %s, %s %zuD, n = %zu, log2(L/s) = %.2f, %zu %s, mean trace distance %.1f, "
              "verified against a from-scratch build; rows appended to %s\n",
              what, m.dist.c_str(), d, m.n, m.initial_spread, m.updates, m.noun,
              m.updates ? static_cast<double>(m.total_distance) / static_cast<double>(m.updates) : 0.0,
              o.csv.c_str());
  if (!o.plot.empty()) {
    plot_stability_csv(o.csv, o.plot);
    std::printf("plot: %s\n", o.plot.c_str());
  }
  return 0;
}

// --dist: `cost` is the structure's memory.
template <std::size_t d, class Structure>
int run(const StabilityOptions& o, Distribution dist, const char* what, const MemoryCost& cost,
        const MeshOptions& mesh_options = {}) {
  // On stderr, a 3D tree is called what it is.
  const char* structure_name = d == 3 && std::is_same_v<Structure, DynamicQuadtree<d>> ? "octree" : what;
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
  Measured m{std::string(distribution_name(dist)), o.n, driver.log2_spread(), o.updates, "updates", 0};
  const std::string prefix = m.dist + ',' + std::to_string(d) + ',' + std::to_string(o.n) + ',';
  std::string rows;
  {
    Progress progress("updates", o.updates);
    for (std::size_t u = 0; u < o.updates; ++u) {
      const auto step = driver.step();
      rows += prefix;
      rows += row_tail(step.log2_spread, step.op, step.stats);
      m.total_distance += step.stats.trace_distance;
      progress.tick(u + 1);
    }
  }
  return finish<d>(o, structure, what, mesh_options, m, rows);
}

// --points POINTS: the `dist` column, POINTS' base name without its extension. A name the
// CSV cannot hold as a plain field is refused rather than altered.
std::string points_label(const std::string& path) {
  const std::string label = std::filesystem::path(path).stem().string();
  if (label.find_first_of(",\"\r\n") != std::string::npos)
    throw InputError(Kind::Malformed,
                     "its name '" + label + "' holds a comma, quote or line break, which cannot be the CSV's dist "
                                            "field; rename or link the file",
                     path);
  return label;
}

// The level below which a structure's build reports a point named alone as unresolvable
// (initial_points.hpp): the tree's grid, or the mesh's coarser resolution level.
template <class Structure, std::size_t d>
int resolution_level(const Box<d>& box) {
  if constexpr (!std::is_same_v<Structure, DynamicQuadtree<d>>) {
    const int level = dynmesh::detail::BasicMeshGrid<d>::resolution_level(box);
    return level >= 2 ? level : -1;
  } else {
    return kMaxLevel;
  }
}

// --points POINTS --edits FILE: every edit of FILE, in order, one propagation each; one row per
// edit. Errors name POINTS or FILE and the line, as `quadtree` and `mesh` name them.
// The memory guard ran before (run_stability_points: it needs the points' dimension).
template <std::size_t d, class Structure>
int run_points(const StabilityOptions& o, Columns columns, const char* what, const MeshOptions& mesh_options = {}) {
  // On stderr, a 3D tree is called what it is.
  const char* structure_name = d == 3 && std::is_same_v<Structure, DynamicQuadtree<d>> ? "octree" : what;
  const std::string label = points_label(o.points);
  std::optional<Phase> reading(std::in_place, "reading " + o.points);
  const InitialPoints<d> initial = read_initial_points<d>(o.points, o.box, /*skip_duplicates=*/false, columns);
  // The whole script before building, so a malformed script fails fast.
  const EditScript<d> script = read_edits_file<d>(o.edits);
  reading.reset();

  std::optional<Structure> built;
  {
    const Phase building(std::string("building the ") + structure_name + " of " +
                         std::to_string(initial.file.points.size()) + " points");
    try {
      built.emplace(build(initial.box, std::span<const Point<d>>(initial.file.points),
                          static_cast<const Structure*>(nullptr), mesh_options));
    } catch (const InputError& e) {
      rethrow_construction_error<d>(e, initial, resolution_level<Structure>(initial.box));
    }
  }
  Structure& structure = *built;
  SpreadTracker<d> spread(structure.points(), initial.box.side);
  Measured m{label, initial.file.points.size(), spread.log2_spread(), script.edits.size(), "edits", 0};
  const std::string prefix = m.dist + ',' + std::to_string(d) + ',' + std::to_string(m.n) + ',';
  std::string rows;
  {
    Progress progress("edits", script.edits.size());
    for (std::size_t i = 0; i < script.edits.size(); ++i) {
      const Edit<d>& e = script.edits[i];
      std::optional<PointId> inserted;
      try {
        if (e.op == EditOp::Insert)
          inserted = structure.insert(e.point);
        else
          structure.erase(e.point);
      } catch (const InputError& err) {
        throw edit_error<d>(script, i, err);
      }
      if (inserted) {
        spread.inserted(*inserted, e.point);
      } else {
        const std::optional<std::size_t> k = spread.find(e.point);
        if (!k) throw InvariantError("the erased point " + to_string<d>(e.point) + " was not among the present points");
        spread.erased_at(*k);
      }
      rows += prefix;
      rows += row_tail(spread.log2_spread(), e.op, structure.last_update());
      m.total_distance += structure.last_update().trace_distance;
      progress.tick(i + 1);
    }
  }
  return finish<d>(o, structure, what, mesh_options, m, rows);
}

// The hpu mesh at --min-angle, or at the default bound.
MeshOptions hpu_mesh_options(const StabilityOptions& o) {
  return MeshOptions{.postprocess = Postprocess::Hpu, .min_angle = o.min_angle_given ? o.min_angle : kHpuDefaultMinAngle};
}

// In 3D the mesh is the octree's (--postprocess quadtree): hpu and --min-angle are 2D only, a
// malformed command line (exit status 2) as for `dynmesh mesh`.
void require_3d_options(const StabilityOptions& o) {
  const std::string why = mesh_options_2d_only(o.postprocess, o.min_angle_given, /*svg=*/false);
  if (!why.empty()) throw CommandLineError(why);
}

// --points: the dimension is --dim's, else a .node header's, else the count of numbers on the
// first line of plain text (as `dynmesh quadtree` and `dynmesh mesh`: initial_points.hpp).
int run_stability_points(const StabilityOptions& o, PostprocessChoice choice) {
  const PointFileShape shape = points_shape(o.points, o.dim_given ? o.dim : 0, [&o, choice](int dim) {
    if (dim == 3) require_3d_options(o);
    if (o.force) return;
    // As `quadtree` and `mesh` count: the lines of POINTS and the `+` lines of FILE.
    const std::uint64_t points = points_held(o.points, o.edits);
    const char* what = dim == 3 ? (choice == PostprocessChoice::None ? "octree" : "octree mesh")
                       : choice == PostprocessChoice::None     ? "quadtree"
                       : choice == PostprocessChoice::Quadtree ? "quadtree mesh"
                                                               : "hpu mesh";
    const MemoryCost cost = dim == 3 ? (choice == PostprocessChoice::None ? kOctree3dCost : kOctreeMeshCost)
                            : choice == PostprocessChoice::None     ? kQuadtree2dCost
                            : choice == PostprocessChoice::Quadtree ? kQuadtreeMeshCost
                                                                    : hpu_dynamic_cost(hpu_mesh_options(o).min_angle);
    guard_memory(std::string("building the ") + what + " of " + std::to_string(points) + " points",
                 estimated_bytes(cost, points, /*check=*/true));
  });
  const Columns columns = shape.columns;
  if (shape.dim == 3) {
    require_3d_options(o);  // again: a pipe's dimension is known only now
    if (choice == PostprocessChoice::None) return run_points<3, DynamicQuadtree<3>>(o, columns, "quadtree");
    return run_points<3, DynamicOctreeMesh>(o, columns, "octree mesh");
  }
  if (choice == PostprocessChoice::None) return run_points<2, DynamicQuadtree<2>>(o, columns, "quadtree");
  if (choice == PostprocessChoice::Quadtree)
    return run_points<2, DynamicMesh>(o, columns, "quadtree mesh", MeshOptions{.postprocess = Postprocess::Quadtree});
  return run_points<2, DynamicMesh>(o, columns, "hpu mesh", hpu_mesh_options(o));
}

}  // namespace

int run_stability(const StabilityOptions& o) {
  if (o.points_given) {
    const PostprocessChoice choice = check_postprocess(
        o.postprocess, /*allow_none=*/true, o.min_angle_given ? std::optional<double>(o.min_angle) : std::nullopt);
    return run_stability_points(o, choice);
  }
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
  if (o.dim == 3) {
    require_3d_options(o);
    return run<3, DynamicOctreeMesh>(o, *dist, "octree mesh", kOctreeMeshCost);
  }
  if (choice == PostprocessChoice::Quadtree)
    return run<2, DynamicMesh>(o, *dist, "quadtree mesh", kQuadtreeMeshCost,
                               MeshOptions{.postprocess = Postprocess::Quadtree});
  const MeshOptions hpu = hpu_mesh_options(o);
  return run<2, DynamicMesh>(o, *dist, "hpu mesh", hpu_dynamic_cost(hpu.min_angle), hpu);
}

}  // namespace dynmesh::tool
