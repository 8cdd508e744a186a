// hpu_cells_state.hpp (private) — the mutator's side of the self-adjusting hpu mesh: what
// HpuCellsProgram reads as its input and writes as its output, all outside the trace.
//
// Purpose: one owner for the input list (HpuInputs: the inputs and their side midpoints in
// insertion order), the cell store (CellDirectory, and InputCells: the box's corners and the
// list's vertices as the store's base values), the Steiner vertices (SteinerVertices) and
// the change feed (HpuMeshFeed). DynamicMesh,
// the program's tests and its benchmark all hold one, declared before their engine so that it
// outlives the trace that refers to it, and the program after the engine; the owner calls
// feed.close() before its engine goes (the blocks the engine destroys then log nothing).
// Invariants (check_invariants): those of HpuInputs, InputCells and HpuMeshFeed; the store's
// base values hold exactly the corners and the list's vertices.
// Complexity: commit O(k (lg n + path)) for k edits, as HpuInputs, plus O(1) store cells each.
// Paper: Acar & Hudson, Section 4 (the mutator's changes, then change propagation).
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include <sac/engine.hpp>

#include "dynmesh/box.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/point.hpp"
#include "hpu/cell_store.hpp"
#include "hpu/hpu_inputs.hpp"
#include "hpu/hpu_mesh_feed.hpp"
#include "hpu/steiner_vertices.hpp"

namespace dynmesh::detail {

struct HpuCellsState {
  explicit HpuCellsState(const Box<2>& box)
      : inputs(box), cells(box), input_cells(cells),
        corners{std::make_unique<CellVertex>(Point<2>{box.origin[0], box.origin[1]}),
                std::make_unique<CellVertex>(Point<2>{box.origin[0] + box.side, box.origin[1]}),
                std::make_unique<CellVertex>(Point<2>{box.origin[0] + box.side, box.origin[1] + box.side}),
                std::make_unique<CellVertex>(Point<2>{box.origin[0], box.origin[1] + box.side})} {}
  HpuCellsState(const HpuCellsState&) = delete;
  HpuCellsState& operator=(const HpuCellsState&) = delete;

  /// Puts the corners into the store (once, before the first commit) and ties the list to it.
  void start(sac::Engine& rt) {
    for (const auto& c : corners) input_cells.insert(rt, c.get());
    inputs.attach(&input_cells);
  }
  std::array<const CellVertex*, 4> corner_vertices() const noexcept {
    return {corners[0].get(), corners[1].get(), corners[2].get(), corners[3].get()};
  }
  /// The edits' plan (validated by the caller's rules; changes nothing), then its commit.
  HpuInputs::Plan plan(std::span<const Edit<2>> edits) const { return inputs.plan(edits); }
  void commit(sac::Engine& rt, const HpuInputs::Plan& plan) { inputs.commit(rt, plan); }
  /// After the propagation that follows a commit: frees the list nodes that left, and the
  /// Steiner vertices no trace record holds any more.
  void release(sac::Engine& rt) {
    inputs.release(rt);
    steiner.collect();
  }

  std::size_t bytes() const noexcept {
    return inputs.bytes() + cells.bytes() + input_cells.bytes() + steiner.bytes();
  }
  void check_invariants(std::span<const Point<2>> present) const {
    feed.check_invariants();
    inputs.check_invariants(present);
    input_cells.check_invariants();
    steiner.check_invariants();
  }

  HpuMeshFeed feed;
  SteinerVertices steiner;  // the off-centers and side midpoints, one object per point
  HpuInputs inputs;
  CellDirectory cells;
  InputCells input_cells;
  std::array<std::unique_ptr<CellVertex>, 4> corners;  // the box's, in the store from the start
};

}  // namespace dynmesh::detail
