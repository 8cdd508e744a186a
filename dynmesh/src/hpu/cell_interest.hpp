// cell_interest.hpp (private) — what a step of the hpu program used of a cell it read, and
// where a read moves when its leaf splits or merges away.
//
// Purpose: a step's read of a cell is a read of a projection (Engine::read_many with
// affected() and follow(); step_rounds.hpp). The projection is the box of the vertices the
// step's searches could see, kept per cell in 256ths of the cell's width (CellInterest, in
// the frame CellFrame gives). A vertex entering or leaving the cell outside that box is no
// change, nor is anything in a cell the step used none of (interest_changed). A leaf that
// split or merged away moves the read to the cell that now holds the used box, when the
// vertices inside it are the same (follow_cell); else the step re-runs.
// Invariants: a vertex inside a box is inside the box's 256ths in every frame (one fixed,
// monotone sequence of double operations per coordinate); a followed interest holds every
// vertex the old one held, however the two frames round; an interest of the whole cell
// never follows (an insertion's leaf, which the insertion writes).
// Complexity: interest_changed O(capacity) per changed leaf; follow_cell O(levels moved ×
// capacity).
// Paper: Acar & Hudson, Section 4 (change propagation re-runs the reads whose values
// changed); docs/HPU_ON_CELLS.md, "A step depends on part of each cell: reads of a
// projection".
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>

#include "dynmesh/box.hpp"
#include "dynmesh/point.hpp"
#include "hpu/bucket_tree.hpp"
#include "hpu/cell_store.hpp"

namespace dynmesh::detail {

/// What a step's answers used of a cell it read: the vertices inside a box of the cell, in
/// 256ths of its width on each axis (inclusive; x0 > x1: none, only the cell's kind). The
/// default is all of it. A vertex's 256th is found by one fixed sequence of double operations,
/// monotone in its coordinate, so a vertex inside a box is inside the box's 256ths.
struct CellInterest {
  std::uint8_t x0 = 0, y0 = 0, x1 = 255, y1 = 255;
  static constexpr CellInterest none() noexcept { return {1, 1, 0, 0}; }
};

static_assert(BucketTree::kMaxLevel < 1023, "CellFrame's widths are normal powers of two");

/// A cell's frame for CellInterest: its lower corner and 256 over its width.
struct CellFrame {
  double ox, oy, inv;
  CellFrame(const Box<2>& box, const CellKey& k) {
    // box.side · 2^-level: a product by a power of two is rounded as ldexp's result is, and
    // costs a multiply rather than a libm call (one frame per cell a step read).
    const double w = box.side * std::bit_cast<double>(static_cast<std::uint64_t>(1023 - k.level) << 52);
    ox = box.origin[0] + grid_double(k.ix) * w;
    oy = box.origin[1] + grid_double(k.iy) * w;
    inv = 256.0 / w;
  }
  static std::uint8_t part(double x, double o, double inv) noexcept {
    // ⌊t⌋ clamped to [0, 255], by truncation, which is the floor for t > 0 (as position()).
    const double t = (x - o) * inv;
    return static_cast<std::uint8_t>(!(t > 0) ? 0 : t >= 255 ? 255 : static_cast<int>(t));  // x, o finite
  }
  /// The 256ths of the box [x0, x1] × [y0, y1] (any box: parts outside the cell clamp).
  CellInterest interest(double x0, double y0, double x1, double y1) const noexcept {
    return {part(x0, ox, inv), part(y0, oy, inv), part(x1, ox, inv), part(y1, oy, inv)};
  }
  bool inside(const CellInterest& in, const Point<2>& p) const noexcept {
    const std::uint8_t x = part(p[0], ox, inv), y = part(p[1], oy, inv);
    return x >= in.x0 && x <= in.x1 && y >= in.y0 && y <= in.y1;
  }
};

/// Are the vertices of `a` inside `in` of frame f the same, in order, as those of `b` inside
/// it that `keep` accepts?
template <class Keep>
bool same_inside(const CellFrame& f, const CellInterest& in, const CellState& a, const CellState& b, Keep&& keep) {
  std::size_t i = 0, j = 0;
  for (;; ++i, ++j) {
    while (i < a.count && !f.inside(in, a.items[i]->p)) ++i;
    while (j < b.count && !(f.inside(in, b.items[j]->p) && keep(b.items[j]))) ++j;
    if (i == a.count || j == b.count) return (i == a.count) == (j == b.count);
    if (a.items[i] != b.items[j]) return false;
  }
}

/// Does replacing a cell's value `before` by `after` change what `in` used of it? Nothing
/// when it used none of it: its answers held whatever the cell held (a split cell whose
/// children a search all pruned, a cell a round read that the run then did not use). Else a
/// change of kind always does; for two leaves, the vertices inside the box, in order, must be
/// the same.
inline bool interest_changed(const Box<2>& box, const CellKey& k, const CellInterest& in, const CellState& before,
                             const CellState& after) {
  if (in.x0 > in.x1) return false;
  if (before.kind != after.kind) return true;
  if (before.kind != CellState::Leaf) return before != after;
  return !same_inside(CellFrame(box, k), in, before, after, [](const CellVertex*) { return true; });
}

/// A read of a leaf n with interest `in` whose value at the read's time is no longer a leaf:
/// the cell that now holds what it used, or null (then the step re-runs). `seen`: n's leaf
/// when the step ran; value(node): a cell's value at the read's time (null: none). On
/// success, *in becomes the interest in the returned cell's frame.
///   - n split: down to the leaf inside which the used box lies, at least one 256th from its
///     children's border on each axis, so that every vertex inside it lies in that child
///     (the rounding of a 256th is far below one).
///   - n absent (a merge above it): up to the leaf that holds its region now.
/// Either way the cell must hold, inside the used box in n's frame, exactly the vertices
/// `seen` held there, in order: the step's answers used no others (each vertex they used
/// lies inside it), so they stand. The new interest widens the old one by a 256th on each
/// side of each level's change of frame: a vertex inside the old is inside it however the
/// two frames round.
/// An interest of the whole cell (an insertion's leaf, which the insertion writes) never
/// follows.
template <class Value>
CellNode* follow_cell(const Box<2>& box, const CellDirectory& dir, CellNode* n, CellInterest* in,
                      const CellState& seen, const CellState& now, Value&& value) {
  const CellInterest u = *in;
  if (seen.kind != CellState::Leaf || now.kind == CellState::Leaf) return nullptr;
  if (u.x0 == 0 && u.y0 == 0 && u.x1 == 255 && u.y1 == 255) return nullptr;
  const auto clamp = [](int v) { return static_cast<std::uint8_t>(std::clamp(v, 0, 255)); };
  CellInterest b = u;
  CellNode* d = n;
  const CellState* s = nullptr;
  if (now.kind == CellState::Split) {
    for (;;) {
      const int qx = b.x1 <= 126 ? 0 : b.x0 >= 129 ? 1 : -1;
      const int qy = b.y1 <= 126 ? 0 : b.y0 >= 129 ? 1 : -1;
      if (qx < 0 || qy < 0) return nullptr;
      d = d->child[static_cast<unsigned>(qx | (qy << 1))];
      if (!d) return nullptr;
      b = CellInterest{clamp(2 * b.x0 - 256 * qx - 1), clamp(2 * b.y0 - 256 * qy - 1),
                       clamp(2 * b.x1 + 2 - 256 * qx), clamp(2 * b.y1 + 2 - 256 * qy)};
      s = value(d);
      if (!s || s->kind == CellState::Absent) return nullptr;
      if (s->kind == CellState::Leaf) break;
    }
    if (!same_inside(CellFrame(box, n->key), u, seen, *s, [](const CellVertex*) { return true; })) return nullptr;
  } else {
    for (;;) {
      if (!d->parent) return nullptr;
      const int qx = static_cast<int>(d->key.ix & 1), qy = static_cast<int>(d->key.iy & 1);
      b = CellInterest{clamp((b.x0 + 256 * qx) / 2 - 1), clamp((b.y0 + 256 * qy) / 2 - 1),
                       clamp((b.x1 + 1 + 256 * qx) / 2 + 1), clamp((b.y1 + 1 + 256 * qy) / 2 + 1)};
      d = d->parent;
      s = value(d);
      if (!s) return nullptr;
      if (s->kind == CellState::Leaf) break;
      if (s->kind == CellState::Split) return nullptr;
    }
    // The leaf holds the vertices of its siblings' regions too: only n's count.
    const CellKey& k = n->key;
    const auto in_n = [&](const CellVertex* v) { return k.contains(CellDirectory::cell_at(dir.position(v->p), k.level)); };
    if (!same_inside(CellFrame(box, k), u, seen, *s, in_n)) return nullptr;
  }
  *in = b;
  return d;
}


}  // namespace dynmesh::detail
