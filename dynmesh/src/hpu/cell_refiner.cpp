// cell_refiner.cpp — the hpu refinement on cell questions (see cell_refiner.hpp).
#include "hpu/cell_refiner.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dynmesh/errors.hpp"
#include "dynmesh/predicates.hpp"
#include "dynmesh/quadtree_mesh.hpp"
#include "geometry/delaunay.hpp"  // perturbed_incircle: the twin's tie rule
#include "hpu/bucket_tree.hpp"
#include "hpu/hpu_geometry.hpp"
#include "io/locate_points.hpp"

namespace dynmesh::detail {
namespace {

using Vid = std::uint32_t;
constexpr Vid kNone = 0xffff'ffffu;

/// Relative slack of the "circumdisc inside the gathered disc" test: far above the rounding
/// of the circumcentre (a few ulps), far below any gap the tests rely on.
constexpr double kSlack = 0x1p-20;

/// An absolute allowance for the rounding of coordinates near p: computed centres and
/// differences are off by a few ulps of the coordinates, which can be large against a small
/// question's radius.
double ulp_room(const Point<2>& p) noexcept { return std::max(std::abs(p[0]), std::abs(p[1])) * 0x1p-40; }

std::uint64_t mix(std::uint64_t h) noexcept {
  h ^= h >> 30;
  h *= 0xbf58476d1ce4e5b9ULL;
  h ^= h >> 27;
  h *= 0x94d049bb133111ebULL;
  return h ^ (h >> 31);
}
std::uint64_t mix(std::uint64_t h, std::uint64_t x) noexcept { return mix(h * 0x9e3779b97f4a7c15ULL + x); }
std::uint64_t mix(std::uint64_t h, const Point<2>& p) noexcept {
  return mix(mix(h, std::bit_cast<std::uint64_t>(p[0] + 0.0)), std::bit_cast<std::uint64_t>(p[1] + 0.0));
}

class CellRefiner {
 public:
  CellRefiner(const Box<2>& box, double min_angle_deg, std::size_t max_vertices, CellRefinement& out,
              const CellRefineOptions& options)
      : box_(box), tree_(box), sides_(box), max_vertices_(max_vertices), out_(out), check_tree_(options.check_tree),
        log_steps_(options.log_steps) {
    apex_height_ = apex_height(min_angle_deg);
    leaf_height_ = leaf_height(min_angle_deg);
    lo_[0] = box.origin[0], lo_[1] = box.origin[1];
    hi_[0] = box.origin[0] + box.side, hi_[1] = box.origin[1] + box.side;
    // The corners first (vertices 0-3: the first entries' order puts them ahead).
    for (const Point<2>& c : {Point<2>{lo_[0], lo_[1]}, Point<2>{hi_[0], lo_[1]}, Point<2>{hi_[0], hi_[1]},
                              Point<2>{lo_[0], hi_[1]}})
      add(c);
  }

  void insert_inputs(std::span<const Point<2>> points) {
    for (const Point<2>& m : side_midpoints(box_, points)) {
      if (!find(m)) add(m);
      ++out_.stats.side_splits;
    }
    for (const Point<2>& p : points)
      if (!find(p)) add(p);
  }

  void refine() {
    for (const Vid v : first_entry_order(box_, pts_)) {
      step_begin();
      const int c = first_class(v);
      step_end(CellStep::FirstClass, mix(0, pts_[v]), static_cast<std::uint64_t>(c));
      queues_[c].push_back({v, true});
    }
    run_rounds(queues_, batch_, pairs_, out_.stats.rounds, [&](const Entry& e, int j) { collect(e.v, j, e.birth); },
               [&](Vid p, Vid q, int j) { process(p, q, j); });
  }

  /// The Delaunay triangulation of all vertices, each triangle found from the local star of
  /// its (x, y)-smallest corner.
  std::vector<Triangle> triangles() {
    std::vector<Triangle> out;
    const std::size_t before = out_.questions.leaves_read;
    for (Vid v = 0; v < pts_.size(); ++v) {
      step_begin();
      std::uint64_t answer = 0;
      star_of(v);
      const std::size_t d = star_.size();
      const bool cycle = !on_boundary(v);
      for (std::size_t i = 0; i < d; ++i) {
        if (i + 1 == d && !cycle) break;
        const Vid a = star_[i], b = star_[(i + 1) % d];
        if (xy_less(pts_[v], pts_[a]) && xy_less(pts_[v], pts_[b])) {
          out.push_back(canonical_triangle(pts_[v], pts_[a], pts_[b]));
          answer = mix(mix(answer, pts_[a]), pts_[b]);
        }
      }
      step_end(CellStep::Final, mix(3, pts_[v]), answer);
    }
    std::sort(out.begin(), out.end());
    out_.questions.leaves_final += out_.questions.leaves_read - before;
    return out;
  }

  void check() const { tree_.check_invariants(pts_); }

 private:
  struct Entry {
    Vid v;
    bool birth;
  };

  // The step log (CellStep): what the cells hand out between step_begin and step_end.
  static std::uint64_t vertex_digest(const void* self, Vid v) {
    return mix(0x5eed, static_cast<const CellRefiner*>(self)->pts_[v]);
  }
  void step_begin() {
    if (!log_steps_) return;
    seen_ = 0;
    step_leaf_ids_.clear();
    tree_.watch(&seen_, &vertex_digest, this, &step_leaf_ids_);
  }
  void step_end(CellStep::Kind kind, std::uint64_t key, std::uint64_t answer, int cls = 0) {
    if (!log_steps_) return;
    tree_.watch(nullptr, nullptr, nullptr);
    // A step reads a leaf once (a self-adjusting step keeps what it read): distinct leaves.
    std::sort(step_leaf_ids_.begin(), step_leaf_ids_.end());
    const auto distinct = std::unique(step_leaf_ids_.begin(), step_leaf_ids_.end()) - step_leaf_ids_.begin();
    out_.steps.push_back(CellStep{mix(mix(mix(key, kind), answer), seen_), static_cast<std::uint32_t>(distinct), kind,
                                  static_cast<std::int16_t>(std::clamp(cls, -30000, 30000))});
  }

  Vid add(const Point<2>& p) {
    const auto v = static_cast<Vid>(pts_.size());
    pts_.push_back(p);
    tree_.insert(v, p, pts_);
    sides_.note(p, v);
    if (pts_.size() > max_vertices_)
      throw InvariantError("dynmesh: hpu refinement did not terminate (over " + std::to_string(max_vertices_) +
                           " vertices)");
    if (check_tree_) tree_.check_invariants(pts_);
    return v;
  }

  /// The vertex at p, if any (a point query on the cells).
  std::optional<Vid> find(const Point<2>& p) const {
    std::optional<Vid> hit;
    tree_.visit(p, p, [&](Vid v) {
      if (pts_[v] == p) hit = v;
    });
    return hit;
  }

  bool on_boundary(Vid v) const noexcept {
    const Point<2>& p = pts_[v];
    return p[0] == lo_[0] || p[0] == hi_[0] || p[1] == lo_[1] || p[1] == hi_[1];
  }


  /// Is the outside of the box on the left of p→q? (Both on one side, q before p in the
  /// side's counter-clockwise direction.)
  bool outside_left(Vid p, Vid q) const noexcept {
    const Point<2>&a = pts_[p], &b = pts_[q];
    if (a[1] == lo_[1] && b[1] == lo_[1]) return b[0] < a[0];
    if (a[0] == hi_[0] && b[0] == hi_[0]) return b[1] < a[1];
    if (a[1] == hi_[1] && b[1] == hi_[1]) return b[0] > a[0];
    if (a[0] == lo_[0] && b[0] == lo_[0]) return b[1] > a[1];
    return false;
  }

  /// p→q is ccw-loose: the outside of the box is not on its left and no vertex lies strictly
  /// inside its ccw-leaf (the cells the leaf meets are asked; the first vertex inside ends
  /// the search's use).
  bool loose(Vid p, Vid q) const {
    ++out_.questions.leaf_tests;
    if (outside_left(p, q)) return false;
    const Point<2>&a = pts_[p], &b = pts_[q];
    // The leaf: centre m + k·J(q − p), radius ρ|pq| = |c − p|.
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const Point<2> c{0.5 * a[0] + 0.5 * b[0] - leaf_height_ * dy, 0.5 * a[1] + 0.5 * b[1] + leaf_height_ * dx};
    const double r = std::hypot(c[0] - a[0], c[1] - a[1]) * (1 + kSlack) + ulp_room(c);
    bool empty = true;
    const std::size_t before = tree_.leaves_read();
    tree_.visit_disc(c, r, [&](Vid v) {
      if (v != p && v != q && pencil(a, b, leaf_height_, pts_[v]) < 0) empty = false;
      return !empty;
    });
    out_.questions.leaves_read += tree_.leaves_read() - before;
    return empty;
  }

  /// The distance from v to its nearest vertex, in doubles: a nearest-first search of the
  /// cells that reads only those nearer than the best found so far.
  double nearest_distance(Vid v) const {
    const Point<2>& p = pts_[v];
    double best = std::numeric_limits<double>::infinity();
    tree_.search(
        p, tree_.margin_for(p, 0.0),
        [&](double x0, double y0, double x1, double y1) {
          return std::sqrt(BucketTree::box_distance2(p, x0, y0, x1, y1)) <= best;
        },
        [&](Vid w) {
          if (w != v) best = std::min(best, std::hypot(pts_[w][0] - p[0], pts_[w][1] - p[1]));
          return false;
        });
    return best;
  }

  /// Some vertex that v has an edge to in every Delaunay triangulation: the nearest one whose
  /// closed diametral disc with v holds no other vertex (a vertex inside or on that disc is
  /// strictly nearer, so the search ends).
  Vid sure_neighbour(Vid v) const {
    const double d = nearest_distance(v);
    Vid a = kNone;
    tree_.visit_disc(pts_[v], d * (1 + kSlack) + ulp_room(pts_[v]), [&](Vid w) {
      if (w != v && (a == kNone || std::hypot(pts_[w][0] - pts_[v][0], pts_[w][1] - pts_[v][1]) <
                                       std::hypot(pts_[a][0] - pts_[v][0], pts_[a][1] - pts_[v][1])))
        a = w;
      return false;
    });
    for (;;) {
      const Vid inside = diametral_intruder(v, a);
      if (inside == kNone) return a;
      a = inside;
    }
  }

  /// A vertex other than v and q inside or on the closed diametral disc of v and q (one is
  /// strictly nearer to v than q is), or kNone.
  Vid diametral_intruder(Vid v, Vid q) const {
    const Point<2>&a = pts_[v], &b = pts_[q];
    const Point<2> m{0.5 * a[0] + 0.5 * b[0], 0.5 * a[1] + 0.5 * b[1]};
    Vid inside = kNone;
    tree_.visit_disc(m, 0.5 * std::hypot(b[0] - a[0], b[1] - a[1]) * (1 + kSlack) + ulp_room(m), [&](Vid w) {
      if (w != v && w != q && pencil(a, b, 0.0, pts_[w]) <= 0) inside = w;
      return inside != kNone;
    });
    return inside;
  }

  /// The Delaunay neighbour of p→q on its left (the third corner of the triangle on its
  /// left, under the triangulations' perturbation): of the vertices on the left, the one
  /// whose circle through p and q lies lowest in the pencil of circles through p and q,
  /// searched among the circles centred at most h_max·|pq| along J(q − p) from pq's
  /// midpoint, smallest first, each asked of the cells its disc meets. kNone when none
  /// lies that low (or the left is outside the box).
  Vid left_search(Vid p, Vid q, double h_max) const {
    ++out_.questions.neighbour_asks;
    if (outside_left(p, q)) return kNone;  // a box edge seen from outside: no triangle there
    const Point<2>&a = pts_[p], &b = pts_[q];
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const double len = std::hypot(dx, dy);
    const Point<2> m{0.5 * a[0] + 0.5 * b[0], 0.5 * a[1] + 0.5 * b[1]};
    const std::size_t before = tree_.leaves_read();
    // Does the box [x0, x1] × [y0, y1] meet the disc (c, r)?
    const auto meets = [](double x0, double y0, double x1, double y1, const Point<2>& c, double r) {
      return BucketTree::box_distance2(c, x0, y0, x1, y1) <= r * r;
    };
    // The disc of the circle through p and q at height h, widened for rounding.
    const auto disc = [&](double h, Point<2>& c, double& r) {
      c = Point<2>{m[0] - h * dy, m[1] + h * dx};
      r = len * std::sqrt(0.25 + h * h) * (1 + kSlack) + ulp_room(c);
    };
    Vid best = kNone;
    for (double h = std::min(0.25, h_max);; h = std::min(2 * h, h_max)) {
      Point<2> pc, bc{};
      double pr, br = 0;
      disc(h, pc, pr);
      // Within the probe, a cell is read only while it can hold a vertex below the best
      // circle found so far (a vertex on that circle can still win a perturbed tie, hence
      // the widening).
      tree_.search(
          pc, tree_.margin_for(pc, pr),
          [&](double x0, double y0, double x1, double y1) {
            return meets(x0, y0, x1, y1, pc, pr) && (best == kNone || meets(x0, y0, x1, y1, bc, br));
          },
          [&](Vid w) {
            if (w == p || w == q || orient2d(a, b, pts_[w]) <= 0 || pencil(a, b, h, pts_[w]) > 0) return false;
            if (best == kNone || perturbed_incircle(a, b, pts_[best], pts_[w])) {
              best = w;
              const Point<2>& t = pts_[w];
              // The best circle's height: (t − p)·(t − q) = 2h·orient(p, q, t). Only a
              // well-conditioned one (t not nearly on pq's line) narrows the search; its
              // relative error is then far below the widening.
              const double tx = t[0] - a[0], ty = t[1] - a[1];
              const double cross = dx * ty - dy * tx;
              const double hb = (tx * (t[0] - b[0]) + ty * (t[1] - b[1])) / (2 * cross);
              if (cross > 0x1p-20 * std::hypot(tx, ty) * len && std::isfinite(hb) && hb < h) {
                disc(hb, bc, br);
                br = br * (1 + 0x1p-10) + ulp_room(bc);
              } else {
                bc = pc, br = pr;
              }
            }
            return false;
          });
      if (best != kNone || h >= h_max) break;
    }
    out_.questions.leaves_read += tree_.leaves_read() - before;
    return best;
  }

  /// v's star, counter-clockwise (as Delaunay::star gives it: a cycle for an interior
  /// vertex, from one box side to the other for a vertex on the boundary), walked from a
  /// sure neighbour by left searches. With a radius R, each step searches only the circles
  /// of radius at most R: the walk then stops where the next triangle's circumradius
  /// exceeds R, and returns false (star_ then holds the star's two ends around that gap,
  /// cut into at most two runs: the counter-clockwise run from the sure neighbour, then the
  /// clockwise one, put first).
  bool star_of(Vid v, double R = std::numeric_limits<double>::infinity()) {
    ++out_.questions.stars;
    const Vid q0 = sure_neighbour(v);
    const auto h_cap = [&](Vid a, Vid b) {
      if (R == std::numeric_limits<double>::infinity()) return R;
      const double half = 0.5 * std::hypot(pts_[b][0] - pts_[a][0], pts_[b][1] - pts_[a][1]);
      return R > half ? std::sqrt((R / (2 * half)) * (R / (2 * half)) - 0.25) : -1.0;
    };
    // One walk from q0 around v, counter-clockwise (the left of v→q) or clockwise (the left
    // of q→v), and why it ended.
    enum class End { Closed, Side, Gap, Met };
    const auto walk = [&](bool ccw, bool stop_at_star, std::vector<Vid>& out) {
      for (Vid q = q0;;) {
        const Vid a = ccw ? v : q, b = ccw ? q : v;
        if (outside_left(a, b)) return End::Side;  // a box side: the fan ends
        const double h = h_cap(a, b);
        const Vid t = h < 0 ? kNone : left_search(a, b, h);
        if (t == kNone) return End::Gap;
        if (t == q0) return End::Closed;
        if (stop_at_star && std::find(star_.begin(), star_.end(), t) != star_.end()) return End::Met;
        out.push_back(t);
        q = t;
      }
    };
    star_.assign(1, q0);
    const End ccw = walk(true, false, star_);
    if (ccw == End::Closed) {
      gap_ends_ = 0;
      return true;
    }
    back_.clear();
    const End cw = walk(false, ccw == End::Gap, back_);  // stops where it meets the other run
    gap_ends_ = (ccw == End::Gap) + (cw == End::Gap);
    star_.insert(star_.begin(), back_.rbegin(), back_.rend());
    return gap_ends_ == 0;
  }

  /// Does the closed diametral disc of v and q hold no other vertex? (Then vq is an edge
  /// of every Delaunay triangulation.)
  bool diametral_empty(Vid v, Vid q) const { return diametral_intruder(v, q) == kNone; }

  /// The class of v's shortest Delaunay edge. edge_class is ⌊log2 |pq|⌋ but where rounding
  /// moves |pq|² across a power of four, so an edge longer than the nearest one by more
  /// than a relative 2^-40 is of no lower class: only the nearest vertices (ties included)
  /// can set the minimum. Each that has an empty closed diametral disc is an edge; if one
  /// of a lower class has not, the star decides (exact ties at a power of two).
  int first_class(Vid v) {
    const double d = nearest_distance(v);
    near_.clear();
    tree_.visit_disc(pts_[v], d * (1 + 0x1p-39) + ulp_room(pts_[v]), [&](Vid w) {
      if (w != v) near_.push_back(w);
      return false;
    });
    out_.questions.gathered_first += near_.size();
    int best = INT_MAX, unsure = INT_MAX;
    for (const Vid q : near_) {
      const int c = edge_class(pts_[v], pts_[q]);
      if (c >= best) continue;
      if (diametral_empty(v, q)) best = c;
      else unsure = std::min(unsure, c);
    }
    if (best != INT_MAX && unsure >= best) return best;
    star_of(v);
    best = INT_MAX;
    for (const Vid q : star_) best = std::min(best, edge_class(pts_[v], pts_[q]));
    return best;
  }

  /// Figure 5, line 7, for one vertex (the twin's collect): its loose pairs of class j (≤ j
  /// at its first entry), in (x, y) order, and its continuation into Q_{j+1}.
  void collect(Vid v, int j, bool birth) {
    ++out_.stats.entries;
    step_begin();
    const std::size_t before = out_.questions.leaves_read;
    // The continuation needs the triangles of circumradius up to 2^(j+1) only: a star
    // triangle beyond it (the walk's gap) already says "go on". The slack keeps a triangle
    // at the rule's edge on the walked side.
    const bool whole = star_of(v, std::ldexp(1.0 + 0x1p-20, j + 1));
    const std::size_t d = star_.size();
    const bool cycle = !on_boundary(v) && whole;
    bool go_on = !whole;
    local_pairs_.clear();
    const auto take = [&](Vid q) {
      const int c = edge_class(pts_[v], pts_[q]);
      if (birth ? c > j : c != j) return;
      if (loose(v, q)) local_pairs_.push_back({v, q});
      if (loose(q, v)) local_pairs_.push_back({q, v});
    };
    for (std::size_t i = 0; i < d; ++i) {
      const Vid q = star_[i];
      // Consecutive vertices of star_ bound a walked (true) triangle; the wrap-around does
      // only in a whole cycle (otherwise the gap lies there).
      if (i + 1 < d || cycle) go_on = go_on || circumradius_above(pts_[v], pts_[q], pts_[star_[(i + 1) % d]], j);
      if (edge_class(pts_[v], pts_[q]) > j) go_on = true;
      take(q);
    }
    if (!whole) {
      // Edges inside the gap have both triangles beyond 2^(j+1); those of class ≤ j end
      // within 2^(j+1) of v, and a loose one is an edge (its leaf is empty): ask each vertex
      // there that the walk did not reach.
      // When both walks stopped at the gap, it is the angle from the counter-clockwise run's
      // last vertex a to the clockwise run's last vertex b (counter-clockwise), and only the
      // cells that meet that angle are read.
      near_.clear();
      const Point<2>& c = pts_[v];
      const double reach = std::ldexp(1.0 + 0x1p-20, j + 1) + ulp_room(c);
      const bool angle = gap_ends_ == 2;
      const Point<2>&a = pts_[star_.back()], &b = pts_[star_.front()];
      const bool reflex = angle && orient2d(c, a, b) <= 0;
      // The sign of the cross product (u − c) × (w − c) in doubles, 0 when within rounding.
      const auto side = [&](const Point<2>& u, double wx, double wy) {
        const double ux = u[0] - c[0], uy = u[1] - c[1], vx = wx - c[0], vy = wy - c[1];
        const double cr = ux * vy - uy * vx;
        const double err = 0x1p-40 * (std::abs(ux * vy) + std::abs(uy * vx)) + 0x1p-1000;
        return cr > err ? 1 : cr < -err ? -1 : 0;
      };
      tree_.search(
          c, tree_.margin_for(c, reach),
          [&](double x0, double y0, double x1, double y1) {
            if (BucketTree::box_distance2(c, x0, y0, x1, y1) > reach * reach) return false;
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
          [&](Vid w) {
            if (w == v || std::find(star_.begin(), star_.end(), w) != star_.end()) return false;
            if (angle) {
              const int oa = orient2d(c, a, pts_[w]), ob = orient2d(c, pts_[w], b);
              if (reflex ? (oa < 0 && ob < 0) : (oa < 0 || ob < 0)) return false;
            }
            near_.push_back(w);
            return false;
          });
      for (const Vid q : near_) take(q);  // local_pairs_ is sorted below
    }
    std::sort(local_pairs_.begin(), local_pairs_.end(), [&](const auto& a, const auto& b) {
      if (pts_[a[0]] != pts_[b[0]]) return xy_less(pts_[a[0]], pts_[b[0]]);
      return xy_less(pts_[a[1]], pts_[b[1]]);
    });
    pairs_.insert(pairs_.end(), local_pairs_.begin(), local_pairs_.end());
    if (go_on) queues_[j + 1].push_back({v, false});
    std::uint64_t answer = go_on;
    for (const auto& [a, b] : local_pairs_) answer = mix(mix(answer, pts_[a]), pts_[b]);
    step_end(CellStep::Collect, mix(mix(mix(1, pts_[v]), static_cast<std::uint64_t>(j)), birth), answer, j);
    out_.questions.leaves_collect += out_.questions.leaves_read - before;
  }

  /// Figure 5, lines 10-14, for the ccw side of p→q (the twin's process).
  void process(Vid p, Vid q, int j) {
    step_begin();
    std::uint64_t answer = 0;
    process_steps(p, q, j, answer);
    step_end(CellStep::Process, mix(mix(mix(2, pts_[p]), pts_[q]), static_cast<std::uint64_t>(j)), answer, j);
  }

  void process_steps(Vid p, Vid q, int j, std::uint64_t& answer) {
    const std::size_t before = out_.questions.leaves_read;
    struct Count {
      std::size_t& total;
      std::size_t& mine;
      std::size_t before;
      ~Count() { mine += total - before; }
    } count{out_.questions.leaves_read, out_.questions.leaves_process, before};
    for (;;) {
      if (!loose(p, q)) return;
      ++out_.stats.loose_pairs;
      const Point<2>&a = pts_[p], &b = pts_[q];
      // Beyond the apex's circle the neighbour does not matter: the off-center is the apex.
      const Vid t = left_search(p, q, apex_height_ * (1 + 4 * kSlack));
      // With no neighbour within the apex's reach the off-center is the apex; a far corner
      // stands in for t (the apex's bits do not depend on it: the frame's scaling is exact).
      const Point<2>& tp = t != kNone ? pts_[t] : far_corner(a, b);
      const auto [r, was_circumcentre] = off_center(a, b, tp, apex_height_);
      if (t == kNone && was_circumcentre)
        throw InvariantError("dynmesh: cell refiner: a circumcentre from beyond the apex");
      if (!std::isfinite(r[0]) || !std::isfinite(r[1])) throw InvariantError("dynmesh: a non-finite off-center");
      if (!(r[0] >= lo_[0] && r[0] <= hi_[0] && r[1] >= lo_[1] && r[1] <= hi_[1])) {
        split_crossed(a, b, r, j);
        answer = mix(answer, pts_.back());
        continue;
      }
      if (find(r))
        throw InputError(InputError::Kind::Resolution,
                         "an off-center falls on the vertex " + format_exact(r[0]) + " " + format_exact(r[1]) +
                             ": the spread is beyond the mesh's resolution");
      encroached_.clear();
      for (int s = 0; s < 4; ++s)
        if (const auto e = encroached_edge(s, r)) encroached_.push_back(*e);
      if (!encroached_.empty()) {
        std::sort(encroached_.begin(), encroached_.end(), [&](const auto& x, const auto& y) {
          return pair_less(pts_[x[0]], pts_[x[1]], pts_[y[0]], pts_[y[1]]);
        });
        for (const auto& s : encroached_) {
          split_side(s[0], s[1], j);
          answer = mix(answer, pts_.back());
        }
        continue;
      }
      const Vid rv = add(r);
      answer = mix(answer, r);
      ++out_.stats.off_centers;
      if (was_circumcentre) ++out_.stats.circumcentres;
      queues_[j].push_back({rv, true});
      return;
    }
  }

  /// The box corner farthest from pq (a stand-in neighbour that makes the apex win).
  Point<2> far_corner(const Point<2>& a, const Point<2>& b) const noexcept {
    const double mx = 0.5 * a[0] + 0.5 * b[0], my = 0.5 * a[1] + 0.5 * b[1];
    return Point<2>{mx - lo_[0] > hi_[0] - mx ? lo_[0] : hi_[0], my - lo_[1] > hi_[1] - my ? lo_[1] : hi_[1]};
  }

  /// The box edge of side s (0 bottom, 1 right, 2 top, 3 left) that r encroaches and whose
  /// triangle holds r in its circle (the twin's cavity box edge), if any. Only the edge
  /// holding r's projection can have r strictly inside its diametral disc.
  std::optional<std::array<Vid, 2>> encroached_edge(int s, const Point<2>& r) {
    const unsigned along = s % 2 == 0 ? 0 : 1;
    const auto held = sides_.edge_holding(s, r[along]);  // none: r projects onto a vertex
    if (!held) return std::nullopt;
    const Vid lo_end = (*held)[0], hi_end = (*held)[1];
    if (!encroaches(pts_[lo_end], pts_[hi_end], r)) return std::nullopt;
    // The edge in counter-clockwise order along the boundary (the inside on its left).
    const bool forward = s == 0 || s == 1;
    const Vid ea = forward ? lo_end : hi_end, eb = forward ? hi_end : lo_end;
    // Its triangle: the edge's left neighbour x. The circle through ea, eb and x holds r
    // (strictly inside the diametral disc, on the inner side) unless x lies strictly
    // inside the diametral disc too; then the perturbed in-circle test decides, as for the
    // twin's cavity.
    const Vid x = left_search(ea, eb, 0.0);
    if (x != kNone && encroaches(pts_[ea], pts_[eb], pts_[x]) && !perturbed_incircle(pts_[ea], pts_[eb], pts_[x], r))
      return std::nullopt;
    return std::array<Vid, 2>{ea, eb};
  }

  /// The twin's split_crossed: the box edge holding the first crossing of m→r with the box.
  void split_crossed(const Point<2>& p, const Point<2>& q, const Point<2>& r, int j) {
    const auto [side, x] = side_crossed(box_, p, q, r);
    const auto e = sides_.edge_around(side, x);
    split_side(e[0], e[1], j);
  }

  void split_side(Vid a, Vid b, int j) {
    const Point<2> mid = side_midpoint(pts_[a], pts_[b]);
    if (find(mid)) throw InvariantError("dynmesh: a box edge's midpoint is already a vertex");
    const Vid v = add(mid);
    ++out_.stats.side_splits;
    queues_[j].push_back({v, true});
  }

  Box<2> box_;
  BucketTree tree_;
  BoxSides<Vid> sides_;
  double lo_[2], hi_[2];
  double apex_height_ = 0, leaf_height_ = 0;
  std::size_t max_vertices_;
  CellRefinement& out_;
  bool check_tree_, log_steps_;
  std::uint64_t seen_ = 0;
  std::vector<std::uint32_t> step_leaf_ids_;
  std::vector<Point<2>> pts_;
  std::map<int, std::vector<Entry>> queues_;
  std::vector<Entry> batch_;
  std::vector<Vid> star_, back_, near_;
  int gap_ends_ = 0;  // star_of's walks that stopped at its cap (0, 1 or 2)
  std::vector<std::array<Vid, 2>> pairs_, local_pairs_, encroached_;
};

}  // namespace

CellRefinement cell_refine(const Box<2>& box, std::span<const Point<2>> points, double min_angle_deg,
                           const CellRefineOptions& options) {
  validate_min_angle(min_angle_deg);
  const auto qs = locate_all(box, points);
  check_separated(qs);
  check_resolution(MeshGrid(box), points, qs);
  validate_mesh_box(box);
  const std::size_t max_vertices = 1000 * (points.size() + 4) + (std::size_t{1} << 20);
  CellRefinement out;
  CellRefiner refiner(box, min_angle_deg, max_vertices, out, options);
  refiner.insert_inputs(points);
  refiner.refine();
  out.triangles = refiner.triangles();
  refiner.check();
  return out;
}

}  // namespace dynmesh::detail
