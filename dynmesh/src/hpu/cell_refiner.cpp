// cell_refiner.cpp — the hpu refinement on cell questions (see cell_refiner.hpp).
#include "hpu/cell_refiner.hpp"

#include <algorithm>
#include <array>
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
#include "geometry/delaunay.hpp"
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

/// The circumcentre of a, b, c and its squared radius, in doubles relative to a (scaled by
/// a power of two, exact, so that squares neither overflow nor underflow); nullopt when the
/// three are (numerically) collinear.
std::optional<std::pair<Point<2>, double>> circumcircle(const Point<2>& a, const Point<2>& b, const Point<2>& c) {
  double bx = b[0] - a[0], by = b[1] - a[1], cx = c[0] - a[0], cy = c[1] - a[1];
  const double m = std::max({std::abs(bx), std::abs(by), std::abs(cx), std::abs(cy)});
  if (!(m > 0)) return std::nullopt;
  const int e = std::ilogb(m);
  bx = std::ldexp(bx, -e), by = std::ldexp(by, -e), cx = std::ldexp(cx, -e), cy = std::ldexp(cy, -e);
  const double d = 2.0 * (bx * cy - by * cx);
  if (d == 0) return std::nullopt;
  const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  const double ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
  if (!std::isfinite(ux) || !std::isfinite(uy)) return std::nullopt;
  return std::pair{Point<2>{a[0] + std::ldexp(ux, e), a[1] + std::ldexp(uy, e)},
                   std::ldexp(ux * ux + uy * uy, 2 * e)};
}

/// An absolute allowance for the rounding of coordinates near p: computed centres and
/// differences are off by a few ulps of the coordinates, which can be large against a small
/// question's radius.
double ulp_room(const Point<2>& p) noexcept { return std::max(std::abs(p[0]), std::abs(p[1])) * 0x1p-40; }

/// Does the circumdisc of a, b, c lie inside the disc (centre, r), with slack to spare?
bool disc_inside(const Point<2>& a, const Point<2>& b, const Point<2>& c, const Point<2>& centre, double r) {
  const auto cc = circumcircle(a, b, c);
  if (!cc) return false;
  const double dx = cc->first[0] - centre[0], dy = cc->first[1] - centre[1];
  const double reach = std::sqrt(dx * dx + dy * dy) + std::sqrt(cc->second) + 2 * ulp_room(centre);
  return reach <= r * (1 - kSlack);
}

/// A Delaunay triangulation of the box's corners and the vertices within r of a centre:
/// the answers of one question. Local vertex i < 4 is global corner i.
class Local {
 public:
  explicit Local(const Box<2>& box) : box_(box) {}

  /// Gathers and triangulates; `want` are global vertices whose local ids the caller needs
  /// (each must lie within the radius).
  void build(const BucketTree& tree, std::span<const Point<2>> pts, const Point<2>& centre, double r,
             CellQuestionStats& qs) {
    centre_ = centre;
    r_ = r;
    const std::size_t before = tree.leaves_read();
    tree.gather(centre, r + ulp_room(centre), pts, ids_);
    qs.leaves_read += tree.leaves_read() - before;
    ids_.erase(std::remove_if(ids_.begin(), ids_.end(), [](Vid v) { return v < 4; }), ids_.end());
    std::sort(ids_.begin(), ids_.end(), [&](Vid a, Vid b) { return morton_less(box_, pts[a], pts[b]); });
    dt_.emplace(box_);
    global_ = {0, 1, 2, 3};
    global_.reserve(ids_.size() + 4);
    Delaunay::Tid hint = dt_->any_live();
    for (const Vid v : ids_) {
      created_.clear();
      const auto lv = dt_->insert(pts[v], hint, created_);
      if (!lv) throw InvariantError("dynmesh: cell refiner: a vertex stored twice");
      global_.push_back(v);
      if (!created_.empty()) hint = created_.back();
    }
    qs.points_gathered += ids_.size();
    qs.max_gathered = std::max(qs.max_gathered, ids_.size());
  }

  const Delaunay& dt() const noexcept { return *dt_; }
  Vid global(Delaunay::Vid l) const noexcept { return global_[l]; }
  /// The local id of global vertex g (which build() gathered).
  Delaunay::Vid local(Vid g) const {
    if (g < 4) return g;
    for (std::size_t i = 4; i < global_.size(); ++i)
      if (global_[i] == g) return static_cast<Delaunay::Vid>(i);
    throw InvariantError("dynmesh: cell refiner: a vertex outside its question's disc");
  }
  /// Is the local triangle (a, b, c) a triangle of the whole vertex set? (Its circumdisc lies
  /// in the gathered disc, so no vertex left out can be inside it.)
  bool certain(Delaunay::Vid a, Delaunay::Vid b, Delaunay::Vid c) const {
    return disc_inside(dt_->point(a), dt_->point(b), dt_->point(c), centre_, r_);
  }

 private:
  Box<2> box_;
  Point<2> centre_{};
  double r_ = 0;
  std::optional<Delaunay> dt_;
  std::vector<Vid> ids_, global_;
  std::vector<Delaunay::Tid> created_;
};

class CellRefiner {
 public:
  CellRefiner(const Box<2>& box, double min_angle_deg, std::size_t max_vertices, CellRefinement& out, bool check_tree)
      : box_(box), tree_(box), local_(box), max_vertices_(max_vertices), out_(out), check_tree_(check_tree) {
    apex_height_ = apex_height(min_angle_deg);
    leaf_height_ = leaf_height(min_angle_deg);
    lo_[0] = box.origin[0], lo_[1] = box.origin[1];
    hi_[0] = box.origin[0] + box.side, hi_[1] = box.origin[1] + box.side;
    // The corners, in the order of Delaunay's (so that local ids 0-3 are the corners).
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
    struct Key {
      int level;
      std::uint64_t code;
      Vid v;
    };
    std::vector<Key> order(pts_.size());
    for (Vid v = 0; v < order.size(); ++v)
      order[v] = {v < 4 ? INT_MAX : brio_level(pts_[v]), morton_of(box_, pts_[v]), v};
    std::sort(order.begin(), order.end(), [&](const Key& a, const Key& b) {
      if (a.level != b.level) return a.level > b.level;
      if (a.code != b.code) return a.code < b.code;
      return xy_less(pts_[a.v], pts_[b.v]);
    });
    for (const auto& [level, code, v] : order) queues_[first_class(v)].push_back({v, true});
    while (!queues_.empty()) {
      const auto it = queues_.begin();
      const int j = it->first;
      batch_.swap(it->second);
      queues_.erase(it);
      ++out_.stats.rounds;
      pairs_.clear();
      for (const Entry& e : batch_) collect(e.v, j, e.birth);
      for (const auto& [p, q] : pairs_) process(p, q, j);
      batch_.clear();
    }
  }

  /// The Delaunay triangulation of all vertices, each triangle found from the local star of
  /// its (x, y)-smallest corner.
  std::vector<Triangle> triangles() {
    std::vector<Triangle> out;
    for (Vid v = 0; v < pts_.size(); ++v) {
      star_of(v, initial_radius(v), std::numeric_limits<double>::infinity());
      const std::size_t d = star_.size();
      const bool cycle = !on_boundary(v);
      for (std::size_t i = 0; i < d; ++i) {
        if (i + 1 == d && !cycle) break;
        const Vid a = star_[i], b = star_[(i + 1) % d];
        if (xy_less(pts_[v], pts_[a]) && xy_less(pts_[v], pts_[b]))
          out.push_back(canonical_triangle(pts_[v], pts_[a], pts_[b]));
      }
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  void check() const { tree_.check_invariants(pts_); }

 private:
  struct Entry {
    Vid v;
    bool birth;
  };

  Vid add(const Point<2>& p) {
    const auto v = static_cast<Vid>(pts_.size());
    pts_.push_back(p);
    tree_.insert(v, p, pts_);
    note_side(v);
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

  /// Sides: 0 bottom, 1 right, 2 top, 3 left; keyed by the coordinate along the side.
  void note_side(Vid v) {
    const Point<2>& p = pts_[v];
    if (p[1] == lo_[1]) sides_[0][p[0]] = v;
    if (p[0] == hi_[0]) sides_[1][p[1]] = v;
    if (p[1] == hi_[1]) sides_[2][p[0]] = v;
    if (p[0] == lo_[0]) sides_[3][p[1]] = v;
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
    tree_.visit(Point<2>{c[0] - r, c[1] - r}, Point<2>{c[0] + r, c[1] + r}, [&](Vid v) {
      if (empty && v != p && v != q && pencil(a, b, leaf_height_, pts_[v]) < 0) empty = false;
    });
    out_.questions.leaves_read += tree_.leaves_read() - before;
    return empty;
  }

  /// A radius that holds v's nearest neighbours: twice the distance to the nearest vertex
  /// found in v's own leaf neighbourhood, grown until one is found.
  double initial_radius(Vid v) const {
    double r = box_.side * 0x1p-20;
    for (;;) {
      double best = std::numeric_limits<double>::infinity();
      tree_.visit(Point<2>{pts_[v][0] - r, pts_[v][1] - r}, Point<2>{pts_[v][0] + r, pts_[v][1] + r}, [&](Vid w) {
        if (w != v) best = std::min(best, std::hypot(pts_[w][0] - pts_[v][0], pts_[w][1] - pts_[v][1]));
      });
      if (best <= r) return 2 * best;
      r *= 4;
    }
  }

  /// v's star (counter-clockwise, as Delaunay::star gives it) from the local triangulation of
  /// the vertices within r of v, r growing from `r0` until every star triangle is certain or
  /// r reaches `cap`. Returns whether the star is the true one (every triangle certain).
  bool star_of(Vid v, double r0, double cap) {
    ++out_.questions.stars;
    double r = std::min(r0, cap);
    for (;;) {
      local_.build(tree_, pts_, pts_[v], r, out_.questions);
      const Delaunay::Vid lv = local_.local(v);
      local_.dt().star(lv, lstar_);
      const std::size_t d = lstar_.size();
      const bool cycle = !on_boundary(v);
      bool sure = true;
      for (std::size_t i = 0; i < d && sure; ++i) {
        if (i + 1 == d && !cycle) break;
        sure = local_.certain(lv, lstar_[i], lstar_[(i + 1) % d]);
      }
      star_.clear();
      for (const Delaunay::Vid l : lstar_) star_.push_back(local_.global(l));
      if (sure || r >= cap) return sure;
      ++out_.questions.star_retries;
      r = std::min(2 * r, cap);
    }
  }

  /// The class of v's shortest true edge. Local edges can be false only where both their
  /// triangles are uncertain; the radius grows until the shortest candidates are certain.
  int first_class(Vid v) {
    ++out_.questions.stars;
    double r = initial_radius(v);
    for (;;) {
      local_.build(tree_, pts_, pts_[v], r, out_.questions);
      const Delaunay::Vid lv = local_.local(v);
      local_.dt().star(lv, lstar_);
      const std::size_t d = lstar_.size();
      const bool cycle = !on_boundary(v);
      const auto tri_certain = [&](std::size_t i) {  // the triangle (v, star[i], star[i + 1])
        if (i + 1 >= d && !cycle) return false;
        return local_.certain(lv, lstar_[i], lstar_[(i + 1) % d]);
      };
      int best = INT_MAX;
      bool sure = true;
      for (std::size_t i = 0; i < d; ++i) {
        const int c = edge_class(pts_[v], local_.dt().point(lstar_[i]));
        const bool edge_true = tri_certain(i) || tri_certain((i + d - 1) % d);
        if (c <= best && !edge_true) sure = false;
        best = std::min(best, c);
      }
      // An uncertain edge of class above the best cannot lower it; one at or below can be
      // false, and then a certain edge of lower class may be hiding: look wider.
      if (sure || r >= 4 * box_.side) return best;
      ++out_.questions.star_retries;
      r *= 2;
    }
  }

  /// Figure 5, line 7, for one vertex (the twin's collect): its loose pairs of class j (≤ j
  /// at its first entry), in (x, y) order, and its continuation into Q_{j+1}.
  void collect(Vid v, int j, bool birth) {
    ++out_.stats.entries;
    // The continuation rule looks at triangles of circumradius up to 2^(j+1): their discs
    // lie within 2^(j+2) of v. (The slack keeps a triangle at the rule's edge certain.)
    const double cap = std::ldexp(1.0 + 4 * kSlack, j + 2);
    const bool sure = star_of(v, std::min(initial_radius(v), cap), cap);
    const std::size_t d = star_.size();
    const bool cycle = !on_boundary(v);
    bool go_on = !sure;
    local_pairs_.clear();
    for (std::size_t i = 0; i < d; ++i) {
      const Vid q = star_[i];
      const int c = edge_class(pts_[v], pts_[q]);
      if (sure && (i + 1 < d || cycle)) go_on = go_on || circumradius_above(pts_[v], pts_[q], pts_[star_[(i + 1) % d]], j);
      if (c > j) go_on = true;
      if (birth ? c > j : c != j) continue;
      if (loose(v, q)) local_pairs_.push_back({v, q});
      if (loose(q, v)) local_pairs_.push_back({q, v});
    }
    std::sort(local_pairs_.begin(), local_pairs_.end(), [&](const auto& a, const auto& b) {
      if (pts_[a[0]] != pts_[b[0]]) return xy_less(pts_[a[0]], pts_[b[0]]);
      return xy_less(pts_[a[1]], pts_[b[1]]);
    });
    pairs_.insert(pairs_.end(), local_pairs_.begin(), local_pairs_.end());
    if (go_on) queues_[j + 1].push_back({v, false});
  }

  /// The Delaunay neighbour of p→q on its left when the circle through p, q and it is
  /// centred within `reach` of pq's midpoint; kNone when it is farther (or the box's outside).
  Vid left_neighbour(Vid p, Vid q, double reach) {
    ++out_.questions.neighbour_asks;
    const Point<2>&a = pts_[p], &b = pts_[q];
    const Point<2> m{0.5 * a[0] + 0.5 * b[0], 0.5 * a[1] + 0.5 * b[1]};
    const double half = 0.5 * std::hypot(b[0] - a[0], b[1] - a[1]);
    // Every circle through p and q centred within `reach` of m lies within reach + its
    // radius (≤ √(reach² + half²)) of m.
    const double r = (reach + std::hypot(reach, half)) * (1 + 4 * kSlack);
    local_.build(tree_, pts_, m, r, out_.questions);
    const auto e = local_.dt().left_of(local_.local(p), local_.local(q));
    if (!e) throw InvariantError("dynmesh: cell refiner: a loose pair that is not a local edge");
    const auto& T = local_.dt().tri(e->first);
    const Delaunay::Vid t = T.v[e->second];
    if (!local_.certain(local_.local(p), local_.local(q), t)) return kNone;
    return local_.global(t);
  }

  /// Figure 5, lines 10-14, for the ccw side of p→q (the twin's process).
  void process(Vid p, Vid q, int j) {
    for (;;) {
      if (!loose(p, q)) return;
      ++out_.stats.loose_pairs;
      const Point<2>&a = pts_[p], &b = pts_[q];
      const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
      const Vid t = left_neighbour(p, q, apex_height_ * len);
      // With no neighbour within the apex's reach the off-center is the apex; a far corner
      // stands in for t (the apex's bits do not depend on it: the frame's scaling is exact).
      const Point<2>& tp = t != kNone ? pts_[t] : far_corner(a, b);
      const auto [r, was_circumcentre] = off_center(a, b, tp, apex_height_);
      if (t == kNone && was_circumcentre)
        throw InvariantError("dynmesh: cell refiner: a circumcentre from beyond the apex");
      if (!std::isfinite(r[0]) || !std::isfinite(r[1])) throw InvariantError("dynmesh: a non-finite off-center");
      if (!(r[0] >= lo_[0] && r[0] <= hi_[0] && r[1] >= lo_[1] && r[1] <= hi_[1])) {
        split_crossed(a, b, r, j);
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
        for (const auto& s : encroached_) split_side(s[0], s[1], j);
        continue;
      }
      const Vid rv = add(r);
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
    const auto& line = sides_[s];
    auto it = line.upper_bound(r[along]);
    if (it == line.begin() || it == line.end()) return std::nullopt;
    const Vid hi_end = it->second, lo_end = std::prev(it)->second;
    if (!(pts_[lo_end][along] < r[along])) return std::nullopt;  // r projects onto a vertex
    if (!encroaches(pts_[lo_end], pts_[hi_end], r)) return std::nullopt;
    // The edge in counter-clockwise order along the boundary (the inside on its left).
    const bool forward = s == 0 || s == 1;
    const Vid ea = forward ? lo_end : hi_end, eb = forward ? hi_end : lo_end;
    // Its triangle: the edge's left neighbour; the circle through ea, eb and it holds r
    // unless it lies inside the diametral disc, so only that disc must be gathered.
    ++out_.questions.neighbour_asks;
    const Point<2>&a = pts_[ea], &b = pts_[eb];
    const Point<2> m{0.5 * a[0] + 0.5 * b[0], 0.5 * a[1] + 0.5 * b[1]};
    const double half = 0.5 * std::hypot(b[0] - a[0], b[1] - a[1]);
    local_.build(tree_, pts_, m, half * (1 + 4 * kSlack), out_.questions);
    const auto e = local_.dt().left_of(local_.local(ea), local_.local(eb));
    if (!e) throw InvariantError("dynmesh: cell refiner: a box edge that is not an edge");
    const auto& T = local_.dt().tri(e->first);
    const bool inside_disc = encroaches(a, b, local_.dt().point(T.v[e->second]));
    if (inside_disc && !local_.dt().in_conflict(e->first, r)) return std::nullopt;
    return std::array<Vid, 2>{ea, eb};
  }

  /// The twin's split_crossed: the box edge holding the first crossing of m→r with the box.
  void split_crossed(const Point<2>& p, const Point<2>& q, const Point<2>& r, int j) {
    const auto [side, x] = side_crossed(box_, p, q, r);
    const auto& line = sides_[side];
    auto it = line.upper_bound(x);
    if (it == line.end()) --it;
    if (it == line.begin()) ++it;
    split_side(std::prev(it)->second, it->second, j);
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
  Local local_;
  double lo_[2], hi_[2];
  double apex_height_ = 0, leaf_height_ = 0;
  std::size_t max_vertices_;
  CellRefinement& out_;
  bool check_tree_;
  std::vector<Point<2>> pts_;
  std::map<int, std::vector<Entry>> queues_;
  std::map<double, Vid> sides_[4];
  std::vector<Entry> batch_;
  std::vector<Vid> star_;
  std::vector<Delaunay::Vid> lstar_;
  std::vector<std::array<Vid, 2>> pairs_, local_pairs_, encroached_;
};

}  // namespace

CellRefinement cell_refine(const Box<2>& box, std::span<const Point<2>> points, double min_angle_deg,
                           bool check_tree) {
  validate_min_angle(min_angle_deg);
  const auto qs = locate_all(box, points);
  check_separated(qs);
  check_resolution(MeshGrid(box), points, qs);
  validate_mesh_box(box);
  const std::size_t max_vertices = 1000 * (points.size() + 4) + (std::size_t{1} << 20);
  CellRefinement out;
  CellRefiner refiner(box, min_angle_deg, max_vertices, out, check_tree);
  refiner.insert_inputs(points);
  refiner.refine();
  out.triangles = refiner.triangles();
  refiner.check();
  return out;
}

}  // namespace dynmesh::detail
