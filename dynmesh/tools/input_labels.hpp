// input_labels.hpp (private to the command) — the library's errors re-labelled with the
// file and line they come from. The library names point or edit indices (InputError::
// point_indices()); the commands know the lines, so they turn indices into "FILE:LINE".
// Shared by `quadtree` and `mesh` (construction errors: initial_points.hpp).
// Invariants: every error thrown here names a file; a line when one is known.
// Complexity: O(1).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/io.hpp"

namespace dynmesh::tool {

/// An error raised without a file name gets `file` (and `line` when it has none).
[[noreturn]] inline void rethrow_in(const InputError& e, const std::string& file, std::size_t line = 0) {
  if (!e.file().empty()) throw e;
  throw InputError(e.kind(), e.text(), file, e.line() != 0 ? e.line() : line);
}

/// The box of `--box o1 o2 [o3] L`.
template <std::size_t d>
Box<d> box_from_option(const std::vector<double>& values) {
  if (values.size() != d + 1)
    throw InputError(InputError::Kind::Malformed,
                     "--box needs " + std::to_string(d + 1) + " numbers (o1 o2" + (d == 3 ? " o3" : "") + " L) for " +
                         std::to_string(d) + "D points, got " + std::to_string(values.size()));
  Box<d> box;
  for (std::size_t a = 0; a < d; ++a) box.origin[a] = values[a];
  box.side = values[d];
  validate_box(box);
  return box;
}

/// The error of edit i of the script as "FILE:LINE: insert (x, y): why" (the point only
/// once; an "edit K: " prefix from a batch dropped, the line names the edit).
template <std::size_t d>
InputError edit_error(const EditScript<d>& script, std::size_t i, const InputError& err) {
  const Edit<d>& e = script.edits[i];
  std::string why = err.text();
  if (why.rfind("edit ", 0) == 0)
    if (const auto colon = why.find(": "); colon != std::string::npos) why.erase(0, colon + 2);
  const std::string point = to_string<d>(e.point);
  std::string text = e.op == EditOp::Insert ? "insert" : "delete";
  if (why.find(point) == std::string::npos) text += " " + point;
  // The box is fixed when the tree is built: a point outside it needs a larger --box.
  if (err.kind() == InputError::Kind::OutsideBox && e.op == EditOp::Insert)
    why += std::string("; the box is derived from the initial points unless --box gives it: pass --box ") +
           (d == 2 ? "o1 o2 L" : "o1 o2 o3 L") + " with a box that holds every point the edits insert";
  return InputError(err.kind(), text + ": " + why, script.name, script.lines[i]);
}

}  // namespace dynmesh::tool
