// dynmesh/detail/touching_leaves.hpp — the leaves that touch a leaf, in any tree given by its
// split predicate.
//
// Purpose: one walk for the static tree's neighbours(), its checker's separation and
// crowding pass, and the dynamic tree's neighbours(), which differ only in how they tell a
// split cell (a hash set, a directory of versioned slots) and in what they do with each leaf.
// Every leaf touching leaf a lies in a same-level neighbour nb of a: either nb is split and
// the leaf is one of nb's descendants that touches a, or nb is not split and the leaf is
// the one containing nb (nb itself when its parent is split, else its nearest such
// ancestor).
// Invariants: is_split describes a tree (the parent of a split cell is split) and a is one
// of its leaves. A leaf may be visited more than once (through several nb); callers dedupe.
// Complexity: O(3^d + number of split cells inside split neighbours that touch a), which is
// O(3^d·2^d) in a graded tree; plus O(depth) for each coarse neighbour.
// Paper: none (tree navigation; docs/DESIGN.md, "The quadtree contract", for touching).
#pragma once

#include <vector>

#include "dynmesh/cell.hpp"

namespace dynmesh::detail {

/// The leaf containing the unsplit cell c: c when its parent is split (or c is the root),
/// else the nearest ancestor whose parent is split.
template <std::size_t d, class IsSplit>
CellId<d> leaf_containing(IsSplit&& is_split, CellId<d> c) {
  while (c.level > 0 && !is_split(parent(c))) c = parent(c);
  return c;
}

/// For each same-level neighbour nb of leaf a: if nb is split and enter(nb) agrees,
/// on_leaf(leaf) for every leaf inside nb that touches a; if nb is not split,
/// on_coarse(leaf containing nb, nb). `stack` is scratch space (left empty).
template <std::size_t d, class IsSplit, class Enter, class OnLeaf, class OnCoarse>
void for_each_touching_leaf(const CellId<d>& a, IsSplit&& is_split, Enter&& enter, OnLeaf&& on_leaf,
                            OnCoarse&& on_coarse, std::vector<CellId<d>>& stack) {
  for_each_neighbour(a, [&](const CellId<d>& nb) {
    if (!is_split(nb)) {
      on_coarse(leaf_containing<d>(is_split, nb), nb);
      return;
    }
    if (!enter(nb)) return;
    stack.push_back(nb);
    while (!stack.empty()) {
      const CellId<d> x = stack.back();
      stack.pop_back();
      for (const CellId<d>& ch : children(x)) {
        if (!touches(ch, a)) continue;
        if (is_split(ch))
          stack.push_back(ch);
        else
          on_leaf(ch);
      }
    }
  });
}

}  // namespace dynmesh::detail
