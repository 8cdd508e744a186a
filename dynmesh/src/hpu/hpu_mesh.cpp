// hpu_mesh.cpp — off-center refinement by size classes on the Delaunay triangulation (see
// hpu_mesh.hpp for the algorithm and its choices).
//
// Purpose: HpuMesh, the static twin of the self-adjusting hpu mesh: rules 1-6 of
// hpu_mesh.hpp on a Delaunay triangulation, in the twin's order.
// Invariants: those of hpu_mesh.hpp (the output is the mesh those rules define).
// Complexity: O(n lg n + m) expected (hpu_mesh.hpp).
// Paper: Acar & Hudson, Figure 5 and Appendix A; Har-Peled & Üngör (2005); docs/DESIGN.md,
// "DynHPU".
#include "dynmesh/hpu_mesh.hpp"

#include <algorithm>
#include <climits>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "geometry/delaunay.hpp"
#include "hpu/hpu_geometry.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/mesh_check.hpp"
#include "dynmesh/predicates.hpp"
#include "dynmesh/quadtree_mesh.hpp"
#include "dynmesh/detail/quadtree_mesh_rules.hpp"
#include "io/locate_points.hpp"
#include "geometry/z_order.hpp"

namespace dynmesh {
namespace {

using detail::Delaunay;
using Tid = Delaunay::Tid;
using Vid = Delaunay::Vid;
using detail::pair_less;
using detail::side_midpoint;
using detail::side_midpoints;

/// DynHPU (the seed's Figure 5) on a Delaunay triangulation: see hpu_mesh.hpp.
class Refiner {
 public:
  Refiner(const Box<2>& box, double min_angle_deg, std::size_t max_vertices, HpuStats& stats)
      : box_(box), dt_(box), max_vertices_(max_vertices), stats_(stats), sides_(box) {
    apex_height_ = detail::apex_height(min_angle_deg);
    leaf_height_ = detail::leaf_height(min_angle_deg);
    lo_[0] = box.origin[0], lo_[1] = box.origin[1];
    hi_[0] = box.origin[0] + box.side, hi_[1] = box.origin[1] + box.side;
    for (Vid v = 0; v < 4; ++v) sides_.note(dt_.point(v), v);
  }

  void insert_inputs(std::span<const Point<2>> points) {
    Tid hint = dt_.any_live();
    for (const Point<2>& m : side_midpoints(box_, points)) {
      created_.clear();
      if (const auto v = dt_.insert(m, hint, created_)) {
        sides_.note(m, *v);
        hint = created_.empty() ? hint : created_.back();
      }
      ++stats_.side_splits;
    }
    // In BRIO order (insertion_less), not plain Morton order: the triangulation of a Morton
    // prefix of points along curves holds long triangles ahead of the frontier, which every
    // insertion there would re-make, with large cavities. Random rounds bound the expected
    // work whatever the input.
    std::vector<std::pair<detail::InsertionKey, std::size_t>> order(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) order[i] = {detail::insertion_key(box_, points[i]), i};
    std::sort(order.begin(), order.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [key, i] : order) {
      created_.clear();
      if (const auto v = dt_.insert(points[i], hint, created_)) {
        sides_.note(points[i], *v);
        hint = created_.empty() ? hint : created_.back();
      }
    }
  }

  void refine() {
    // The first entries: every vertex at the class of its shortest edge; the corners first
    // in (Morton, xy) order, then the rest in insertion_less order (hpu_geometry.hpp).
    std::vector<Point<2>> pts(dt_.num_vertices());
    for (Vid v = 0; v < pts.size(); ++v) pts[v] = dt_.point(v);
    // Each vertex's shortest edge class, from one pass over the triangles in slot order:
    // every edge once, from the triangle of lower slot (a star walk per vertex loaded the
    // same triangles in random order).
    std::vector<int> first(pts.size(), std::numeric_limits<int>::max());
    for (Tid t = 0; t < dt_.num_slots(); ++t) {
      const auto& T = dt_.tri(t);
      if (!T.alive) continue;
      for (int k = 0; k < 3; ++k) {
        if (T.n[k] != kNone && T.n[k] < t) continue;
        const Vid a = T.v[k == 2 ? 0 : k + 1], b = T.v[k == 0 ? 2 : k - 1];
        const int c = edge_class(a, b);
        first[a] = std::min(first[a], c), first[b] = std::min(first[b], c);
      }
    }
    for (const Vid v : detail::first_entry_order(box_, pts)) queues_[first[v]].push_back({v, true});
    detail::run_rounds(queues_, batch_, pairs_, stats_.rounds,
                       [&](const Entry& e, std::size_t at, int j) { collect(e, at, j); },
                       [&](Vid p, Vid q, int j) { process(p, q, j); });
  }

  std::vector<Triangle> triangles() const { return dt_.triangles(); }
  const Delaunay& triangulation() const noexcept { return dt_; }

 private:
  static constexpr Vid kNone = Delaunay::kNone;

  int edge_class(Vid a, Vid b) const noexcept { return detail::edge_class(dt_.point(a), dt_.point(b)); }

  bool on_boundary(Vid v) const noexcept {
    const Point<2>& p = dt_.point(v);
    return p[0] == lo_[0] || p[0] == hi_[0] || p[1] == lo_[1] || p[1] == hi_[1];
  }


  /// A queue entry: a vertex, and whether this is its first (it then collects its shorter
  /// pairs too: a side's midpoint can have edges of classes already done).
  struct Entry {
    Vid v;
    bool birth;
  };

  bool circumradius_above(Vid a, Vid b, Vid c, int j) const noexcept {
    return detail::circumradius_above(dt_.point(a), dt_.point(b), dt_.point(c), j);
  }

  /// p→q is ccw-loose: its ccw-leaf holds no vertex. t is the third corner of the triangle on
  /// its left (kNone: the outside of the box), u the one on its right. When pq is a Delaunay
  /// edge, t and u are the vertices nearest the leaf on either side, so they decide.
  bool loose(Vid p, Vid q, Vid t, Vid u) const noexcept {
    return detail::loose(dt_.point(p), dt_.point(q), leaf_height_, t == kNone ? nullptr : &dt_.point(t),
                         u == kNone ? nullptr : &dt_.point(u));
  }

  /// Figure 5, line 7, for one vertex: its loose pairs of class j (≤ j at its first entry),
  /// in (x, y) order of their ends. v enters Q_{j+1} unless it has no loose edge of a class
  /// above j and no triangle whose circumradius exceeds 2^{j+1+kGoOnReach}: a rule that
  /// reads only the vertices near v (without the large triangle, the longer edges'
  /// neighbours are in the star), so that the self-adjusting version decides it from nearby
  /// cells.
  void collect(const Entry& e, std::size_t at, int j) {
    const Vid v = e.v;
    const bool birth = e.birth;
    ++stats_.entries;
    // The first collect of a round (e is batch_[at]; run_rounds has just cleared the pairs)
    // starts the round's hints.
    if (at == 0) {
      hints_.clear();
      hint_at_ = 0;
    }
    // A round's collects only read the triangulation (its pairs are processed after them),
    // so the stars of the next kStarsAtOnce entries are walked together, their cache misses
    // overlapping, when the round reaches the first of them.
    if (at % kGroup == 0) {
      group_.clear();
      for (std::size_t i = at; i < std::min(at + kGroup, batch_.size()); ++i) group_.push_back(batch_[i].v);
      dt_.stars(group_, stars_, lefts_);
      // The neighbours' coordinates are the collects' next misses: ask for them all at once.
      for (std::size_t k = 0; k < group_.size(); ++k) {
        __builtin_prefetch(&dt_.point(group_[k]));
        for (const Vid q : stars_[k]) __builtin_prefetch(&dt_.point(q));
      }
    }
    const std::vector<Vid>& star = stars_[at % kGroup];
    const std::vector<Tid>& star_left = lefts_[at % kGroup];
    const bool cycle = !on_boundary(v);
    const std::size_t d = star.size();
    bool go_on = false;
    local_.clear();
    for (std::size_t i = 0; i < d; ++i) {
      const Vid q = star[i];
      const int c = edge_class(v, q);
      if (i + 1 < d || cycle) go_on = go_on || circumradius_above(v, q, star[i + 1 < d ? i + 1 : 0], j + detail::kGoOnReach);
      const Vid left = i + 1 < d ? star[i + 1] : cycle ? star[0] : kNone;
      const Vid right = i > 0 ? star[i - 1] : cycle ? star[d - 1] : kNone;
      // A longer edge matters only while loose: looseness never returns, and a later edge
      // of v has a newer end whose own entries collect it.
      if (c > j && !go_on) go_on = loose(v, q, left, right) || loose(q, v, right, left);
      if (birth ? c > j : c != j) continue;
      // With each pair, the triangle on its left as the walk saw it: process() tries it
      // before walking around p (left_of's hint, checked there).
      if (loose(v, q, left, right)) local_.push_back({{v, q}, star_left[i]});
      if (loose(q, v, right, left)) local_.push_back({{q, v}, i > 0 ? star_left[i - 1] : cycle ? star_left[d - 1] : kNone});
    }
    std::sort(local_.begin(), local_.end(), [&](const LocalPair& x, const LocalPair& y) {
      const auto &a = x.pq, &b = y.pq;
      if (dt_.point(a[0]) != dt_.point(b[0])) return xy_less(dt_.point(a[0]), dt_.point(b[0]));
      return xy_less(dt_.point(a[1]), dt_.point(b[1]));
    });
    // A pair collected twice (from both ends) is processed twice; the second time it is no
    // longer loose, since looseness and edges, once lost, never come back as vertices are
    // added. So no de-duplication is needed, and the result is that of the first.
    for (const LocalPair& l : local_) {
      pairs_.push_back(l.pq);
      hints_.push_back(l.left);
    }
    if (go_on) queues_[j + 1].push_back({v, false});
  }

  /// Figure 5, lines 10-14, for the ccw side of p→q.
  void process(Vid p, Vid q, int j) {
    // The pairs are processed in the order collected, so this one's hint is the next.
    Tid hint = kNone;
    if (hint_at_ < hints_.size() && pairs_[hint_at_] == std::array<Vid, 2>{p, q}) hint = hints_[hint_at_];
    ++hint_at_;
    for (;;) {
      const auto e = dt_.left_of(p, q, hint);
      hint = kNone;  // after a split, the triangles have changed
      if (!e) return;
      const auto [t, k] = *e;
      const auto& T = dt_.tri(t);
      const Vid tv = T.v[k];
      Vid uv = kNone;
      if (const Tid o = T.n[k]; o != kNone)
        for (const Vid w : dt_.tri(o).v)
          if (w != p && w != q) uv = w;
      if (!loose(p, q, tv, uv)) return;
      ++stats_.loose_pairs;
      const auto [r, was_circumcentre] = detail::off_center(dt_.point(p), dt_.point(q), dt_.point(tv), apex_height_);
      if (!std::isfinite(r[0]) || !std::isfinite(r[1])) throw InvariantError("dynmesh: a non-finite off-center");
      if (!(r[0] >= lo_[0] && r[0] <= hi_[0] && r[1] >= lo_[1] && r[1] <= hi_[1])) {
        split_crossed(dt_.point(p), dt_.point(q), r, j);
        continue;
      }
      const Delaunay::Walk w = dt_.walk(t, r);
      if (w.exit_edge >= 0) throw InvariantError("dynmesh: an off-center in the box walked out of it");
      if (dt_.vertex_at(w.t, r))
        throw InputError(InputError::Kind::Resolution,
                         "an off-center falls on the vertex " + format_exact(r[0]) + " " + format_exact(r[1]) +
                             ": the spread is beyond the mesh's resolution");
      dt_.cavity(w.t, r, cavity_);
      dt_.cavity_box_edges(cavity_, sides_found_);
      encroached_.clear();
      for (const auto& s : sides_found_)
        if (encroaches(dt_.point(s[0]), dt_.point(s[1]), r)) encroached_.push_back(s);
      if (!encroached_.empty()) {
        std::sort(encroached_.begin(), encroached_.end(), [&](const auto& x, const auto& y) {
          return pair_less(dt_.point(x[0]), dt_.point(x[1]), dt_.point(y[0]), dt_.point(y[1]));
        });
        for (const auto& s : encroached_) split_side(s[0], s[1], j);
        continue;
      }
      created_.clear();
      const Vid rv = dt_.insert(r, cavity_, created_);
      ++stats_.off_centers;
      if (was_circumcentre) ++stats_.circumcentres;
      check_size();
      queues_[j].push_back({rv, true});
      return;
    }
  }

  /// The off-center r of a loose pair lies outside the box: split the box edge that the
  /// segment from pq's midpoint to r crosses first (both ends lie in the leaf, so the
  /// crossing does too, and halving the edges around it puts a vertex into the leaf).
  void split_crossed(const Point<2>& p, const Point<2>& q, const Point<2>& r, int j) {
    const auto [side, x] = detail::side_crossed(box_, p, q, r);
    const auto e = sides_.edge_around(side, x);
    split_side(e[0], e[1], j);
  }

  void split_side(Vid a, Vid b, int j) {
    const Point<2> mid = side_midpoint(dt_.point(a), dt_.point(b));
    created_.clear();
    const auto v = dt_.insert(mid, dt_.incident(a), created_);
    if (!v) throw InvariantError("dynmesh: a box edge's midpoint is already a vertex");
    sides_.note(mid, *v);
    ++stats_.side_splits;
    check_size();
    queues_[j].push_back({*v, true});
  }

  void check_size() const {
    if (dt_.num_vertices() > max_vertices_)
      throw InvariantError("dynmesh: hpu refinement did not terminate (over " + std::to_string(max_vertices_) +
                           " vertices)");
  }

  Box<2> box_;
  Delaunay dt_;
  double lo_[2], hi_[2];
  double apex_height_ = 0, leaf_height_ = 0;
  std::size_t max_vertices_;
  HpuStats& stats_;
  std::map<int, std::vector<Entry>> queues_;
  detail::BoxSides<Vid> sides_;
  std::vector<Entry> batch_;
  // The stars of a group of a round's entries (collect()): stars_[k] of group_[k], and
  // lefts_[k][i] the triangle on the left of group_[k]→stars_[k][i].
  static constexpr std::size_t kGroup = Delaunay::kStarsAtOnce;
  std::vector<Vid> group_;
  std::array<std::vector<Vid>, kGroup> stars_;
  std::array<std::vector<Tid>, kGroup> lefts_;
  struct LocalPair {
    std::array<Vid, 2> pq;
    Tid left;  // the triangle on the left of p→q when collected (a hint)
  };
  std::vector<LocalPair> local_;
  std::vector<std::array<Vid, 2>> pairs_;
  std::vector<Tid> hints_;   // hints_[i]: pairs_[i]'s LocalPair::left
  std::size_t hint_at_ = 0;  // the next pair process() sees
  std::vector<Tid> created_, cavity_;
  std::vector<std::array<Vid, 2>> sides_found_, encroached_;
};

}  // namespace

HpuMesh::HpuMesh(const Box<2>& box, std::span<const Point<2>> points, double min_angle_deg)
    : box_(box), min_angle_(min_angle_deg), points_(points.begin(), points.end()) {
  detail::validate_min_angle(min_angle_deg);
  const auto qs = detail::locate_all(box, points);
  detail::check_separated(qs);  // duplicates and the spread's resolution, as T* reports them
  // What double coordinates cannot refine around (the quadtree mesh's rule: near points and
  // points near a side have 4096 ulps of room at the finest level, L/2^R).
  detail::check_resolution(detail::MeshGrid(box), points, qs);
  validate_mesh_box(box);
  // A guard against a refinement that runs away, far above any size the tests have seen.
  const std::size_t max_vertices = 1000 * (points.size() + 4) + (std::size_t{1} << 20);
  Refiner refiner(box, min_angle_deg, max_vertices, stats_);
  refiner.insert_inputs(points);
  refiner.refine();
  triangles_ = refiner.triangles();
  stats_.triangles_made = refiner.triangulation().num_made();
  stats_.max_cavity = refiner.triangulation().max_cavity();
}

void HpuMesh::check_invariants() const {
  require_valid_mesh(mesh(), box_, points_, MeshCheckOptions{.min_angle_deg = min_angle_, .delaunay = true});
}

}  // namespace dynmesh
