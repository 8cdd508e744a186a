// cell_questions.hpp (private) — the hpu refinement's questions, answered from the cells of
// a vertex store: one code for the static cell refiner (cell_refiner.cpp, on BucketTree) and
// the self-adjusting program (hpu_cells_program.hpp, on a step's view of CellStore).
//
// Purpose: every decision of the twin's rules (dynmesh/hpu_mesh.hpp, rules 1-6) as a
// predicate on the vertices near the pair or vertex it concerns, each found by exact searches
// of the store's cells (docs/HPU_ON_CELLS.md has the exactness arguments):
//   - left_search: the Delaunay neighbour of p→q on its left (the twin's perturbation breaks
//     ties), the vertex whose circle through p and q is lowest in their pencil, asked of the
//     circles at heights 1/2, 1, 2, ... up to a cap, narrowing to the best circle found (its
//     answer uses that circle's disc only);
//   - star_of: walked by left searches from a sure neighbour (empty closed diametral disc),
//     chosen among the vertices the nearest search kept (no search of its own);
//     a collect of class j caps the circles at radius 2^(j+2) (hpu_geometry.hpp's
//     kGoOnReach), and the edges of class ≤ j in such a gap are found among the vertices
//     within 2^(j+1) in its angle;
//   - first_class: the nearest vertices only, unless rounding at a power of two makes the
//     star decide;
//   - loose: no vertex strictly inside the leaf; in a collect, for a pair whose two
//     triangles the walk met, decided by those triangles' third corners, as the twin does;
//   - decide: one try of the twin's process(p, q, j) — not loose, split these box edges, or
//     insert the off-center (its neighbour by the left search capped at the apex);
//   - triangles_of: a vertex's triangles of the final mesh (it is their (x, y)-smallest
//     corner).
// The store is anything with search(focus, scale, margin, keep, f) (nearest-first pruned
// leaf visits: keep(x0, y0, x1, y1) asked of every cell, stop = f(v) for a leaf's vertices),
// search_within(focus, radius, scale, margin, keep, f) (the same, keep() bounded by that disc),
// search_from(focus, R, margin, keep, f) (the same over the cells that cover [focus ± R], its
// use stated afterwards as a search()'s; more search_from()s may come first),
// search_near(focus, scale, margin, keep, f, radius) (search() for a keep() that accepts no
// cell beyond radius(), which only shrinks: it may start at focus's leaf),
// margin_for(c, r) and leaves_read(). After every search() the question says what its answer
// used of the leaves it read: used_within(c, r) (the vertices within r of c), used_box(x0, y0,
// x1, y1) (those inside that closed box) or used_all().
// A search_within's answer uses only the vertices within its radius (plus the margins): f
// rejects every other one without an effect. A step's reads re-run only when what it used
// changes (cell_view.hpp). Every store answers exactly: a step's view
// (cell_view.hpp) looks a cell the step has not read up as it is now and notes it for the
// step's next round of reads.
// Invariants: a question reads nothing but the store; given a store that does not fail, the
// answers are those of the twin's triangulation on the same vertices (tests/dynmesh/
// hpu_cells_test.cpp compares meshes on every distribution and angle bound).
// Complexity: O(1) cells per question in a graded mesh (CellQuestionStats counts them).
// Paper: Acar & Hudson, Figure 5 and Appendix A; Har-Peled & Üngör (2005).
#pragma once

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/predicates.hpp"
#include "geometry/delaunay.hpp"  // perturbed_incircle: the twin's tie rule
#include "hpu/bucket_tree.hpp"     // box_distance2
#include "hpu/hpu_geometry.hpp"

namespace dynmesh::detail {

/// What the cell questions cost: the figures a self-adjusting version pays in reads.
struct CellQuestionStats {
  std::size_t stars = 0;           // stars walked (first classes, collects, final mesh)
  std::size_t leaf_tests = 0;      // loose tests asked of the cells
  std::size_t neighbour_asks = 0;  // left searches (star steps, off-centers, box edges)
  std::size_t leaves_read = 0;     // store leaves met by left searches and loose tests
  std::size_t gathered_first = 0;  // vertices looked at for first classes
  // Leaves read by the collects, by the pairs' processing and by the final mesh (kept by
  // the static refiner's step log).
  std::size_t leaves_collect = 0, leaves_process = 0, leaves_final = 0;
  // With CellRefineOptions::held_stars: what stars held from one walk to the next would save.
  // A collect's walk is held when it closed (the whole star) or stopped at a cap no larger
  // than the one before, with the same neighbours: its left searches are then repeats.
  std::size_t collects = 0, collect_asks = 0;       // every collect, and its left searches
  std::size_t held_collects = 0, held_asks = 0;     // collects a held star answers
  // Collects whose vertex had walked its whole star before (what stars kept up to date by
  // every walk would answer is star_ledger.hpp's count, CellRefineOptions::maintained_stars).
  std::size_t kept_collects = 0, kept_asks = 0;
  // Triangles (consecutive neighbours) of a collect's walk, and those its vertex's previous
  // walk had found already: each is a left search a walk resumed from its last one would
  // not repeat, at most.
  std::size_t walk_triangles = 0, repeated_triangles = 0;
  std::size_t final_stars = 0, held_final = 0;      // vertices, and those whose last collect
                                                    // walked their whole final star
  std::size_t final_asks = 0, held_final_asks = 0;  // the final walks' left searches
};

namespace cellq {
/// Relative slack of the "circumdisc inside the gathered disc" test: far above the rounding
/// of the circumcentre (a few ulps), far below any gap the tests rely on.
inline constexpr double kSlack = 0x1p-20;

/// An absolute allowance for the rounding of coordinates near p: computed centres and
/// differences are off by a few ulps of the coordinates (2^-52 of them each), which can be
/// large against a small question's radius. 2^-46 is 64 such ulps: enough for the rounding,
/// and no larger, since in a cluster far below the box's scale a larger allowance widens
/// every question by several vertex spacings and a search reads many more leaves.
inline double ulp_room(const Point<2>& p) noexcept { return std::max(std::abs(p[0]), std::abs(p[1])) * 0x1p-46; }

/// |(dx, dy)| for radii and thresholds that carry a slack: within two ulps of std::hypot at
/// a fraction of its cost (a tenth of the program's time went to hypot); hypot itself where
/// the squares would overflow or lose precision.
inline double length(double dx, double dy) noexcept {
  const double s = dx * dx + dy * dy;
  if (s > 0x1p-900 && s < 0x1p900) return std::sqrt(s);
  return std::hypot(dx, dy);
}

}  // namespace cellq

/// One try of a loose pair (the twin's process loop body): what to do next.
template <class V>
struct CellDecision {
  enum Kind : std::uint8_t { Done, Split, Insert };
  Kind kind = Done;
  std::vector<std::array<V, 2>> splits;  // box edges to split, in order (Split)
  Point<2> at{};                         // the off-center (Insert)
  bool circumcentre = false;
};

/// Store: the cell store (see the header). V: a vertex handle; Coords: V → const Point<2>&.
template <class Store, class V, class Coords>
class CellQuestions {
 public:
  CellQuestions(const Box<2>& box, double min_angle_deg, const Store& store, Coords coords, V none,
                CellQuestionStats& stats)
      : box_(box), store_(&store), P_(coords), none_(none), stats_(stats) {
    apex_height_ = apex_height(min_angle_deg);
    leaf_height_ = leaf_height(min_angle_deg);
    lo_[0] = box.origin[0], lo_[1] = box.origin[1];
    hi_[0] = box.origin[0] + box.side, hi_[1] = box.origin[1] + box.side;
  }

  void set_store(const Store& s) noexcept { store_ = &s; }
  const Store& store() const noexcept { return *store_; }
  V none() const noexcept { return none_; }
  const Point<2>& pt(V v) const { return P_(v); }
  double apex() const noexcept { return apex_height_; }

  bool on_boundary(V v) const noexcept {
    const Point<2>& p = P_(v);
    return p[0] == lo_[0] || p[0] == hi_[0] || p[1] == lo_[1] || p[1] == hi_[1];
  }

  /// Is the outside of the box on the left of p→q? (Both on one side, q before p in the
  /// side's counter-clockwise direction.)
  bool outside_left(V p, V q) const noexcept {
    const Point<2>&a = P_(p), &b = P_(q);
    if (a[1] == lo_[1] && b[1] == lo_[1]) return b[0] < a[0];
    if (a[0] == hi_[0] && b[0] == hi_[0]) return b[1] < a[1];
    if (a[1] == hi_[1] && b[1] == hi_[1]) return b[0] > a[0];
    if (a[0] == lo_[0] && b[0] == lo_[0]) return b[1] > a[1];
    return false;
  }

  /// Calls stop = f(v) for the vertices of every cell that meets the disc (c, r). `scale`:
  /// the size of the cells expected there (r when 0).
  template <class F>
  void visit_disc(const Point<2>& c, double r, F&& f, double scale = 0) const {
    const double margin = store_->margin_for(c, r);
    const double r2 = (r + margin) * (r + margin);
    // A vertex farther than r in doubles is outside the disc (every caller's r has a relative
    // slack far above the rounding of the squares): not handed to f, which saves its exact
    // predicates.
    const double rr = r * r;
    store_->search_within(
        c, r, scale, margin,
        [&](double x0, double y0, double x1, double y1) { return BucketTree::box_distance2(c, x0, y0, x1, y1) <= r2; },
        [&](V v) {
          const double dx = P_(v)[0] - c[0], dy = P_(v)[1] - c[1];
          return dx * dx + dy * dy > rr ? false : f(v);
        });
  }

  /// The vertex at p, if any. `scale`: the size of the cells expected there.
  std::optional<V> find(const Point<2>& p, double scale = 0) const {
    std::optional<V> hit;
    visit_disc(
        p, 0.0,
        [&](V v) {
          if (P_(v) == p) hit = v;
          return hit.has_value();
        },
        scale);
    return hit;
  }

  /// p→q is ccw-loose: the outside of the box is not on its left and no vertex lies strictly
  /// inside its ccw-leaf (the first vertex inside ends the search).
  bool loose(V p, V q) const {
    ++stats_.leaf_tests;
    if (outside_left(p, q)) return false;
    const Point<2>&a = P_(p), &b = P_(q);
    // The leaf: centre m + k·J(q − p), radius ρ|pq| = |c − p|.
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const Point<2> c{0.5 * a[0] + 0.5 * b[0] - leaf_height_ * dy, 0.5 * a[1] + 0.5 * b[1] + leaf_height_ * dx};
    const double r = cellq::length(c[0] - a[0], c[1] - a[1]) * (1 + cellq::kSlack) + cellq::ulp_room(c);
    bool empty = true;
    const std::size_t before = store_->leaves_read();
    visit_disc(c, r, [&](V v) {
      if (v != p && v != q && pencil(a, b, leaf_height_, P_(v)) < 0) empty = false;
      return !empty;
    });
    stats_.leaves_read += store_->leaves_read() - before;
    return empty;
  }

  /// The distance from v to its nearest vertex, in doubles (nearest-first: only the cells
  /// nearer than the best found so far are read). `scale`: the distance expected.
  ///
  /// It also keeps, in near_all_, every vertex within the distance found plus a relative
  /// 2^-19 (and twice ulp_room): a superset of the vertices within d·(1 + 2^-20) that
  /// sure_neighbour and first_class choose from, and of every vertex nearer than those
  /// (a diametral intruder is). So those questions need no search of their own.
  double nearest_distance(V v, double scale) const {
    const Point<2>& p = P_(v);
    const double room = 2 * cellq::ulp_room(p);
    const auto reach = [&](double d) { return d * (1 + 0x1p-19) + room; };
    double best = std::numeric_limits<double>::infinity();
    near_all_.clear();
    store_->search_near(
        p, scale, store_->margin_for(p, 0.0),
        [&](double x0, double y0, double x1, double y1) {
          // By length(), which does not overflow: near the largest doubles every squared
          // distance would be infinite, and the search must still prune by best only.
          const double dx = p[0] < x0 ? x0 - p[0] : p[0] > x1 ? p[0] - x1 : 0.0;
          const double dy = p[1] < y0 ? y0 - p[1] : p[1] > y1 ? p[1] - y1 : 0.0;
          return cellq::length(dx, dy) <= reach(best);
        },
        [&](V w) {
          if (w == v) return false;
          const double l = cellq::length(P_(w)[0] - p[0], P_(w)[1] - p[1]);
          if (l <= reach(best)) near_all_.push_back(w);
          best = std::min(best, l);
          return false;
        },
        [&] { return reach(best); });
    // The minimum is that of the vertices within best, and the kept ones lie within
    // reach(best): one farther changes neither.
    if (std::isfinite(best)) store_->used_within(p, reach(best));
    else store_->used_all();
    return best;
  }

  /// The vertices of near_all_ (the last nearest_distance(v)) within r of v, by the same
  /// test as visit_disc's, in the order found.
  void kept_within(V v, double r, std::vector<V>& out) const {
    out.clear();
    const Point<2>& p = P_(v);
    const double rr = r * r;
    for (const V w : near_all_) {
      const double dx = P_(w)[0] - p[0], dy = P_(w)[1] - p[1];
      if (dx * dx + dy * dy <= rr) out.push_back(w);
    }
  }

  /// A vertex other than v and q inside or on the closed diametral disc of v and q, or
  /// none(), among near_all_ (the last nearest_distance(v)), for q within its reach: such a
  /// vertex is strictly nearer to v than q is, so it was kept.
  V kept_intruder(V v, V q) const {
    const Point<2>&a = P_(v), &b = P_(q);
    for (const V w : near_all_)
      if (w != q && pencil(a, b, 0.0, P_(w)) <= 0) return w;
    return none_;
  }

  /// Some vertex that v has an edge to in every Delaunay triangulation: the nearest one whose
  /// closed diametral disc with v holds no other vertex (a vertex inside or on that disc is
  /// strictly nearer, so the search ends). none() when v is alone.
  V sure_neighbour(V v, double scale) const {
    const double d = nearest_distance(v, scale);
    if (!std::isfinite(d)) return none_;
    V a = none_;
    const Point<2>& p = P_(v);
    kept_within(v, d * (1 + cellq::kSlack) + cellq::ulp_room(p), near_);
    for (const V w : near_)
      if (a == none_ || std::hypot(P_(w)[0] - p[0], P_(w)[1] - p[1]) < std::hypot(P_(a)[0] - p[0], P_(a)[1] - p[1]))
        a = w;
    // Each step moves strictly nearer to v, so the loop ends.
    while (a != none_) {
      const V inside = kept_intruder(v, a);
      if (inside == none_) return a;
      a = inside;
    }
    return none_;
  }

  /// The left search's first probe: the circle at height 1/2 (its third corner sees pq at
  /// 45° or more) holds most neighbours of a quality mesh, and probes below it mostly came
  /// back empty.
  static constexpr double kFirstHeight = 0.5;

  /// The Delaunay neighbour of p→q on its left (the third corner of the triangle on its
  /// left, under the triangulations' perturbation): of the vertices on the left, the one
  /// whose circle through p and q lies lowest in the pencil of circles through p and q,
  /// searched among the circles centred at most h_max·|pq| along J(q − p) from pq's
  /// midpoint, smallest first. none() when none lies that low (or the left is outside the
  /// box).
  V left_search(V p, V q, double h_max) const {
    ++stats_.neighbour_asks;
    if (outside_left(p, q)) return none_;  // a box edge seen from outside: no triangle there
    const Point<2>&a = P_(p), &b = P_(q);
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const double len = cellq::length(dx, dy);
    const Point<2> m{0.5 * a[0] + 0.5 * b[0], 0.5 * a[1] + 0.5 * b[1]};
    const std::size_t before = store_->leaves_read();
    const auto meets = [](double x0, double y0, double x1, double y1, const Point<2>& c, double r) {
      return BucketTree::box_distance2(c, x0, y0, x1, y1) <= r * r;
    };
    // The disc of the circle through p and q at height h, widened for rounding.
    const auto disc = [&](double h, Point<2>& c, double& r) {
      c = Point<2>{m[0] - h * dy, m[1] + h * dx};
      r = len * std::sqrt(0.25 + h * h) * (1 + cellq::kSlack) + cellq::ulp_room(c);
    };
    V best = none_;
    Point<2> pc, bc{};
    double pr, br = 0;
    for (double h = std::min(kFirstHeight, h_max);; h = std::min(2 * h, h_max)) {
      disc(h, pc, pr);
      // Within the probe, a cell is read only while it can hold a vertex below the best
      // circle found so far (a vertex on that circle can still win a perturbed tie, hence
      // the widening).
      const double margin = store_->margin_for(pc, pr);
      store_->search_from(
          pc, pr + 3 * margin, margin,
          [&](double x0, double y0, double x1, double y1) {
            return meets(x0, y0, x1, y1, pc, pr) && (best == none_ || meets(x0, y0, x1, y1, bc, br));
          },
          [&](V w) {
            // Outside the probe's disc in doubles (its radius has a relative slack): outside
            // the circle at height h, so pencil() > 0, without the exact predicates.
            const double ex = P_(w)[0] - pc[0], ey = P_(w)[1] - pc[1];
            if (ex * ex + ey * ey > pr * pr) return false;
            if (w == p || w == q || orient2d(a, b, P_(w)) <= 0 || pencil(a, b, h, P_(w)) > 0) return false;
            if (best == none_ || perturbed_incircle(a, b, P_(best), P_(w))) {
              best = w;
              const Point<2>& t = P_(w);
              // The best circle's height: (t − p)·(t − q) = 2h·orient(p, q, t). Only a
              // well-conditioned one (t not nearly on pq's line) narrows the search; its
              // relative error is then far below the widening.
              const double tx = t[0] - a[0], ty = t[1] - a[1];
              const double cross = dx * ty - dy * tx;
              const double hb = (tx * (t[0] - b[0]) + ty * (t[1] - b[1])) / (2 * cross);
              if (cross > 0x1p-20 * cellq::length(tx, ty) * len && std::isfinite(hb) && hb < h) {
                disc(hb, bc, br);
                br = br * (1 + 0x1p-10) + cellq::ulp_room(bc);
              } else {
                bc = pc, br = pr;
              }
            }
            return false;
          });
      if (best != none_ || h >= h_max) break;
    }
    // On the left of pq the discs grow with the height, so the answer used the vertices in
    // the best circle's disc (the last probe's when it found none): a vertex beyond it is
    // higher in the pencil, or on the right. So a first probe wider than the answer needs
    // costs no dependency.
    if (best != none_) store_->used_within(bc, br);
    else store_->used_within(pc, pr);
    stats_.leaves_read += store_->leaves_read() - before;
    return best;
  }

  /// v's star, counter-clockwise (a cycle for an interior vertex, from one box side to the
  /// other for a vertex on the boundary), walked from a sure neighbour by left searches, into
  /// star(). With a radius R, each step searches only the circles of radius at most R: the
  /// walk then stops where the next triangle's circumradius exceeds R, and returns false
  /// (star() then holds the star's two ends around that gap, cut into at most two runs: the
  /// counter-clockwise run from the sure neighbour, then the clockwise one, put first).
  /// `scale`: the distance to v's nearest vertex expected.
  bool star_of(V v, double scale, double R = std::numeric_limits<double>::infinity()) {
    ++stats_.stars;
    star_.clear();
    gap_ends_ = 0;
    const V q0 = sure_neighbour(v, scale);
    if (q0 == none_) return false;  // no other vertex
    const auto h_cap = [&](V a, V b) {
      if (R == std::numeric_limits<double>::infinity()) return R;
      const double half = 0.5 * cellq::length(P_(b)[0] - P_(a)[0], P_(b)[1] - P_(a)[1]);
      return R > half ? std::sqrt((R / (2 * half)) * (R / (2 * half)) - 0.25) : -1.0;
    };
    // One walk from q0 around v, counter-clockwise (the left of v→q) or clockwise (the left
    // of q→v), and why it ended.
    enum class End { Closed, Side, Gap, Met };
    const auto walk = [&](bool ccw, bool stop_at_star, std::vector<V>& out) {
      for (V q = q0;;) {
        const V a = ccw ? v : q, b = ccw ? q : v;
        if (outside_left(a, b)) return End::Side;  // a box side: the fan ends
        const double h = h_cap(a, b);
        const V t = h < 0 ? none_ : left_search(a, b, h);
        if (t == none_) return End::Gap;
        if (t == q0) return End::Closed;
        if (stop_at_star && std::find(star_.begin(), star_.end(), t) != star_.end()) return End::Met;
        if (out.size() > 4096) throw InvariantError("dynmesh: a star walk that does not close");
        out.push_back(t);
        q = t;
      }
    };
    star_.assign(1, q0);
    const End ccw = walk(true, false, star_);
    if (ccw == End::Closed) return true;
    back_.clear();
    const End cw = walk(false, ccw == End::Gap, back_);  // stops where it meets the other run
    gap_ends_ = (ccw == End::Gap) + (cw == End::Gap);
    star_.insert(star_.begin(), back_.rbegin(), back_.rend());
    return gap_ends_ == 0;
  }

  const std::vector<V>& star() const noexcept { return star_; }
  /// The last star_of's walks that stopped at its cap (0: the star is whole).
  int star_gap_ends() const noexcept { return gap_ends_; }

  /// The class of v's shortest Delaunay edge. edge_class is ⌊log2 |pq|⌋ but where rounding
  /// moves |pq|² across a power of four, so an edge longer than the nearest one by more
  /// than a relative 2^-40 is of no lower class: only the nearest vertices (ties included)
  /// can set the minimum. Each that has an empty closed diametral disc is an edge; if one
  /// of a lower class has not, the star decides (exact ties at a power of two).
  int first_class(V v, double scale) {
    const double d = nearest_distance(v, scale);
    if (!std::isfinite(d)) return INT_MAX;  // no other vertex
    kept_within(v, d * (1 + 0x1p-39) + cellq::ulp_room(P_(v)), near_);
    stats_.gathered_first += near_.size();
    int best = INT_MAX, unsure = INT_MAX;
    for (const V q : near_) {
      const int c = edge_class(P_(v), P_(q));
      if (c >= best) continue;
      if (kept_intruder(v, q) == none_) best = c;
      else unsure = std::min(unsure, c);
    }
    if (best != INT_MAX && unsure >= best) return best;
    star_of(v, d);
    best = INT_MAX;
    for (const V q : star_) best = std::min(best, edge_class(P_(v), P_(q)));
    return best;
  }

  /// Figure 5, line 7, for one vertex (the twin's collect): its loose pairs of class j (≤ j
  /// at its first entry), in (x, y) order, into `pairs`; returns whether v continues into
  /// Q_{j+1}.
  bool collect(V v, int j, bool birth, std::vector<std::array<V, 2>>& pairs) {
    pairs.clear();
    // The continuation needs the triangles of circumradius up to 2^(j+1+kGoOnReach) only: a
    // star triangle beyond it (the walk's gap) already says "go on". The slack keeps a
    // triangle at the rule's edge on the walked side. The pairs of class ≤ j in a gap end
    // within 2^(j+1) of v.
    const double reach = std::ldexp(1.0 + 0x1p-20, j + 1 + kGoOnReach);
    const double gap_reach = std::ldexp(1.0 + 0x1p-20, j + 1);
    const bool whole = star_of(v, std::ldexp(1.0, j), reach);
    const std::size_t d = star_.size();
    const bool cycle = !on_boundary(v) && whole;
    bool go_on = !whole;
    // Is p→q loose, given its left and right neighbours when the walk met both triangles
    // (none_: the outside of the box)? For a Delaunay edge they are the vertices nearest the
    // leaf on either side, so they decide, as in the twin, without a search of the leaf's
    // disc; otherwise the cells answer. So a collect reads what its star walk read, plus the
    // cells of the gap's pairs only.
    const auto loose_pair = [&](V p, V q, const V* t, const V* u) {
      if (!t || !u) return loose(p, q);
      ++stats_.leaf_tests;
      return detail::loose(P_(p), P_(q), leaf_height_, *t == none_ ? nullptr : &P_(*t),
                           *u == none_ ? nullptr : &P_(*u));
    };
    // c: the class of vq.
    const auto take = [&](V q, int c, const V* left, const V* right) {
      if (birth ? c > j : c != j) return;
      if (loose_pair(v, q, left, right)) pairs.push_back({v, q});
      if (loose_pair(q, v, right, left)) pairs.push_back({q, v});
    };
    for (std::size_t i = 0; i < d; ++i) {
      const V q = star_[i];
      // Consecutive vertices of star_ bound a walked (true) triangle; the wrap-around does
      // only in a whole cycle (otherwise the gap lies there).
      if (i + 1 < d || cycle) go_on = go_on || circumradius_above(P_(v), P_(q), P_(star_[(i + 1) % d]), j + kGoOnReach);
      // q's neighbours around v: the next vertex of star_ is on the left of v→q, the one
      // before on its right. At the ends of a walk that stopped at the box's sides, the
      // outside; at a gap, unknown.
      const V* left = i + 1 < d ? &star_[i + 1] : cycle ? &star_[0] : whole ? &none_ : nullptr;
      const V* right = i > 0 ? &star_[i - 1] : cycle ? &star_[d - 1] : whole ? &none_ : nullptr;
      // A longer edge continues v only while loose (the twin's rule). Without a gap both its
      // triangles were walked, so the walk decides; with one, go_on is already set.
      const int c = edge_class(P_(v), P_(q));
      if (!go_on && c > j) go_on = loose_pair(v, q, left, right) || loose_pair(q, v, right, left);
      take(q, c, left, right);
    }
    if (!whole && d > 0) {
      // Edges inside the gap have both triangles beyond the cap; those of class ≤ j end
      // within 2^(j+1) of v, and a loose one is an edge (its leaf is empty): ask each vertex
      // there that the walk did not reach. When both walks stopped at the gap, it is the
      // angle from the counter-clockwise run's last vertex a to the clockwise run's last
      // vertex b (counter-clockwise), and only the cells that meet that angle are read.
      near_.clear();
      const Point<2>& c = P_(v);
      const double r = gap_reach + cellq::ulp_room(c);
      const bool angle = gap_ends_ == 2;
      const Point<2>&a = P_(star_.back()), &b = P_(star_.front());
      const bool reflex = angle && orient2d(c, a, b) <= 0;
      // The sign of the cross product (u − c) × (w − c) in doubles, 0 when within rounding.
      const auto side = [&](const Point<2>& u, double wx, double wy) {
        const double ux = u[0] - c[0], uy = u[1] - c[1], vx = wx - c[0], vy = wy - c[1];
        const double cr = ux * vy - uy * vx;
        const double err = 0x1p-40 * (std::abs(ux * vy) + std::abs(uy * vx)) + 0x1p-1000;
        return cr > err ? 1 : cr < -err ? -1 : 0;
      };
      store_->search_within(
          c, r, r, store_->margin_for(c, r),
          [&](double x0, double y0, double x1, double y1) {
            if (BucketTree::box_distance2(c, x0, y0, x1, y1) > r * r) return false;
            if (!angle) return true;
            // Outside the angle for certain: every corner right of ca, or every corner left
            // of cb (a reflex angle: both at once).
            bool right_of_a = true, left_of_b = true;
            for (const auto& [x, y] : {std::pair{x0, y0}, std::pair{x1, y0}, std::pair{x0, y1}, std::pair{x1, y1}}) {
              right_of_a = right_of_a && side(a, x, y) < 0;
              left_of_b = left_of_b && side(b, x, y) > 0;
            }
            return reflex ? !(right_of_a && left_of_b) : !(right_of_a || left_of_b);
          },
          [&](V w) {
            if (w == v || std::find(star_.begin(), star_.end(), w) != star_.end()) return false;
            if (angle) {
              const int oa = orient2d(c, a, P_(w)), ob = orient2d(c, P_(w), b);
              if (reflex ? (oa < 0 && ob < 0) : (oa < 0 || ob < 0)) return false;
            }
            near_.push_back(w);
            return false;
          });
      for (const V q : near_) take(q, edge_class(P_(v), P_(q)), nullptr, nullptr);
    }
    std::sort(pairs.begin(), pairs.end(), [&](const auto& x, const auto& y) {
      if (P_(x[0]) != P_(y[0])) return xy_less(P_(x[0]), P_(y[0]));
      return xy_less(P_(x[1]), P_(y[1]));
    });
    return go_on;
  }

  /// Figure 5, lines 10-14, one try for the ccw side of p→q (the twin's process loop body):
  /// Done when the pair is not loose; else the box edges to split first (the one the
  /// off-center's way out crosses, or those it encroaches), else the off-center to insert.
  /// Throws InputError (Resolution) when the off-center falls on a vertex.
  CellDecision<V> decide(V p, V q, int j) {
    CellDecision<V> out;
    if (!loose(p, q)) return out;
    const Point<2>&a = P_(p), &b = P_(q);
    // Beyond the apex's circle the neighbour does not matter: the off-center is the apex.
    const V t = left_search(p, q, apex_height_ * (1 + 4 * cellq::kSlack));
    // With no neighbour within the apex's reach the off-center is the apex; a far corner
    // stands in for t (the apex's bits do not depend on it: the frame's scaling is exact).
    const Point<2> tp = t != none_ ? P_(t) : far_corner(a, b);
    const auto [r, was_circumcentre] = off_center(a, b, tp, apex_height_);
    if (!std::isfinite(r[0]) || !std::isfinite(r[1]) || (t == none_ && was_circumcentre))
      throw InvariantError(t == none_ && was_circumcentre ? "dynmesh: cell refiner: a circumcentre from beyond the apex"
                                                          : "dynmesh: a non-finite off-center");
    const double scale = std::ldexp(1.0, j);
    if (!(r[0] >= lo_[0] && r[0] <= hi_[0] && r[1] >= lo_[1] && r[1] <= hi_[1])) {
      const auto [s, x] = side_crossed(box_, a, b, r);
      const auto e = side_edge(s, x, scale, false);
      if (!e) return out;
      out.kind = CellDecision<V>::Split;
      out.splits.push_back(*e);
      return out;
    }
    const bool taken = find(r, scale).has_value();
    if (taken)
      throw InputError(InputError::Kind::Resolution, "an off-center falls on the vertex " + format_exact(r[0]) + " " +
                                                         format_exact(r[1]) +
                                                         ": the spread is beyond the mesh's resolution");
    for (int s = 0; s < 4; ++s)
      if (const auto e = encroached_edge(s, r, scale)) out.splits.push_back(*e);
    if (!out.splits.empty()) {
      std::sort(out.splits.begin(), out.splits.end(), [&](const auto& x, const auto& y) {
        return pair_less(P_(x[0]), P_(x[1]), P_(y[0]), P_(y[1]));
      });
      out.kind = CellDecision<V>::Split;
      return out;
    }
    out.kind = CellDecision<V>::Insert;
    out.at = r;
    out.circumcentre = was_circumcentre;
    return out;
  }

  /// v's triangles of the final mesh, those whose (x, y)-smallest corner v is, as (a, b):
  /// the triangle (v, a, b) counter-clockwise. `scale`: v's expected nearest distance.
  /// Only the arc of v's star that is (x, y)-greater than v is walked: those neighbours lie
  /// in a half-plane through v, so they are consecutive around it. From the sure neighbour
  /// the walk goes counter-clockwise until it has left that arc, then, if it started inside
  /// the arc or met a box side before reaching it, clockwise the same way.
  void triangles_of(V v, double scale, std::vector<std::array<V, 2>>& out) {
    out.clear();
    ++stats_.stars;
    const V q0 = sure_neighbour(v, scale);
    if (q0 == none_) return;
    const auto greater = [&](V q) { return xy_less(P_(v), P_(q)); };
    const bool started_in = greater(q0);
    bool seen_in = started_in;
    // Counter-clockwise: the next neighbour of q is the left neighbour of v→q.
    bool closed = false;
    std::size_t steps = 0;
    for (V q = q0;; ++steps) {
      if (outside_left(v, q)) break;  // a box side
      const V t = left_search(v, q, std::numeric_limits<double>::infinity());
      if (t == none_) break;
      if (greater(q) && greater(t)) out.push_back({q, t});
      if (t == q0) {
        closed = true;
        break;
      }
      if (greater(t)) seen_in = true;
      else if (seen_in) break;  // past the arc
      if (steps > 4096) throw InvariantError("dynmesh: a star walk that does not close");
      q = t;
    }
    // Done when the cycle closed, or when the walk entered the arc from its clockwise end.
    if (closed || (seen_in && !started_in)) return;
    // Clockwise from q0: the next neighbour of q is the left neighbour of q→v.
    for (V q = q0;;) {
      if (outside_left(q, v)) return;
      const V t = left_search(q, v, std::numeric_limits<double>::infinity());
      if (t == none_ || t == q0) return;
      if (greater(q) && greater(t)) out.push_back({t, q});
      if (greater(t)) seen_in = true;
      else if (seen_in) return;
      if (++steps > 8192) throw InvariantError("dynmesh: a star walk that does not close");
      q = t;
    }
  }

 private:
  /// The box corner farthest from pq (a stand-in neighbour that makes the apex win).
  Point<2> far_corner(const Point<2>& a, const Point<2>& b) const noexcept {
    const double mx = 0.5 * a[0] + 0.5 * b[0], my = 0.5 * a[1] + 0.5 * b[1];
    return Point<2>{mx - lo_[0] > hi_[0] - mx ? lo_[0] : hi_[0], my - lo_[1] > hi_[1] - my ? lo_[1] : hi_[1]};
  }

  /// The box edge of side s (0 bottom, 1 right, 2 top, 3 left) around the coordinate x along
  /// it: with `holding`, the one whose open interval holds x (none when x is a vertex's
  /// coordinate); otherwise the one holding x in [a, b), clamped to the side's first and last
  /// edges (the twin's std::map::upper_bound rule). As (lower, upper) along the side. The
  /// side's vertices are searched nearest first from the point x of the side.
  std::optional<std::array<V, 2>> side_edge(int s, double x, double scale, bool holding) const {
    const unsigned along = s % 2 == 0 ? 0 : 1;
    const double across = s == 0 ? lo_[1] : s == 1 ? hi_[0] : s == 2 ? hi_[1] : lo_[0];
    Point<2> X;
    X[along] = x;
    X[1 - along] = across;
    // below: the last side vertex at or before x; above: the first after x.
    V below = none_, above = none_;
    const auto scan = [&](double lim_lo, bool strict_below) {
      store_->search(
          X, scale, store_->margin_for(X, scale),
          [&](double x0, double y0, double x1, double y1) {
            const double c0[2] = {x0, y0}, c1[2] = {x1, y1};
            if (!(c0[1 - along] <= across && across <= c1[1 - along])) return false;
            const double lo = below != none_ ? P_(below)[along] : lim_lo;
            const double hi = above != none_ ? P_(above)[along] : std::numeric_limits<double>::infinity();
            return c1[along] >= lo && c0[along] <= hi;
          },
          [&](V w) {
            const Point<2>& pw = P_(w);
            if (pw[1 - along] != across) return false;
            const bool is_below = strict_below ? pw[along] < x : pw[along] <= x;
            if (is_below) {
              if (below == none_ || pw[along] > P_(below)[along]) below = w;
            } else if (!strict_below && (above == none_ || pw[along] < P_(above)[along])) {
              above = w;
            }
            return false;
          });
      // The answer is the side's vertices next to x: it changes only if a side vertex
      // enters or leaves the closed stretch between them. So the scan used that stretch of
      // the side line, not the leaves' other vertices: a coarse leaf that reaches from the
      // side deep into the box (a sparse quadrant) changes with vertices far from the side.
      const double s0 = below != none_ ? P_(below)[along] : lo_[along];
      const double s1 = above != none_ ? P_(above)[along] : hi_[along];
      if (along == 0) store_->used_box(s0, across, s1, across);
      else store_->used_box(across, s0, across, s1);
    };
    scan(-std::numeric_limits<double>::infinity(), false);
    if (holding) {
      if (below == none_ || above == none_ || !(P_(below)[along] < x)) return std::nullopt;
      return std::array<V, 2>{below, above};
    }
    if (above == none_) {
      // x is the side's far end (a corner): the side's last edge.
      above = below;
      below = none_;
      scan(-std::numeric_limits<double>::infinity(), true);
      if (below == none_) return std::nullopt;
      return std::array<V, 2>{below, above};
    }
    if (below == none_) throw InvariantError("dynmesh: a side crossing before the side's first corner");
    return std::array<V, 2>{below, above};
  }

  /// The box edge of side s that r encroaches and whose triangle holds r in its circle (the
  /// twin's cavity box edge), if any. Only the edge holding r's projection can have r
  /// strictly inside its diametral disc.
  std::optional<std::array<V, 2>> encroached_edge(int s, const Point<2>& r, double scale) {
    const unsigned along = s % 2 == 0 ? 0 : 1;
    const auto held = side_edge(s, r[along], scale, true);  // none: r projects onto a vertex
    if (!held) return std::nullopt;
    const V lo_end = (*held)[0], hi_end = (*held)[1];
    if (!encroaches(P_(lo_end), P_(hi_end), r)) return std::nullopt;
    // The edge in counter-clockwise order along the boundary (the inside on its left).
    const bool forward = s == 0 || s == 1;
    const V ea = forward ? lo_end : hi_end, eb = forward ? hi_end : lo_end;
    // Its triangle: the edge's left neighbour x. The circle through ea, eb and x holds r
    // (strictly inside the diametral disc, on the inner side) unless x lies strictly inside
    // the diametral disc too; then the perturbed in-circle test decides, as for the twin's
    // cavity.
    const V x = left_search(ea, eb, 0.0);
    if (x != none_ && encroaches(P_(ea), P_(eb), P_(x)) && !perturbed_incircle(P_(ea), P_(eb), P_(x), r))
      return std::nullopt;
    return std::array<V, 2>{ea, eb};
  }

  Box<2> box_;
  const Store* store_;
  Coords P_;
  V none_;
  CellQuestionStats& stats_;
  double lo_[2], hi_[2];
  double apex_height_ = 0, leaf_height_ = 0;
  std::vector<V> star_, back_;
  mutable std::vector<V> near_, near_all_;
  int gap_ends_ = 0;  // star_of's walks that stopped at its cap (0, 1 or 2)
};

}  // namespace dynmesh::detail
