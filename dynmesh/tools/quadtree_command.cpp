// `dynmesh quadtree`: build T* on a point file, apply an edit script dynamically, write the
// final leaves as `.cells` (docs/FORMATS.md). Every error names the file and line it
// comes from; the tree's own errors (which name point indices or nothing) are re-labelled
// here with the line of the point file or of the edit script. The point file is read,
// stripped of later copies on request (--duplicates skip) and located by initial_points.hpp,
// shared with `dynmesh mesh`. As there, --check runs before anything is written, and the
// outputs (.cells, --svg) are written aside and renamed into place together
// (atomic_file.hpp), so a failed run leaves the files of an earlier run as they were.
// Before anything is read, the memory guard (memory_guard.hpp) compares the build's estimated
// peak with the memory available and refuses a build that cannot fit, unless --force; the
// long phases (reading, building, --check) show their elapsed time on stderr (progress.hpp).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "edit_runner.hpp"
#include "initial_points.hpp"
#include "input_labels.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/io.hpp"
#include "dynmesh/svg.hpp"
#include "memory_guard.hpp"
#include "progress.hpp"
#include "verify.hpp"

namespace dynmesh::tool {
namespace {

using Kind = InputError::Kind;

// What the tree is called in messages: T* is a quadtree in 2D and an octree in 3D.
const char* tree_name(int dim) { return dim == 3 ? "octree" : "quadtree"; }

template <std::size_t d>
int run(const QuadtreeOptions& o, Columns columns) {
  if (d != 2 && !o.svg.empty())
    throw InputError(Kind::Malformed, "--svg draws 2D trees only; " + o.points + " holds " + std::to_string(d) +
                                          "D points");

  std::optional<Phase> reading(std::in_place, "reading " + o.points);
  const InitialPoints<d> initial = read_initial_points<d>(o.points, o.box, o.skip_duplicates, columns);
  const PointFile<d>& file = initial.file;
  const Box<d>& box = initial.box;
  // Read the whole script before building, so a malformed script fails fast.
  const EditScript<d> script = o.edits.empty() ? EditScript<d>{} : read_edits_file<d>(o.edits);
  reading.reset();

  std::optional<DynamicQuadtree<d>> built;
  {
    const Phase building(std::string("building the ") + tree_name(d) + " of " + std::to_string(file.points.size()) +
                         " points");
    try {
      built.emplace(box, std::span<const Point<d>>(file.points));
    } catch (const InputError& e) {
      rethrow_construction_error<d>(e, initial);
    }
  }
  DynamicQuadtree<d>& tree = *built;

  apply_edits<d>(tree, script, o.batch);

  if (o.check) {
    Verification v;
    {
      const Phase checking("checking against a from-scratch build of the " + std::to_string(tree.size()) +
                           " final points");
      v = verify<d>(tree);
    }
    if (!v.ok) throw InvariantError("--check failed: " + v.problem);
  }
  const std::vector<Leaf<d>> leaves = tree.leaves();
  std::vector<Point<d>> pts;
  if (!o.svg.empty())
    for (const auto& entry : tree.points()) pts.push_back(entry.second);
  // The tree's trace is most of the process's memory: formatting the outputs beside it put
  // their size on top of the peak (560 bytes a point of peak RSS in 2D at 10^6). From here
  // on only the leaves and the points are needed.
  built.reset();

  AtomicOutputs out;
  out.add(o.cells, format_cells<d>(box, leaves));
  if constexpr (d == 2) {
    if (!o.svg.empty()) {
      SvgOptions svg_options;
      svg_options.point_radius_px = o.svg_point_radius;
      svg_options.max_points = o.svg_max_points;
      std::ostringstream svg;
      write_svg(svg, box, leaves, pts, svg_options);
      out.add(o.svg, svg.str());
    }
  }
  out.commit();
  if (o.skip_duplicates) std::printf("duplicates: skipped %zu later copies\n", initial.duplicates_skipped);
  return 0;
}

}  // namespace

int run_quadtree(const QuadtreeOptions& o) {
  // The dimension: --dim, else a `.node` header's, else the count of numbers on the first
  // line of plain text (with --dim, a `.node` header that announces another is an error
  // naming its line).
  const PointFileShape shape = points_shape(o.points, o.dim_given ? o.dim : 0, [&o](int dim) {
    if (o.force) return;
    const std::uint64_t points = points_held(o.points, o.edits);
    guard_memory(std::string("building the ") + tree_name(dim) + " of " + std::to_string(points) + " points" +
                     (o.check ? " with --check" : ""),
                 estimated_bytes(dim == 3 ? kOctree3dCost : kQuadtree2dCost, points, o.check));
  });
  return shape.dim == 3 ? run<3>(o, shape.columns) : run<2>(o, shape.columns);
}

}  // namespace dynmesh::tool
