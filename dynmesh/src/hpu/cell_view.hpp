// cell_view.hpp (private) — CellView: a step's view of the hpu cell store, on which the
// static questions of cell_questions.hpp run.
//
// Purpose: a step (a vertex's first class, an entry's collect, one try of a pair, an
// insertion, a vertex's final triangles) asks its questions of a CellView. The view holds the
// cells the step has read (the rounds of step_rounds.hpp add them) and answers searches from
// them. A cell it has not read is looked up with Engine::peek (its value now, recorded
// nothing), so every answer is exact, and the cell becomes pending: the run has failed and
// must not act; its next round reads pending(). Once a run's answers stand, done() gives each
// read cell what the answers used of it (CellInterest, cell_interest.hpp), which the round
// that read it keeps.
// Which cells a step depends on: the leaves a search hands vertices from, a split cell whose
// children it all prunes, and the leaf an insertion locates. The leaves tile the region the
// search covers, so any change there (a vertex, a split, a merge) changes one of them; the
// cells above them are split, implied by the leaves. A bounded search starts at the cells as
// wide as its box (at most 2 × 2), each at its deepest present ancestor.
// Invariants: a view's read cells are read by the step's enclosing reads; a run that did
// not fail used no cell beyond them. A view kept across runs (begin_run() returned true)
// holds the cells of the run that handed it over, peeked cells included; any other run
// starts from no cells. A run that did not fail answers as the static tree on the same
// vertices, and done() has then given every cell of every round its used box: a vertex the
// answers depend on lies inside the used box of the leaf that holds it. One view at a time
// per directory (its marks live on the directory's nodes).
// Complexity: a step's questions once, on peeked cells (each peek a directory lookup and a
// version walk); O(1) cells per question in a graded mesh.
// Paper: Acar & Hudson, Section 4; Hammer, Acar & Chen (CEAL, 2009) for reads as the unit of
// re-execution; docs/HPU_ON_CELLS.md, "A step peeks, then reads exactly the cells it used".
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <sac/engine.hpp>

#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"
#include "hpu/cell_interest.hpp"
#include "hpu/cell_questions.hpp"
#include "hpu/cell_store.hpp"

namespace dynmesh::detail {

class CellView {
 public:
  using V = const CellVertex*;

  CellView(sac::Engine& rt, CellDirectory& dir) : rt_(&rt), dir_(&dir), box_(dir.box()) {
    dir.claim_marks(this);
    for (int l = 0; l <= BucketTree::kMaxLevel; ++l) width_[l] = std::ldexp(box_.side, -l);
  }
  ~CellView() { dir_->release_marks(this); }
  CellView(const CellView&) = delete;
  CellView& operator=(const CellView&) = delete;

  // ---------------------------------------------------------------- filling

  /// The start of a run of a step (step_rounds.hpp's states): S1, a step's first run
  /// (no arguments), or S4, a round's run, where `parent` is the round this one is nested in
  /// (null for a first round, which names the run that issued it by `serial` instead). When
  /// the view's last run is the one that issued this round (S3 handed the view over to it),
  /// the view keeps its cells, peeked ones included (nothing was written between), and
  /// returns true: the caller adds only this round's cells, and kept() tells the step that
  /// its last run's answers stand. Otherwise it forgets every cell and returns false.
  bool begin_run(const void* parent = nullptr, std::uint32_t serial = 0) {
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
    run_search(focus, margin, keep, f, false, 0.0);
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
    run_search_near(focus, margin, keep, f, radius);
  }
  /// search() over the cells that cover the box [focus ± R] only (starts_for), for a
  /// keep() that accepts no cell beyond it. Unlike search_within(), the question states
  /// afterwards what its answer used, as after search(); more search_from()s may come first.
  template <class Keep, class F>
  void search_from(const Point<2>& focus, double R, double margin, Keep&& keep, F&& f) const {
    run_search(focus, margin, keep, f, false, R);
  }
  /// The last search()'s answer used the vertices within r of c only (of the leaves it met).
  void used_within(const Point<2>& c, double r) const {
    const double R = r * (1 + 0x1p-20) + cellq::ulp_room(c);
    for (CellNode* n : visited_) widen(mark(n), c, R);
    visited_.clear();
  }
  /// The last search()'s answer used the vertices inside the closed box [x0, x1] × [y0, y1]
  /// only (of the leaves it met). A degenerate box (a stretch of a box side) is exact: a
  /// vertex's 256th and the box's come from the same monotone function.
  void used_box(double x0, double y0, double x1, double y1) const {
    for (CellNode* n : visited_) widen(mark(n), x0, y0, x1, y1);
    visited_.clear();
  }
  /// The last search()'s answer may depend on any vertex of the leaves it met.
  void used_all() const {
    for (CellNode* n : visited_) mark(n).all = true;
    visited_.clear();
  }

  /// search() for a keep() that accepts no cell farther than radius from focus: it starts at
  /// the cells around that disc's box (starts_for), not at the root.
  template <class Keep, class F>
  void search_within(const Point<2>& focus, double radius, double /*scale*/, double margin, Keep&& keep,
                     F&& f) const {
    run_search(focus, margin, keep, f, true, radius + 3 * margin);
  }

  /// S3 after a round's run that failed: the view now belongs to the round `self`, whose
  /// run issues the next round (nested in it), which then finds the view kept.
  void hand_over(const void* self) noexcept { owner_ = self; }
  /// S3 after a step's first run that failed: the same, the run named by a serial (it has no
  /// round), which its first round carries.
  std::uint32_t hand_over_first_run() noexcept {
    if (++serial_ == 0) serial_ = 1;
    return owner_serial_ = serial_;
  }

  /// The leaf that holds grid position pos, and its value (pending when unread).
  std::pair<CellNode*, const CellState*> locate(const std::array<std::uint64_t, 2>& pos, double /*scale*/) {
    CellNode* n = deepest_present(CellDirectory::cell_at(pos, BucketTree::kMaxLevel));
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
  CellMark& resolve(CellNode* n) const {
    CellMark& x = mark(n);
    if (x.tag == Tag::Unknown) {
      x.state = rt_->peek(n->state);
      x.tag = tag_of(x.state);
    }
    return x;
  }

  void touch(CellNode* n, CellMark& x) const {
    if (x.read || x.pending) return;
    x.pending = true;
    pending_.push_back(n);
  }

  /// The deepest cell on k's path to the root that is not absent (a leaf or a split; the
  /// path is split cells, then the leaf, then absent ones, and a cell never made is absent).
  CellNode* deepest_present(const CellKey& k) const {
    // From the last answer by the tree's links, when it is near k: a step's searches are
    // mostly in one region, where the nodes are in the cache, but a lookup of a key not
    // looked up before misses on the table however hot its node is. Else by the lookups.
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
  CellNode* walk_from(CellNode* n, int c, const CellKey& k) const {
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
  CellNode* probe_deepest_present(const CellKey& k) const {
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
  void run_search(const Point<2>& focus, double margin, Keep& keep, F& f, bool bounded, double R) const {
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
  void run_search_near(const Point<2>& focus, double margin, Keep& keep, F& f, Radius& radius) const {
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
  /// (itself when present), without repeats, nearest to the focus first. Not the smallest
  /// cell holding the whole box: for a box that straddles a coarse cell's boundary that is a
  /// cell near the root, and the search would walk down from there.
  std::size_t starts_for(const Point<2>& focus, double R, std::array<CellNode*, 4>& out) const {
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
  CellNode* start_cell(const CellKey& k) const {
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

  CellNode* root() const {
    if (!root_) root_ = dir_->find(CellKey{});
    return root_;
  }

  /// A search's visit of k. Its answers depend on the leaves it hands vertices from, and on
  /// a split cell whose children it all prunes; those cells are used (touched). Every other
  /// cell it passes is an ancestor of a used one, known split through it.
  template <class Keep, class F>
  void search_node(CellNode* n, const Point<2>& focus, double margin, Keep& keep, F& f, bool& stop) const {
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

  // The members marked mutable are the searches' scratch. The questions of
  // cell_questions.hpp take their store as a const Store& (the static BucketTree is the other
  // store they run on), and a search of this view, though it changes no cell, peeks at cells
  // (pending_, the marks on the nodes), records the leaves it met (visited_, the region) and
  // remembers where it ended (finger_, start_memo_, root_) — state of the running step that a
  // const question must be able to change.
  sac::Engine* rt_;
  CellDirectory* dir_;
  Box<2> box_;
  std::array<double, BucketTree::kMaxLevel + 1> width_{};
  mutable CellNode* root_ = nullptr;  // the directory's, made before any step runs
  std::uint32_t gen_ = 0;             // the marks of this generation are this step's
  struct ReadCell {
    CellNode* node;
    const CellState* state;
    CellInterest* used;  // in the closure of the round that read it
  };
  std::vector<ReadCell> read_;
  std::size_t settled_ = 0;  // read_'s prefix settle() has seen
  mutable std::vector<CellNode*> pending_;
  // The running search's disc of used vertices (region_), or, for a search() without one,
  // the leaves it met, until the question states its use.
  mutable bool region_ = false;
  mutable Point<2> region_c_{};
  mutable double region_r_ = 0;
  mutable std::vector<CellNode*> visited_;
  mutable bool searched_from_ = false;  // the last search was a search_from()
  // deepest_present's last answer: where the next starts (its walk, or its lookups at the
  // answer's level first), a hint only, whose state is looked up again.
  mutable CellNode* finger_ = nullptr;
  // start_cell()'s answers of this generation, by key (direct-mapped).
  struct StartMemo {
    std::uint32_t gen = 0;
    int level = 0;
    std::uint64_t ix = 0, iy = 0;
    CellNode* node = nullptr;
  };
  static constexpr std::size_t kStartMemo = 16;
  mutable std::array<StartMemo, kStartMemo> start_memo_{};
  mutable std::size_t leaves_read_ = 0;
  Counts counts_;
  // The run the view was handed over to when it failed (S3; see begin_run()).
  const void* owner_ = nullptr;     // a round, by its closure
  std::uint32_t owner_serial_ = 0;  // or the step's first run, by its serial
  std::uint32_t serial_ = 0;
  bool kept_ = false;
};


}  // namespace dynmesh::detail
