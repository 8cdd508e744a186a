// cell_view.hpp (private) — how a step of the self-adjusting hpu program reads the cells:
// its view of the cell store, the rounds of reads that fill it, and the insertion step.
//
// Purpose: a step (a vertex's first class, an entry's collect, one try of a pair, a leaf's
// final triangles) runs the static questions of cell_questions.hpp on a CellView. The view
// holds the cells the step has read and answers searches from them; a search that needs a
// cell the step has not read records it as missing and fails, and every later question of
// the step then returns at once. run_step() then reads the missing cells, as one
// Engine::read_many (one trace event, up to 16 cells), nested in the reads before, and runs
// the step again on the larger view; the round that fails nothing does the step's writes.
// So a step costs a few events, whatever the number of vertices it looks at, and it re-runs
// only when a cell it read changes (cut-off: a write of an equal vertex set is no change).
// Which cells a search asks for: the view walks the tree from the root, like BucketTree's
// search. An ancestor of a cell read as a leaf or split is split (the tree grows only), so
// the step never reads the coarse cells above its region. A failed view keeps answering on
// the cells it has (cell_questions.hpp), so one round asks for the cells of several questions
// (at most 16, one read_many). An unread cell below the level
// that suits the search's scale is read itself; above it, its descendants at that level
// near the focus are read instead (at most 3 × 3), and a cell read as absent (an ancestor
// is a leaf) makes its next ancestors be read.
// Invariants: a view's cells are read by the step's enclosing reads. A round that runs right
// after the one it is nested in keeps that round's view and adds its own cells; any other
// (a round re-run by change propagation) rebuilds the view, looking the outer rounds' values
// up with Engine::current (no write between: a step writes only in its last round). A
// failed run writes, allocates and issues nothing but the next round; the answers of a run
// that did not fail are those of the static tree on the same vertices. A round replays the
// searches its parent round completed (same order, same answers) instead of walking cells.
// Complexity: a round O(new cells × depth) to extend the view, plus the step's questions.
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

class CellView {
 public:
  using V = const CellVertex*;

  CellView(sac::Engine& e, CellDirectory& dir) : e_(&e), dir_(&dir), box_(dir.box()) {
    table_.resize(1024);
    mask_ = table_.size() - 1;
    for (int l = 0; l <= BucketTree::kMaxLevel; ++l) width_[l] = std::ldexp(box_.side, -l);
  }
  CellView(const CellView&) = delete;
  CellView& operator=(const CellView&) = delete;

  // ---------------------------------------------------------------- filling

  /// A new round. `parent`: the round this one is nested in (null for a step's first round
  /// or its run on an empty view). When the view's last run was that round's (it failed and
  /// issued this one), the view keeps its cells and returns true: the caller adds only this
  /// round's, and the searches the parent completed are replayed (see search()). Otherwise
  /// it forgets every cell and returns false.
  bool reset(const void* parent = nullptr) {
    const bool replay = parent != nullptr && parent == owner_;
    owner_ = nullptr;
    if (replay) {
      rep_v_.swap(rec_v_);
      rep_n_.swap(rec_n_);
      rep_searches_ = rec_complete_;
    } else {
      rep_searches_ = 0;
    }
    rec_v_.clear();
    rec_n_.clear();
    rec_complete_ = 0;
    search_idx_ = 0;
    rep_pos_ = 0;
    misses_.clear();
    failed_ = false;
    if (replay) return true;
    if (++gen_ == 0) {
      for (Slot& s : table_) s.gen = 0;
      gen_ = 1;
    }
    used_ = 0;
    read_.clear();
    settled_ = 0;
    return false;
  }

  /// A cell the step has read, with its value now.
  void add(CellNode* n, const CellState* s) { read_.push_back({n, s}); }

  /// After the adds: marks the ancestors of the cells read as leaves or splits as split, and
  /// those of cells read as absent as "absent below" (the cells added since the last call).
  void settle() {
    const std::span<const std::pair<CellNode*, const CellState*>> fresh(read_.data() + settled_,
                                                                        read_.size() - settled_);
    settled_ = read_.size();
    for (const auto& [n, s] : fresh) {
      Slot& x = slot(n->key);
      x.tag = s->kind == CellState::Leaf ? Tag::Leaf : s->kind == CellState::Split ? Tag::Split : Tag::Absent;
      x.state = s;
      x.node = n;
    }
    for (const auto& [n, s] : fresh) {
      if (s->kind == CellState::Absent || n->key.level == 0) continue;
      for (CellKey k = n->key.parent();; k = k.parent()) {
        Slot& x = slot(k);
        if (x.tag == Tag::Split) break;
        if (x.tag == Tag::Leaf || x.tag == Tag::Absent)
          throw InvariantError("dynmesh: CellView: a cell read below a leaf or an absent cell");
        x.tag = Tag::Split;
        if (k.level == 0) break;
      }
    }
    for (const auto& [n, s] : fresh) {
      if (s->kind != CellState::Absent) continue;
      if (n->key.level == 0) throw InvariantError("dynmesh: CellView: the root cell is absent");
      for (CellKey k = n->key.parent();; k = k.parent()) {
        Slot& x = slot(k);
        if (x.tag != Tag::Unknown && x.tag != Tag::AbsentBelow) break;
        if (x.tag == Tag::Unknown) {
          x.tag = Tag::AbsentBelow;
          x.below = n->key;
        }
        if (k.level == 0) break;
      }
    }
  }

  // ---------------------------------------------------------------- the store interface

  bool failed() const noexcept { return failed_; }
  std::span<CellNode* const> misses() const noexcept { return misses_; }
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

  /// BucketTree::search on the cells read; `scale` (the search's radius, or the distance it
  /// expects) chooses which cells to ask for when it needs unread ones.
  /// A step's questions ask the same searches in the same order in every round until the
  /// first one that failed (they are pure functions of the searches' answers), and a search
  /// that did not fail saw every cell it needed; so in the next round such a search is
  /// replayed from what it handed out, without walking the cells.
  template <class Keep, class F>
  void search(const Point<2>& focus, double scale, double margin, Keep&& keep, F&& f) const {
    auto* self = const_cast<CellView*>(this);
    self->run_search(focus, scale, margin, keep, f, false, 0.0);
  }

  /// search() for a keep() that accepts no cell farther than radius from focus: it starts at
  /// the smallest cell read (or known split) that holds that disc's box, not at the root.
  /// `scale` (at least the radius) chooses which cells to ask for.
  template <class Keep, class F>
  void search_within(const Point<2>& focus, double radius, double scale, double margin, Keep&& keep, F&& f) const {
    auto* self = const_cast<CellView*>(this);
    self->run_search(focus, std::max(radius, scale), margin, keep, f, true, radius + 3 * margin);
  }

  /// After a run that failed: the round `self` recorded its searches for the round it issues.
  void hand_over(const void* self) noexcept { owner_ = self; }

  /// The leaf that holds grid position q, and its value; null when a cell is missing.
  std::pair<CellNode*, const CellState*> locate(const std::array<std::uint64_t, 2>& q, double scale) {
    CellKey k{};
    for (;;) {
      Slot& x = slot(k);
      if (x.tag == Tag::Leaf) return {x.node, x.state};
      if (x.tag == Tag::Split) {
        k = CellDirectory::cell_at(q, k.level + 1);
        continue;
      }
      if (x.tag == Tag::Absent) throw InvariantError("dynmesh: CellView: located into an absent cell");
      failed_ = true;
      if (x.tag == Tag::AbsentBelow) {
        ask_above(k, x.below);
      } else {
        const int g = level_for(scale);
        ask(g <= k.level ? k : CellDirectory::cell_at(q, g));
      }
      return {nullptr, nullptr};
    }
  }

  // ---------------------------------------------------------------- helpers

  /// The level whose cells are at least 2·scale wide (so a disc of radius scale meets at
  /// most 2 × 2 of them).
  int level_for(double scale) const noexcept {
    if (!(scale > 0)) return BucketTree::kMaxLevel;
    const double ratio = box_.side / (2 * scale);
    if (!(ratio >= 1)) return 0;
    return std::min(BucketTree::kMaxLevel, std::ilogb(ratio));
  }

  /// A cell's box, widened by margin.
  void cell_box(const CellKey& k, double margin, double& x0, double& y0, double& x1, double& y1) const noexcept {
    const double w = width_[k.level];
    x0 = box_.origin[0] + static_cast<double>(k.ix) * w - margin, x1 = x0 + w + 2 * margin;
    y0 = box_.origin[1] + static_cast<double>(k.iy) * w - margin, y1 = y0 + w + 2 * margin;
  }

 private:
  enum class Tag : std::uint8_t { Unknown, Leaf, Split, Absent, AbsentBelow, Asked };
  struct Slot {
    std::uint32_t gen = 0;
    Tag tag = Tag::Unknown;
    CellKey key;
    CellKey below;  // AbsentBelow: a cell read as absent under this one
    const CellState* state = nullptr;
    CellNode* node = nullptr;
  };

  Slot& slot(const CellKey& k) {
    if (2 * (used_ + 1) > table_.size()) grow();
    for (std::size_t i = k.hash() & mask_;; i = (i + 1) & mask_) {
      Slot& s = table_[i];
      if (s.gen != gen_) {
        s.gen = gen_;
        s.tag = Tag::Unknown;
        s.key = k;
        s.state = nullptr;
        s.node = nullptr;
        ++used_;
        return s;
      }
      if (s.key == k) return s;
    }
  }

  template <class Keep, class F>
  void run_search(const Point<2>& focus, double scale, double margin, Keep& keep, F& f, bool bounded, double R) {
    const std::size_t idx = search_idx_++;
    if (idx < rep_searches_) {
      // Replay: hand out what this search handed out last round, in order.
      const std::uint32_t k = rep_n_[idx];
      const CellVertex* const* vs = rep_v_.data() + rep_pos_;
      rep_pos_ += k;
      std::uint32_t handed = 0;
      while (handed < k) {
        rec_v_.push_back(vs[handed]);
        if (f(vs[handed++])) break;
      }
      rec_n_.push_back(handed);
      if (!failed_) ++rec_complete_;
      return;
    }
    const std::size_t first = rec_v_.size();
    auto g = [&](const CellVertex* v) {
      rec_v_.push_back(v);
      return f(v);
    };
    bool stop = false;
    search_node(bounded ? start_for(focus, R) : CellKey{}, focus, scale, margin, keep, g, stop);
    rec_n_.push_back(static_cast<std::uint32_t>(rec_v_.size() - first));
    if (!failed_) ++rec_complete_;
  }

  /// The deepest cell holding the box [focus ± R] whose state the view knows (leaf or split),
  /// else the root.
  CellKey start_for(const Point<2>& focus, double R) {
    const auto a = dir_->position(Point<2>{focus[0] - R, focus[1] - R});
    const auto b = dir_->position(Point<2>{focus[0] + R, focus[1] + R});
    const int diff = std::max(std::bit_width(a[0] ^ b[0]), std::bit_width(a[1] ^ b[1]));
    CellKey k = CellDirectory::cell_at(a, BucketTree::kMaxLevel - diff);
    for (; k.level > 0; k = k.parent()) {
      const Slot* x = find_slot(k);
      if (x && (x->tag == Tag::Split || x->tag == Tag::Leaf)) return k;
    }
    return CellKey{};
  }

  const Slot* find_slot(const CellKey& k) const {
    for (std::size_t i = k.hash() & mask_;; i = (i + 1) & mask_) {
      const Slot& s = table_[i];
      if (s.gen != gen_) return nullptr;
      if (s.key == k) return &s;
    }
  }

  void grow() {
    std::vector<Slot> old(table_.size() * 2);
    old.swap(table_);
    mask_ = table_.size() - 1;
    used_ = 0;
    for (const Slot& s : old) {
      if (s.gen != gen_) continue;
      Slot& n = slot(s.key);
      n = s;
    }
  }

  void ask(const CellKey& k) {
    failed_ = true;
    if (misses_.size() >= kCellsPerRead) return;  // one round reads no more
    Slot& x = slot(k);
    if (x.tag == Tag::Asked) return;
    if (x.tag != Tag::Unknown && x.tag != Tag::AbsentBelow) return;  // read already
    x.tag = Tag::Asked;
    misses_.push_back(dir_->node(*e_, k));
  }

  /// Cells read as absent below k: ask for the next unread ancestors of one of them (up to
  /// three, and not above k), where the leaf that holds it must be.
  void ask_above(const CellKey& k, const CellKey& below) {
    failed_ = true;
    int asked = 0;
    for (CellKey a = below.parent(); a.level >= k.level && asked < 3; a = a.parent()) {
      const Slot* x = find_slot(a);
      if (!x || x->tag == Tag::Unknown || x->tag == Tag::AbsentBelow || x->tag == Tag::Asked) {
        ask(a);
        ++asked;
      }
      if (a.level == 0) break;
    }
  }

  template <class Keep, class F>
  void search_node(const CellKey& k, const Point<2>& focus, double scale, double margin, Keep& keep, F& f, bool& stop) {
    double x0, y0, x1, y1;
    cell_box(k, margin, x0, y0, x1, y1);
    if (!keep(x0, y0, x1, y1)) return;
    Slot& x = slot(k);
    switch (x.tag) {
      case Tag::Leaf: {
        ++leaves_read_;
        const CellState& s = *x.state;
        for (std::size_t i = 0; i < s.count; ++i)
          if (f(s.items[i])) {
            stop = true;
            return;
          }
        return;
      }
      case Tag::Split: {
        // Children nearest to the focus first (by their centres' distance), as BucketTree.
        // The child holding the focus's side in x and y first, then its x neighbour, its y
        // neighbour, and the opposite one: nearest first for the four equal squares.
        const double w = width_[k.level];
        const double mx = box_.origin[0] + (static_cast<double>(k.ix) + 0.5) * w;
        const double my = box_.origin[1] + (static_cast<double>(k.iy) + 0.5) * w;
        const unsigned hx = focus[0] >= mx ? 1 : 0, hy = focus[1] >= my ? 1 : 0;
        const unsigned near = hx | (hy << 1);
        const bool x_first = std::abs(focus[0] - mx) >= std::abs(focus[1] - my);
        const unsigned order[4] = {near, near ^ (x_first ? 2u : 1u), near ^ (x_first ? 1u : 2u), near ^ 3u};
        for (const unsigned c : order) {
          if (stop) return;
          search_node(k.child(c), focus, scale, margin, keep, f, stop);
        }
        return;
      }
      case Tag::Absent:
        throw InvariantError("dynmesh: CellView: an absent cell under a split one");
      case Tag::Asked:
        failed_ = true;
        return;
      case Tag::AbsentBelow:
        ask_above(k, x.below);
        return;
      case Tag::Unknown:
        ask_for(k, focus, scale, margin, keep);
        return;
    }
  }

  /// k is unread and the search needs it: read it if it is at the search's level or finer;
  /// otherwise read its cells of that level near the focus that the search keeps.
  template <class Keep>
  void ask_for(const CellKey& k, const Point<2>& focus, double scale, double margin, Keep& keep) {
    failed_ = true;
    double s = scale;
    for (int attempt = 0; attempt < 2; ++attempt) {
      const int g = level_for(s);
      if (g <= k.level) return ask(k);
      const int shift = g - k.level;
      const double w = width_[g];
      const double R = 2 * s + margin;
      const auto index = [&](double x, unsigned a, std::uint64_t lo, std::uint64_t hi) -> std::uint64_t {
        const double u = std::floor((x - box_.origin[a]) / w);
        if (!(u > static_cast<double>(lo))) return lo;
        if (!(u < static_cast<double>(hi))) return hi;
        return static_cast<std::uint64_t>(u);
      };
      const std::uint64_t lo_x = k.ix << shift, hi_x = ((k.ix + 1) << shift) - 1;
      const std::uint64_t lo_y = k.iy << shift, hi_y = ((k.iy + 1) << shift) - 1;
      // The focus box clamped to k: empty when k lies beyond it.
      const double fx0 = focus[0] - R, fx1 = focus[0] + R, fy0 = focus[1] - R, fy1 = focus[1] + R;
      double kx0, ky0, kx1, ky1;
      cell_box(k, 0.0, kx0, ky0, kx1, ky1);
      if (fx1 < kx0 || fx0 > kx1 || fy1 < ky0 || fy0 > ky1) {
        // Beyond the focus box: scale up to k's distance and try again.
        s = std::max(s, std::sqrt(BucketTree::box_distance2(focus, kx0, ky0, kx1, ky1)));
        continue;
      }
      const std::uint64_t ax = index(fx0, 0, lo_x, hi_x), bx = index(fx1, 0, lo_x, hi_x);
      const std::uint64_t ay = index(fy0, 1, lo_y, hi_y), by = index(fy1, 1, lo_y, hi_y);
      bool any = false;
      for (std::uint64_t iy = ay; iy <= by; ++iy)
        for (std::uint64_t ix = ax; ix <= bx; ++ix) {
          const CellKey c{g, ix, iy};
          double c0, c1, c2, c3;
          cell_box(c, margin, c0, c1, c2, c3);
          if (!keep(c0, c1, c2, c3)) continue;
          ask(c);
          any = true;
        }
      if (any) return;
      break;
    }
    ask(k);
  }

  sac::Engine* e_;
  CellDirectory* dir_;
  Box<2> box_;
  std::array<double, BucketTree::kMaxLevel + 1> width_{};
  std::vector<Slot> table_;
  std::size_t mask_ = 0, used_ = 0;
  std::uint32_t gen_ = 0;
  std::vector<std::pair<CellNode*, const CellState*>> read_;
  std::size_t settled_ = 0;  // read_'s prefix settle() has seen
  std::vector<CellNode*> misses_;
  bool failed_ = false;
  std::size_t leaves_read_ = 0;
  Counts counts_;
  // Search replay (search()): this round's record, and the last round's to replay.
  const void* owner_ = nullptr;  // the round whose record rec_ holds, after it failed
  std::vector<const CellVertex*> rec_v_, rep_v_;
  std::vector<std::uint32_t> rec_n_, rep_n_;
  std::size_t rec_complete_ = 0, rep_searches_ = 0, search_idx_ = 0, rep_pos_ = 0;
};

// -------------------------------------------------------------------- rounds of reads

/// The part of a round's closure that later rounds look through: the round before, and how
/// many cells this one read (the cells follow it in CellRound).
struct CellRoundHead {
  const CellRoundHead* parent;
  std::uint32_t n;
};

template <std::size_t N>
struct CellRoundCells {
  CellRoundHead head;
  std::array<CellNode*, N> cells;
};

inline CellNode* const* cells_of(const CellRoundHead* h) {
  // Every CellRound<Step, N> starts with a CellRoundCells<N> (standard layout), whose cells
  // follow the head at the same offset for every N.
  return reinterpret_cast<const CellRoundCells<1>*>(h)->cells.data();
}

template <class Step>
void issue_round(sac::Engine& e, const Step& step, const CellRoundHead* parent, std::span<CellNode* const> misses);

/// One round of a step: reads its cells, then runs the step on the view of all its rounds.
template <class Step, std::size_t N>
struct CellRound {
  CellRoundCells<N> c;
  Step step;

  void operator()(sac::Engine& e, std::span<const CellState* const> vals) const {
    CellView& v = *step.view(e);
    const bool kept = v.reset(c.head.parent);  // the parent's cells are still in the view
    for (std::uint32_t i = 0; i < c.head.n; ++i) v.add(c.cells[i], vals[i]);
    if (!kept)
      for (const CellRoundHead* r = c.head.parent; r; r = r->parent) {
        CellNode* const* cells = cells_of(r);
        for (std::uint32_t i = 0; i < r->n; ++i) v.add(cells[i], &e.current(cells[i]->state));
      }
    v.settle();
    if (!step.run(e, v)) {
      v.hand_over(&c.head);
      issue_round(e, step, &c.head, v.misses());
    }
  }
};

template <class Step, std::size_t N>
void issue_round_n(sac::Engine& e, const Step& step, const CellRoundHead* parent, std::span<CellNode* const> misses) {
  static_assert(std::is_standard_layout_v<CellRoundCells<N>>);
  static_assert(offsetof(CellRoundCells<N>, cells) == offsetof(CellRoundCells<1>, cells));
  CellRound<Step, N> r{{{parent, static_cast<std::uint32_t>(misses.size())}, {}}, step};
  std::array<const sac::Mod<CellState>*, N> mods;
  for (std::size_t i = 0; i < misses.size(); ++i) {
    r.c.cells[i] = misses[i];
    mods[i] = &misses[i]->state;
  }
  e.read_many(std::span<const sac::Mod<CellState>* const>(mods.data(), misses.size()), std::move(r));
}

template <class Step>
void issue_round(sac::Engine& e, const Step& step, const CellRoundHead* parent, std::span<CellNode* const> misses) {
  if (misses.empty()) throw InvariantError("dynmesh: a step failed without a missing cell");
  if (misses.size() > kCellsPerRead) misses = misses.first(kCellsPerRead);  // the rest next round
  step.view(e)->count_round(misses.size());
  if (misses.size() <= 2) return issue_round_n<Step, 2>(e, step, parent, misses);
  if (misses.size() <= 4) return issue_round_n<Step, 4>(e, step, parent, misses);
  if (misses.size() <= 8) return issue_round_n<Step, 8>(e, step, parent, misses);
  issue_round_n<Step, kCellsPerRead>(e, step, parent, misses);
}

/// Runs a step: step.run(e, view) on an empty view (it fails at its first question), then
/// on the cells it asked for, round after round, until a run does not fail. Step: copyable
/// (it is each round's closure), with CellView* view(Engine&) and bool run(Engine&,
/// CellView&). run returns false when the view failed, and has then written, allocated and
/// issued nothing; otherwise it does the step's effects, in this order: writes and
/// allocations first (they use the view and the program's scratch), then the reads, memo
/// calls and run_step calls that continue the program (a write after an issued call would
/// run that call on the spot, and it would reuse the view).
template <class Step>
void run_step(sac::Engine& e, const Step& step) {
  CellView& v = *step.view(e);
  v.reset();
  if (!step.run(e, v)) issue_round(e, step, nullptr, v.misses());
}

}  // namespace dynmesh::detail
