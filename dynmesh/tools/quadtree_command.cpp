// `dynmesh quadtree`: build T* on a point file, apply an edit script dynamically, write the
// final leaves as `.cells` (shared/FORMATS.md). Every error names the file and line it
// comes from; the tree's own errors (which name point indices or nothing) are re-labelled
// here with the line of the point file or of the edit script.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/io.hpp"
#include "dynmesh/svg.hpp"
#include "progress.hpp"
#include "verify.hpp"

namespace dynmesh::tool {
namespace {

using Kind = InputError::Kind;

// An error raised without a file name gets `file` (and `line` when it has none).
[[noreturn]] void rethrow_in(const InputError& e, const std::string& file, std::size_t line = 0) {
  if (!e.file().empty()) throw e;
  throw InputError(e.kind(), e.text(), file, e.line() != 0 ? e.line() : line);
}

template <std::size_t d>
Box<d> box_from_option(const std::vector<double>& values) {
  if (values.size() != d + 1)
    throw InputError(Kind::Malformed, "--box needs " + std::to_string(d + 1) + " numbers (o1 o2" +
                                          (d == 3 ? " o3" : "") + " L) for " + std::to_string(d) +
                                          "D points, got " + std::to_string(values.size()));
  Box<d> box;
  for (std::size_t a = 0; a < d; ++a) box.origin[a] = values[a];
  box.side = values[d];
  validate_box(box);
  return box;
}

// The error of edit i of the script as "FILE:LINE: insert (x, y): why" (the point only
// once; an "edit K: " prefix from a batch dropped, the line names the edit).
template <std::size_t d>
InputError edit_error(const EditScript<d>& script, std::size_t i, const InputError& err) {
  const Edit<d>& e = script.edits[i];
  std::string why = err.text();
  if (why.rfind("edit ", 0) == 0)
    if (const auto colon = why.find(": "); colon != std::string::npos) why.erase(0, colon + 2);
  const std::string point = to_string<d>(e.point);
  std::string text = e.op == EditOp::Insert ? "insert" : "delete";
  if (why.find(point) == std::string::npos) text += " " + point;
  return InputError(err.kind(), text + ": " + why, script.name, script.lines[i]);
}

template <std::size_t d>
int run(const QuadtreeOptions& o) {
  if (d != 2 && !o.svg.empty())
    throw InputError(Kind::Malformed, "--svg draws 2D trees only; " + o.points + " holds " + std::to_string(d) +
                                          "D points");

  const PointFile<d> file = read_points_file<d>(o.points);
  Box<d> box;
  if (o.box.empty()) {
    try {
      box = derive_box<d>(file.points);
    } catch (const InputError& e) {
      rethrow_in(e, file.name);
    }
  } else {
    box = box_from_option<d>(o.box);
  }
  // Outside the box, NaN, duplicates: named by line here, before the tree sees the points.
  const std::vector<Position<d>> located = locate_points<d>(file, box);
  // Read the whole script before building, so a malformed script fails fast.
  const EditScript<d> script = o.edits.empty() ? EditScript<d>{} : read_edits_file<d>(o.edits);
  const std::vector<Edit<d>>& edits = script.edits;

  auto line_of = [&](std::size_t i) { return i < file.lines.size() ? file.lines[i] : std::size_t{0}; };
  std::optional<DynamicQuadtree<d>> built;
  try {
    built.emplace(box, std::span<const Point<d>>(file.points));
  } catch (const InputError& e) {
    // The tree names point indices (e.g. the pair closer than the resolution); name lines.
    std::vector<std::size_t> idx = e.point_indices();
    if (idx.empty()) rethrow_in(e, file.name);
    if (e.kind() == Kind::Resolution && idx.size() == 1) {
      // Name the partner too: a point within one grid unit per axis.
      for (std::size_t j = 0; j < located.size(); ++j) {
        bool near = j != idx[0];
        for (std::size_t a = 0; a < d && near; ++a) {
          const std::uint64_t x = located[j][a], y = located[idx[0]][a];
          near = (x > y ? x - y : y - x) <= 1;
        }
        if (near) {
          idx.push_back(j);
          break;
        }
      }
    }
    std::sort(idx.begin(), idx.end());
    const std::size_t last = idx.back();
    std::string text = e.text();
    // "point I: ..." names an index; the line number replaces it.
    for (const std::size_t i : idx) {
      const std::string prefix = "point " + std::to_string(i) + ": ";
      if (text.compare(0, prefix.size(), prefix) == 0) text.erase(0, prefix.size());
    }
    if (idx.size() > 1) {
      text += " (lines";
      for (std::size_t k = 0; k < idx.size(); ++k) text += (k ? ", " : " ") + std::to_string(line_of(idx[k]));
      text += ")";
    }
    throw InputError(e.kind(), text, file.name, line_of(last));
  }
  DynamicQuadtree<d>& tree = *built;

  if (!edits.empty()) {
    const std::span<const Edit<d>> all(edits);
    Progress progress("edits", edits.size());
    if (o.batch == 0) {
      for (std::size_t i = 0; i < edits.size(); ++i) {
        const Edit<d>& e = edits[i];
        try {
          if (e.op == EditOp::Insert)
            tree.insert(e.point);
          else
            tree.erase(e.point);
        } catch (const InputError& err) {
          throw edit_error<d>(script, i, err);
        }
        progress.tick(i + 1);
      }
    } else {
      for (std::size_t i = 0; i < edits.size(); i += o.batch) {
        const std::size_t k = std::min(o.batch, edits.size() - i);
        try {
          tree.apply(all.subspan(i, k));
        } catch (const InputError& err) {
          // apply() names the failing edit by its index in the batch.
          if (err.point_indices().empty()) rethrow_in(err, o.edits);
          throw edit_error<d>(script, i + err.point_indices().back(), err);
        }
        progress.tick(i + k);
      }
    }
  }

  const std::vector<Leaf<d>> leaves = tree.leaves();
  write_cells_file<d>(o.cells, box, leaves);
  if constexpr (d == 2) {
    if (!o.svg.empty()) {
      std::vector<Point<2>> pts;
      for (const auto& entry : tree.points()) pts.push_back(entry.second);
      write_svg_file(o.svg, box, leaves, pts);
    }
  }
  if (o.check) {
    const Verification v = verify<d>(tree);
    if (!v.ok) throw InvariantError("--check failed: " + v.problem);
  }
  return 0;
}

}  // namespace

int run_quadtree(const QuadtreeOptions& o) {
  int dim = o.dim;
  // A `.node` header announces its dimension; without --dim it decides, with --dim the two
  // must agree (read_node reports a mismatch, naming the header line).
  if (!o.dim_given && format_for_path(o.points) == PointFormat::Node) dim = node_file_dimension(o.points) == 3 ? 3 : 2;
  return dim == 3 ? run<3>(o) : run<2>(o);
}

}  // namespace dynmesh::tool
