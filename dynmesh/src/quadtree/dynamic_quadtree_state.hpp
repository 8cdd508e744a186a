// dynamic_quadtree_state.hpp (private) — the state behind DynamicQuadtree: QuadtreeCore
// running QuadTreeRefine alone, and the tree read out of the directory's slots.
//
// Purpose: DynamicQuadtree's implementation object. It is a header rather than part of
// dynamic_quadtree.cpp so that the white-box tests (tests/dynmesh/, through the test-only
// DynamicQuadtreeTestAccess) can reach the engine and the directory, corrupt them and see
// the checkers fail.
// Invariants: QuadtreeCore's (quadtree_core.hpp).
// Complexity: for_each_leaf O(|T*|); is_leaf O(1) and leaf_at O(depth) directory probes.
// Paper: Acar & Hudson, Section 2 (the tree T*) and Section 4.
#pragma once

#include <cstddef>

#include "dynmesh/cell.hpp"
#include "quadtree/quadtree_core.hpp"

namespace dynmesh::detail {

template <std::size_t d>
struct DynamicState : QuadtreeCore<d> {
  using QuadtreeCore<d>::QuadtreeCore;

  /// f(leaf, its point list) for the leaves of T* under `from` (the root by default; a
  /// leaf or a split cell of T*).
  template <class F>
  void for_each_leaf(F&& f, const CellId<d>& from = CellId<d>::root()) const {
    this->for_each_leaf_of([&](const CellId<d>& c) { return this->is_split(c); },
                           [&](const CellId<d>& c) { f(c, this->points_in(c)); }, from);
  }
  bool is_leaf(const CellId<d>& c) const {
    return valid(c) && (c.level == 0 || this->is_split(parent(c))) && !this->is_split(c);
  }
  CellId<d> leaf_at(const Position<d>& q) const {
    CellId<d> c = CellId<d>::root();
    while (this->is_split(c)) c = cell_of(q, c.level + 1);
    return c;
  }
};

}  // namespace dynmesh::detail
