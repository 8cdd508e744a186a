// dynmesh/tools/edit_runner.hpp — an edit script applied to a dynamic structure (private to
// the tool).
//
// Purpose: `quadtree` and `mesh` (2D and 3D) apply `--edits` the same way: each edit is one
// propagation (insert or erase by coordinates), or `--batch K` groups K consecutive edits
// into one apply(); a failed edit is reported by its line in the script (edit_error), and the
// edit count shows on stderr (progress.hpp). What a command does after each propagation (the
// change feed, the propagation figures) is its `after` callback.
// Invariants: `after` runs once per successful propagation, in order, after the structure
// has propagated; an error leaves the structure as the library leaves it (unchanged: every
// update is failure-atomic) and no later edit is applied.
// Complexity: one propagation per edit or per batch, plus O(1) bookkeeping each.
// Paper: none.
#pragma once

#include <algorithm>
#include <cstddef>
#include <span>

#include "dynmesh/edit.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/io.hpp"
#include "input_labels.hpp"
#include "progress.hpp"

namespace dynmesh::tool {

/// Applies script.edits to `structure` (any of DynamicQuadtree<d>, DynamicMesh,
/// DynamicOctreeMesh): one propagation per edit when batch == 0, else per batch of `batch`
/// edits. Calls after() after each propagation. Throws InputError naming the script's line.
template <std::size_t d, class Structure, class After>
void apply_edits(Structure& structure, const EditScript<d>& script, std::size_t batch, After&& after) {
  const std::vector<Edit<d>>& edits = script.edits;
  if (edits.empty()) return;
  const std::span<const Edit<d>> all(edits);
  Progress progress("edits", edits.size());
  if (batch == 0) {
    for (std::size_t i = 0; i < edits.size(); ++i) {
      const Edit<d>& e = edits[i];
      try {
        if (e.op == EditOp::Insert)
          structure.insert(e.point);
        else
          structure.erase(e.point);
      } catch (const InputError& err) {
        throw edit_error<d>(script, i, err);
      }
      after();
      progress.tick(i + 1);
    }
    return;
  }
  for (std::size_t i = 0; i < edits.size(); i += batch) {
    const std::size_t k = std::min(batch, edits.size() - i);
    try {
      structure.apply(all.subspan(i, k));
    } catch (const InputError& err) {
      // apply() names the failing edit by its index in the batch.
      if (err.point_indices().empty()) rethrow_in(err, script.name);
      throw edit_error<d>(script, i + err.point_indices().back(), err);
    }
    after();
    progress.tick(i + k);
  }
}

/// apply_edits with nothing to do after a propagation.
template <std::size_t d, class Structure>
void apply_edits(Structure& structure, const EditScript<d>& script, std::size_t batch) {
  apply_edits<d>(structure, script, batch, [] {});
}

}  // namespace dynmesh::tool
