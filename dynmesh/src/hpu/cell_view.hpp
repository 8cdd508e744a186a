// cell_view.hpp (private) — how a step of the self-adjusting hpu program reads the cells:
// its view of the cell store, the rounds of reads that fill it, and the insertion step.
//
// Purpose: a step (a vertex's first class, an entry's collect, one try of a pair, a vertex's
// final triangles) runs the static questions of cell_questions.hpp on a CellView. The view
// holds the cells the step has read and answers searches from them. A cell it has not read
// is looked up with Engine::peek (its value now, recorded nothing), so every answer is
// exact, and the cell becomes pending: the run "fails" and must not act. run_step() then
// reads the pending cells as one Engine::read_many (one trace event, up to 16 cells), nested
// in the reads before, and runs the step again; that run takes the answers of the run
// before (the same values: kept()) and does the step's writes. So a step is one read of
// exactly the cells its answers depend on (1.01 rounds per step measured: bench/RESULTS.md),
// and it re-runs only when what it used of one of them changes: each read is a read of a
// projection (Engine::read_many with affected()) that keeps, per cell, the box of the
// vertices the step's searches could see (CellInterest); a vertex entering or leaving the
// cell outside it is no change, nor is anything in a cell the step used none of. A leaf that
// split or merged away moves the read to the cell that now holds the used box, when the
// vertices inside it are the same (follow_cell, Engine::read_many's follow()); else the step
// re-runs. The runtime asks when propagation reaches the read, so a change undone before
// then costs nothing.
// Which cells a step depends on: the leaves a search hands vertices from, a split cell whose
// children it all prunes, and the leaf an insertion locates. The leaves tile the region the
// search covers, so any change there (a vertex, a split, a merge) changes one of them; the
// cells above them are split, implied by the leaves. A bounded search starts at the cells as
// wide as its box (at most 2 × 2), each at its deepest present ancestor.
// Invariants: a view's read cells are read by the step's enclosing reads; a run that did
// not fail used no cell beyond them. A round that runs right after the run it was issued by
// keeps that run's view, peeked cells included (no write between: a step writes only in its
// last run); any other (a round re-run by change propagation) rebuilds the view, looking the
// outer rounds' values up with Engine::current. A failed run writes, allocates and issues
// nothing but the next round; a run that did not fail answers as the static tree on the same
// vertices, and done() has then given every cell of every round its used box: a vertex the
// answers depend on lies inside the used box of the leaf that holds it.
// Complexity: a step's questions once, on peeked cells (each peek a directory lookup and a
// version walk); O(1) cells per question in a graded mesh.
// Paper: Acar & Hudson, Section 4; Hammer, Acar & Chen (CEAL, 2009) for reads as the unit of
// re-execution.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include <sac/engine.hpp>
#include <sac/mod.hpp>

#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"
#include "hpu/cell_questions.hpp"
#include "hpu/cell_store.hpp"

namespace dynmesh::detail {

inline constexpr std::size_t kCellsPerRead = 16;  // Engine::read_many's most

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

class CellView {
 public:
  using V = const CellVertex*;

  CellView(sac::Engine& e, CellDirectory& dir) : e_(&e), dir_(&dir), box_(dir.box()) {
    dir.claim_marks(this);
    for (int l = 0; l <= BucketTree::kMaxLevel; ++l) width_[l] = std::ldexp(box_.side, -l);
  }
  ~CellView() { dir_->release_marks(this); }
  CellView(const CellView&) = delete;
  CellView& operator=(const CellView&) = delete;

  // ---------------------------------------------------------------- filling

  /// A new round. `parent`: the round this one is nested in (null for a step's first run).
  /// When the view's last run was that round's (it needed cells and issued this one), the
  /// view keeps its cells, peeked ones included (no write between), and returns true: the
  /// caller adds only this round's, and kept() tells the step that its last run's answers
  /// stand (see kept()). Otherwise it forgets every cell and returns false.
  bool reset(const void* parent = nullptr, std::uint32_t serial = 0) {
    kept_ = parent != nullptr ? parent == owner_ : serial != 0 && serial == owner_serial_;
    owner_ = nullptr;
    owner_serial_ = 0;
    if (kept_) return true;
    pending_.clear();
    if (++gen_ == 0) {
      dir_->clear_marks();
      start_memo_ = {};
      gen_ = 1;
    }
    read_.clear();
    settled_ = 0;
    visited_.clear();
    return false;
  }

  /// A cell the step has read, with its value now, and where the step's read keeps what the
  /// step used of it (CellInterest; written by done()).
  void add(CellNode* n, const CellState* s, CellInterest* used) { read_.push_back({n, s, used}); }

  /// After the adds: the cells added since the last call become read, and so do their
  /// ancestors, as splits (a read leaf or split has a split parent); the cells still
  /// pending are those no round has read yet.
  void settle() {
    const std::span<const ReadCell> fresh(read_.data() + settled_, read_.size() - settled_);
    settled_ = read_.size();
    for (const auto& [n, s, used] : fresh) {
      CellMark& x = mark(n);
      x.tag = tag_of(s);
      x.state = s;
      x.read = true;
    }
    for (const auto& [n, s, used] : fresh) {
      if (s->kind == CellState::Absent) continue;
      for (CellNode* a = n->parent; a; a = a->parent) {
        CellMark& x = mark(a);
        if (x.read && x.tag == Tag::Split) break;
        if (x.read && x.tag != Tag::Unknown)
          throw InvariantError("dynmesh: CellView: a cell read below a leaf or an absent cell");
        x.tag = Tag::Split;
        x.read = true;
      }
    }
    std::erase_if(pending_, [&](CellNode* n) { return mark(n).read; });
  }

  // ---------------------------------------------------------------- the store interface

  /// Did the run need a cell that no round of the step has read? Its answers are exact all
  /// the same (the cell was peeked), but it must not act on them: its next round reads
  /// pending().
  bool failed() const noexcept { return !pending_.empty(); }
  /// After a step's questions: !failed(), and then the step's reads learn what it used of
  /// each cell (CellInterest), so that a change elsewhere in a cell does not re-run it. A
  /// step calls it once its answers stand, before it acts.
  bool done() {
    if (failed()) return false;
    if (!visited_.empty()) throw InvariantError("dynmesh: CellView: a search's use was not stated");
    for (const ReadCell& r : read_) {
      if (!r.used) continue;
      const CellMark& x = mark(r.node);
      CellInterest in = CellInterest::none();
      if (x.all) {
        in = CellInterest{};
      } else if (x.bx0 <= x.bx1) {
        in = CellFrame(box_, r.node->key).interest(x.bx0, x.by0, x.bx1, x.by1);
      }
      *r.used = in;
    }
    return true;
  }
  /// Is this run's view the one the step's last run had, the cells it peeked now read? Then
  /// that run's answers are this run's (the same values at the same time: nothing ran
  /// between), and the step takes them from its scratch instead of asking again.
  bool kept() const noexcept { return kept_; }
  std::span<CellNode* const> pending() const noexcept { return pending_; }
  std::size_t leaves_read() const noexcept { return leaves_read_; }

  /// What the steps' reads cost so far: rounds issued (read_many events) and cells in them.
  struct Counts {
    std::uint64_t rounds = 0, cells = 0;
  };
  const Counts& counts() const noexcept { return counts_; }
  void count_round(std::size_t cells) noexcept {
    ++counts_.rounds;
    counts_.cells += cells;
  }

  double margin_for(const Point<2>& c, double r) const noexcept { return dir_->margin_for(c, r); }

  /// BucketTree::search on the cells as they are now. `scale` is not used (the interface of
  /// cell_questions.hpp).
  /// The question then says what its answer used of the leaves it met: used_within() or
  /// used_all().
  template <class Keep, class F>
  void search(const Point<2>& focus, double /*scale*/, double margin, Keep&& keep, F&& f) const {
    auto* self = const_cast<CellView*>(this);
    self->run_search(focus, margin, keep, f, false, 0.0);
  }
  /// search() for a keep() that accepts no cell whose box (widened by margin) lies farther
  /// than radius() from focus, where radius() only shrinks as the search goes (a nearest
  /// search). It visits the same cells in the same order as search(), but from focus's leaf
  /// upwards: the descent from the root goes to that leaf first, then visits the other
  /// children of each cell on the way back up, so walking up from the leaf and visiting
  /// them level by level is the same search. It stops climbing once a cell holds the disc
  /// (focus, radius()) with room: every cell outside it is one keep() would refuse. The
  /// cells on the path to the root are what search() would have walked for nothing.
  template <class Keep, class F, class Radius>
  void search_near(const Point<2>& focus, double /*scale*/, double margin, Keep&& keep, F&& f,
                   Radius&& radius) const {
    const_cast<CellView*>(this)->run_search_near(focus, margin, keep, f, radius);
  }
  /// search() over the cells that cover the box [focus ± R] only (starts_for), for a
  /// keep() that accepts no cell beyond it. Unlike search_within(), the question states
  /// afterwards what its answer used, as after search(); more search_from()s may come first.
  template <class Keep, class F>
  void search_from(const Point<2>& focus, double R, double margin, Keep&& keep, F&& f) const {
    auto* self = const_cast<CellView*>(this);
    self->run_search(focus, margin, keep, f, false, R);
  }
  /// The last search()'s answer used the vertices within r of c only (of the leaves it met).
  void used_within(const Point<2>& c, double r) const {
    auto* self = const_cast<CellView*>(this);
    const double R = r * (1 + 0x1p-20) + cellq::ulp_room(c);
    for (CellNode* n : visited_) self->widen(self->mark(n), c, R);
    self->visited_.clear();
  }
  /// The last search()'s answer used the vertices inside the closed box [x0, x1] × [y0, y1]
  /// only (of the leaves it met). A degenerate box (a stretch of a box side) is exact: a
  /// vertex's 256th and the box's come from the same monotone function.
  void used_box(double x0, double y0, double x1, double y1) const {
    auto* self = const_cast<CellView*>(this);
    for (CellNode* n : visited_) widen(self->mark(n), x0, y0, x1, y1);
    self->visited_.clear();
  }
  /// The last search()'s answer may depend on any vertex of the leaves it met.
  void used_all() const {
    auto* self = const_cast<CellView*>(this);
    for (CellNode* n : visited_) self->mark(n).all = true;
    self->visited_.clear();
  }

  /// search() for a keep() that accepts no cell farther than radius from focus: it starts at
  /// the cells around that disc's box (starts_for), not at the root.
  template <class Keep, class F>
  void search_within(const Point<2>& focus, double radius, double /*scale*/, double margin, Keep&& keep,
                     F&& f) const {
    auto* self = const_cast<CellView*>(this);
    self->run_search(focus, margin, keep, f, true, radius + 3 * margin);
  }

  /// After a run that needed cells: it was the run of round `self`, which issues the next.
  void hand_over(const void* self) noexcept { owner_ = self; }
  /// The same after a step's first run: its first round names the run by the serial.
  std::uint32_t hand_over_root() noexcept {
    if (++serial_ == 0) serial_ = 1;
    return owner_serial_ = serial_;
  }

  /// The leaf that holds grid position q, and its value (pending when unread).
  std::pair<CellNode*, const CellState*> locate(const std::array<std::uint64_t, 2>& q, double /*scale*/) {
    CellNode* n = deepest_present(CellDirectory::cell_at(q, BucketTree::kMaxLevel));
    CellMark& x = resolve(n);
    if (x.tag != Tag::Leaf) throw InvariantError("dynmesh: CellView: a position with no leaf");
    touch(n, x);
    x.all = true;  // the insertion writes the leaf's next value: all its vertices
    return {n, x.state};
  }

  /// A cell's box, widened by margin.
  void cell_box(const CellKey& k, double margin, double& x0, double& y0, double& x1, double& y1) const noexcept {
    const double w = width_[k.level];
    x0 = box_.origin[0] + grid_double(k.ix) * w - margin, x1 = x0 + w + 2 * margin;
    y0 = box_.origin[1] + grid_double(k.iy) * w - margin, y1 = y0 + w + 2 * margin;
  }

 private:
  using Tag = CellTag;

  static Tag tag_of(const CellState* s) noexcept {
    if (!s || s->kind == CellState::Absent) return Tag::Absent;
    return s->kind == CellState::Leaf ? Tag::Leaf : Tag::Split;
  }

  /// n's mark in this view: what the step knows of the cell (its node holds it, so a search
  /// reaches it by the directory's child links, with no lookup).
  CellMark& mark(CellNode* n) const noexcept {
    CellMark& x = n->mark;
    if (x.gen != gen_) {
      x = CellMark{};
      x.gen = gen_;
    }
    return x;
  }

  /// n's mark, its state looked up now if the view does not know it: a peek, which records
  /// nothing (the runtime's guess for a prefetch); a search that uses the cell makes it
  /// pending, and the step reads it before it acts.
  CellMark& resolve(CellNode* n) {
    CellMark& x = mark(n);
    if (x.tag == Tag::Unknown) {
      x.state = e_->peek(n->state);
      x.tag = tag_of(x.state);
    }
    return x;
  }

  void touch(CellNode* n, CellMark& x) {
    if (x.read || x.pending) return;
    x.pending = true;
    pending_.push_back(n);
  }

  /// The deepest cell on k's path to the root that is not absent (a leaf or a split; the
  /// path is split cells, then the leaf, then absent ones, and a cell never made is absent).
  CellNode* deepest_present(const CellKey& k) {
    // From the last answer by the tree's links, when it is near k: a step's searches are
    // mostly in one region, where the nodes are in the cache, but a lookup of a key not
    // looked up before misses on the table however hot its node is (bench/RESULTS.md, "The
    // program's searches start from their last answer"). Else by the lookups.
    if (finger_) {
      const CellKey& f = finger_->key;
      const int m = std::min(f.level, k.level);
      const std::uint64_t dx = (f.ix >> (f.level - m)) ^ (k.ix >> (k.level - m));
      const std::uint64_t dy = (f.iy >> (f.level - m)) ^ (k.iy >> (k.level - m));
      const int c = m - static_cast<int>(std::bit_width(dx | dy));  // their common ancestor's level
      if ((f.level - c) + (k.level - c) <= kNearSteps) {
        finger_ = walk_from(finger_, c, k);
#ifdef SAC_DEBUG_CHECKS
        if (finger_ != probe_deepest_present(k))
          throw InvariantError("dynmesh: CellView: the walk from the last answer and the lookups disagree");
#endif
        return finger_;
      }
    }
    return finger_ = probe_deepest_present(k);
  }
  static constexpr int kNearSteps = 12;

  /// deepest_present(k) from n, whose ancestor at level c (≤ k.level) is k's: up to that
  /// ancestor, up past absent cells, then down k's path while the cells are split.
  CellNode* walk_from(CellNode* n, int c, const CellKey& k) {
    while (n->key.level > c) n = n->parent;
    while (resolve(n).tag == Tag::Absent) n = n->parent;  // the root is present
    while (n->key.level < k.level && resolve(n).tag == Tag::Split) {
      const int s = k.level - n->key.level - 1;
      n = n->child[((k.ix >> s) & 1) | (((k.iy >> s) & 1) << 1)];
      if (!n) throw InvariantError("dynmesh: CellView: a split cell without its children's nodes");
    }
    return n;
  }

  /// deepest_present(k) by directory lookups: a binary search over the levels.
  CellNode* probe_deepest_present(const CellKey& k) {
    int lo = 0, hi = k.level;  // the root is present
    const auto present = [&](int level) {
      const int s = k.level - level;
      CellNode* n = dir_->find(CellKey{level, k.ix >> s, k.iy >> s});
      return n && resolve(n).tag != Tag::Absent;
    };
    // The last answer's level first: a step's searches are mostly in one region, so its
    // leaves' level and the one below usually settle it in two lookups.
    if (const int g = std::min(finger_ ? finger_->key.level : 0, k.level); g > 0) {
      if (present(g)) {
        lo = g;
        if (g < hi) {
          if (present(g + 1)) lo = g + 1;
          else hi = g;
        }
      } else {
        hi = g - 1;
        if (present(hi)) lo = hi;
      }
    }
    while (lo < hi) {
      const int mid = (lo + hi + 1) / 2;
      if (present(mid))
        lo = mid;
      else
        hi = mid - 1;
    }
    const int s = k.level - lo;
    return dir_->find(CellKey{lo, k.ix >> s, k.iy >> s});
  }

  template <class Keep, class F>
  void run_search(const Point<2>& focus, double margin, Keep& keep, F& f, bool bounded, double R) {
    // Only a search_from() may come between a search and the statement of its use.
    if (!visited_.empty() && !(searched_from_ && !bounded && R != 0))
      throw InvariantError("dynmesh: CellView: a search's use was not stated");
    searched_from_ = !bounded && R != 0;
    bool stop = false;
    if (!bounded && R == 0) {
      region_ = false;
      return search_node(root(), focus, margin, keep, f, stop);
    }
    // search_from() records the leaves it meets until the question states its use. A
    // bounded search's answer uses the vertices within R of the focus only
    // (cell_questions.hpp): the box around that disc, widened past the rounding of the
    // questions' distances.
    region_ = bounded;
    if (bounded) {
      region_c_ = focus;
      region_r_ = R * (1 + 0x1p-20) + cellq::ulp_room(focus);
    }
    std::array<CellNode*, 4> starts;
    const std::size_t n = starts_for(focus, R, starts);
    for (std::size_t i = 0; i < n && !stop; ++i) search_node(starts[i], focus, margin, keep, f, stop);
  }

  template <class Keep, class F, class Radius>
  void run_search_near(const Point<2>& focus, double margin, Keep& keep, F& f, Radius& radius) {
    const auto from_root = [&] { run_search(focus, margin, keep, f, false, 0.0); };
    const double x1 = box_.origin[0] + box_.side, y1 = box_.origin[1] + box_.side;
    if (!(focus[0] >= box_.origin[0] && focus[0] <= x1 && focus[1] >= box_.origin[1] && focus[1] <= y1))
      return from_root();
    CellNode* leaf = deepest_present(CellDirectory::cell_at(dir_->position(focus), BucketTree::kMaxLevel));
    // search() descends by the side tests of search_node on doubles, and prunes by keep():
    // the walk up is the same search only if those lead to this leaf (a focus on a cell's
    // boundary may have its grid position on the other side).
    for (CellNode* n = leaf;; n = n->parent) {
      double bx0, by0, bx1, by1;
      cell_box(n->key, margin, bx0, by0, bx1, by1);
      if (!keep(bx0, by0, bx1, by1)) return from_root();
      if (!n->parent) break;
      if (n->parent->child[near_child(n->parent->key, focus)] != n) return from_root();
    }
    if (!visited_.empty()) throw InvariantError("dynmesh: CellView: a search's use was not stated");
    searched_from_ = false;
    region_ = false;
    bool stop = false;
    search_node(leaf, focus, margin, keep, f, stop);
    for (CellNode* n = leaf; n->parent && !stop; n = n->parent) {
      double bx0, by0, bx1, by1;
      cell_box(n->key, 0.0, bx0, by0, bx1, by1);
      const double inside = std::min({focus[0] - bx0, bx1 - focus[0], focus[1] - by0, by1 - focus[1]});
      if (inside > (radius() + 2 * margin) * (1 + 0x1p-30)) break;
      CellNode* p = n->parent;
      const auto order = child_order(p->key, focus);
      for (int i = 1; i < 4 && !stop; ++i) {
        CellNode* ch = p->child[order[i]];
        if (!ch) throw InvariantError("dynmesh: CellView: a split cell without its children's nodes");
        search_node(ch, focus, margin, keep, f, stop);
      }
    }
  }

  /// The children of a split cell k in the order search_node visits them: the one holding
  /// focus's side in x and y first, then its x neighbour, its y neighbour, and the opposite
  /// one (nearest first for four equal squares, by their centres' distance, as BucketTree).
  std::array<unsigned, 4> child_order(const CellKey& k, const Point<2>& focus) const noexcept {
    const double w = width_[k.level];
    const double mx = box_.origin[0] + (grid_double(k.ix) + 0.5) * w;
    const double my = box_.origin[1] + (grid_double(k.iy) + 0.5) * w;
    const unsigned hx = focus[0] >= mx ? 1 : 0, hy = focus[1] >= my ? 1 : 0;
    const unsigned near = hx | (hy << 1);
    const bool x_first = std::abs(focus[0] - mx) >= std::abs(focus[1] - my);
    return {near, near ^ (x_first ? 2u : 1u), near ^ (x_first ? 1u : 2u), near ^ 3u};
  }
  unsigned near_child(const CellKey& k, const Point<2>& focus) const noexcept { return child_order(k, focus)[0]; }

  /// x's box of used vertices grows by the box around the disc (c, R).
  static void widen(CellMark& x, const Point<2>& c, double R) noexcept {
    widen(x, c[0] - R, c[1] - R, c[0] + R, c[1] + R);
  }
  /// x's box of used vertices grows by the box [x0, x1] × [y0, y1].
  static void widen(CellMark& x, double x0, double y0, double x1, double y1) noexcept {
    x.bx0 = std::min(x.bx0, x0), x.by0 = std::min(x.by0, y0);
    x.bx1 = std::max(x.bx1, x1), x.by1 = std::max(x.by1, y1);
  }

  /// Where a search of the box [focus ± R] starts: the cells of the finest level as wide as
  /// the box (at most 2 × 2 of them cover it), each replaced by its deepest present ancestor
  /// (itself when present), without repeats, nearest to the focus first. Starting at the
  /// smallest cell holding the whole box instead walked down from the root whenever the box
  /// straddled a coarse cell's boundary.
  std::size_t starts_for(const Point<2>& focus, double R, std::array<CellNode*, 4>& out) {
    const auto a = dir_->position(Point<2>{focus[0] - R, focus[1] - R});
    const auto b = dir_->position(Point<2>{focus[0] + R, focus[1] + R});
    const int g = BucketTree::kMaxLevel - std::bit_width(std::max(b[0] - a[0], b[1] - a[1]));
    const int s = BucketTree::kMaxLevel - g;
    std::array<double, 4> dist{};
    std::size_t n = 0;
    for (std::uint64_t iy = a[1] >> s; iy <= b[1] >> s; ++iy)
      for (std::uint64_t ix = a[0] >> s; ix <= b[0] >> s; ++ix) {
        CellNode* k = start_cell(CellKey{g, ix, iy});
        const auto end = out.begin() + static_cast<std::ptrdiff_t>(n);
        if (std::find(out.begin(), end, k) != end) continue;
        double x0, y0, x1, y1;
        cell_box(k->key, 0.0, x0, y0, x1, y1);
        const double d = BucketTree::box_distance2(focus, x0, y0, x1, y1);
        std::size_t i = n++;
        for (; i > 0 && dist[i - 1] > d; --i) {  // insertion: stable, so ties keep the scan order
          out[i] = out[i - 1];
          dist[i] = dist[i - 1];
        }
        out[i] = k;
        dist[i] = d;
      }
    return n;
  }

  /// deepest_present(k) for a start cell, remembered for the step: the probes of one
  /// step (a star walk's left searches around one vertex) ask for the same few cells of a
  /// level again and again, and the walk to each costs a resolve() per cell on its way.
  CellNode* start_cell(const CellKey& k) {
    StartMemo& m = start_memo_[(k.ix * 5 + k.iy * 3 + static_cast<std::uint64_t>(k.level)) & (kStartMemo - 1)];
    if (m.gen == gen_ && m.level == k.level && m.ix == k.ix && m.iy == k.iy) {
#ifdef SAC_DEBUG_CHECKS
      if (m.node != probe_deepest_present(k))
        throw InvariantError("dynmesh: CellView: a remembered start cell and the lookups disagree");
#endif
      return m.node;
    }
    m = StartMemo{gen_, k.level, k.ix, k.iy, deepest_present(k)};
    return m.node;
  }

  CellNode* root() {
    if (!root_) root_ = dir_->find(CellKey{});
    return root_;
  }

  /// A search's visit of k. Its answers depend on the leaves it hands vertices from, and on
  /// a split cell whose children it all prunes; those cells are used (touched). Every other
  /// cell it passes is an ancestor of a used one, known split through it.
  template <class Keep, class F>
  void search_node(CellNode* n, const Point<2>& focus, double margin, Keep& keep, F& f, bool& stop) {
    const CellKey& k = n->key;
    double x0, y0, x1, y1;
    cell_box(k, margin, x0, y0, x1, y1);
    if (!keep(x0, y0, x1, y1)) return;
    CellMark& x = resolve(n);
    switch (x.tag) {
      case Tag::Leaf: {
        ++leaves_read_;
        touch(n, x);
        if (region_) widen(x, region_c_, region_r_);
        else visited_.push_back(n);
        const CellState& s = *x.state;
        for (std::size_t i = 0; i < s.count; ++i)
          if (f(s.items[i])) {
            stop = true;
            return;
          }
        return;
      }
      case Tag::Split: {
        const std::size_t before = leaves_read_;
        for (const unsigned c : child_order(k, focus)) {
          if (stop) return;
          CellNode* ch = n->child[c];
          if (!ch) throw InvariantError("dynmesh: CellView: a split cell without its children's nodes");
          search_node(ch, focus, margin, keep, f, stop);
        }
        if (leaves_read_ == before) touch(n, x);
        return;
      }
      case Tag::Absent:
        throw InvariantError("dynmesh: CellView: an absent cell under a split one");
      case Tag::Unknown:
        break;
    }
  }

  sac::Engine* e_;
  CellDirectory* dir_;
  Box<2> box_;
  std::array<double, BucketTree::kMaxLevel + 1> width_{};
  CellNode* root_ = nullptr;  // the directory's, made before any step runs
  std::uint32_t gen_ = 0;     // the marks of this generation are this step's
  struct ReadCell {
    CellNode* node;
    const CellState* state;
    CellInterest* used;  // in the closure of the round that read it
  };
  std::vector<ReadCell> read_;
  std::size_t settled_ = 0;  // read_'s prefix settle() has seen
  std::vector<CellNode*> pending_;
  // The running search's disc of used vertices (region_), or, for a search() without one,
  // the leaves it met, until the question states its use.
  bool region_ = false;
  Point<2> region_c_{};
  double region_r_ = 0;
  std::vector<CellNode*> visited_;
  bool searched_from_ = false;  // the last search was a search_from()
  // deepest_present's last answer: where the next starts (its walk, or its lookups at the
  // answer's level first), a hint only, whose state is looked up again.
  CellNode* finger_ = nullptr;
  // start_cell()'s answers of this generation, by key (direct-mapped).
  struct StartMemo {
    std::uint32_t gen = 0;
    int level = 0;
    std::uint64_t ix = 0, iy = 0;
    CellNode* node = nullptr;
  };
  static constexpr std::size_t kStartMemo = 16;
  std::array<StartMemo, kStartMemo> start_memo_{};
  std::size_t leaves_read_ = 0;
  Counts counts_;
  // The run the view was last filled for, when it failed (see reset()).
  const void* owner_ = nullptr;     // a round, by its closure
  std::uint32_t owner_serial_ = 0;  // or the step's first run, by its serial
  std::uint32_t serial_ = 0;
  bool kept_ = false;
};

// -------------------------------------------------------------------- rounds of reads

/// The part of a round's closure that later rounds look through: the round before, and how
/// many cells this one read (the cells follow it in CellRound).
struct CellRoundHead {
  const CellRoundHead* parent;
  std::uint16_t n;    // cells read
  std::uint16_t cap;  // N
  std::uint32_t serial;  // a first round: its step's run that issued it (CellView::hand_over)
};

/// A round's cells, and what the step used of each (the read's own state: the step's last
/// run that did not fail wrote it, CellView::done(); the read asks it on every change).
template <std::size_t N>
struct CellRoundCells {
  CellRoundHead head;
  mutable std::array<CellNode*, N> cells;  // follow() may move a read to another cell
  mutable std::array<CellInterest, N> used;
};

inline CellNode* const* cells_of(const CellRoundHead* h) {
  // Every CellRound<Step, N> starts with a CellRoundCells<N> (standard layout), whose cells
  // follow the head at the same offset for every N, and whose `used` follows the N cells.
  return reinterpret_cast<const CellRoundCells<1>*>(h)->cells.data();
}
inline CellInterest* used_of(const CellRoundHead* h) {
  return const_cast<CellInterest*>(reinterpret_cast<const CellInterest*>(cells_of(h) + h->cap));
}

template <class Step>
void issue_round(sac::Engine& e, const Step& step, const CellRoundHead* parent, std::uint32_t serial,
                 std::span<CellNode* const> misses);

/// One round of a step: reads its cells, then runs the step on the view of all its rounds.
/// A read of a projection (sac::Engine::read_many): a change of a cell re-runs it only when
/// it changes what the step used of that cell.
template <class Step, std::size_t N>
struct CellRound {
  CellRoundCells<N> c;
  Step step;

  void operator()(sac::Engine& e, std::span<const CellState* const> vals) const {
    CellView& v = *step.view(e);
    const bool kept = v.reset(c.head.parent, c.head.serial);  // the view before is still there
    for (std::uint32_t i = 0; i < c.head.n; ++i) v.add(c.cells[i], vals[i], &c.used[i]);
    if (!kept)
      for (const CellRoundHead* r = c.head.parent; r; r = r->parent) {
        CellNode* const* cells = cells_of(r);
        CellInterest* used = used_of(r);
        for (std::uint32_t i = 0; i < r->n; ++i) v.add(cells[i], &e.current(cells[i]->state), &used[i]);
      }
    v.settle();
    if (!step.run(e, v)) {
      v.hand_over(&c.head);
      issue_round(e, step, &c.head, 0, v.pending());
    }
  }

  bool affected(std::size_t i, const CellState& before, const CellState& after) const {
    return interest_changed(step.box(), c.cells[i]->key, c.used[i], before, after);
  }

  /// A leaf that split or merged away: its read moves to the cell that holds what the step
  /// used of it, when that is unchanged (follow_cell).
  const sac::Mod<CellState>* follow(std::size_t i, const CellState& seen, const CellState& now,
                                    const sac::Engine::At& at) const {
    CellInterest in = c.used[i];
    CellNode* d = follow_cell(step.box(), step.dir(), c.cells[i], &in, seen, now,
                              [&](const CellNode* x) { return at.value(x->state); });
    if (!d) return nullptr;
    c.cells[i] = d;
    c.used[i] = in;
    return &d->state;
  }
};

template <class Step, std::size_t N>
void issue_round_n(sac::Engine& e, const Step& step, const CellRoundHead* parent, std::uint32_t serial,
                   std::span<CellNode* const> misses) {
  static_assert(std::is_standard_layout_v<CellRoundCells<N>>);
  static_assert(offsetof(CellRoundCells<N>, cells) == offsetof(CellRoundCells<1>, cells));
  static_assert(offsetof(CellRoundCells<N>, used) == offsetof(CellRoundCells<N>, cells) + N * sizeof(CellNode*));
  CellRound<Step, N> r{{{parent, static_cast<std::uint16_t>(misses.size()), static_cast<std::uint16_t>(N), serial}, {}, {}},
                       step};
  std::array<const sac::Mod<CellState>*, N> mods;
  for (std::size_t i = 0; i < misses.size(); ++i) {
    r.c.cells[i] = misses[i];
    mods[i] = &misses[i]->state;
  }
  e.read_many(std::span<const sac::Mod<CellState>* const>(mods.data(), misses.size()), std::move(r));
}

template <class Step>
void issue_round(sac::Engine& e, const Step& step, const CellRoundHead* parent, std::uint32_t serial,
                 std::span<CellNode* const> misses) {
  if (misses.empty()) throw InvariantError("dynmesh: a step failed without a pending cell");
  if (misses.size() > kCellsPerRead) misses = misses.first(kCellsPerRead);  // the rest next round
  step.view(e)->count_round(misses.size());
  if (misses.size() <= 2) return issue_round_n<Step, 2>(e, step, parent, serial, misses);
  if (misses.size() <= 4) return issue_round_n<Step, 4>(e, step, parent, serial, misses);
  if (misses.size() <= 8) return issue_round_n<Step, 8>(e, step, parent, serial, misses);
  issue_round_n<Step, kCellsPerRead>(e, step, parent, serial, misses);
}

/// Runs a step: step.run(e, view) on an empty view, which peeks at every cell the step's
/// questions use and so fails (unless they use none); then, round after round, on the
/// cells it used, read, until a run does not fail (one round when it uses at most 16
/// cells). A run in a kept view (CellView::kept()) takes the answers of the run before from
/// the step's scratch. Step: copyable (it is each round's closure), with CellView*
/// view(Engine&), const Box<2>& box() (the store's) and bool run(Engine&, CellView&). run
/// returns false when CellView::done() does (the view failed), and has then written,
/// allocated and issued nothing; otherwise it does the step's effects, in this order: writes and
/// allocations first (they use the view and the program's scratch), then the reads, memo
/// calls and run_step calls that continue the program (a write after an issued call would
/// run that call on the spot, and it would reuse the view).
template <class Step>
void run_step(sac::Engine& e, const Step& step) {
  CellView& v = *step.view(e);
  v.reset();
  if (!step.run(e, v)) issue_round(e, step, nullptr, v.hand_over_root(), v.pending());
}

}  // namespace dynmesh::detail
