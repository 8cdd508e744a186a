// hpu_mesh.cpp — off-center refinement by size classes on the Delaunay triangulation (see
// hpu_mesh.hpp for the algorithm and its choices).
#include "dynmesh/hpu_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "delaunay.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/mesh_check.hpp"
#include "dynmesh/predicates.hpp"
#include "dynmesh/quadtree_mesh.hpp"
#include "locate_points.hpp"
#include "z_order.hpp"

namespace dynmesh {
namespace {

using detail::Delaunay;
using Tid = Delaunay::Tid;
using Vid = Delaunay::Vid;

constexpr int next(int i) noexcept { return i == 2 ? 0 : i + 1; }
constexpr int prev(int i) noexcept { return i == 0 ? 2 : i - 1; }

double squared_length(const Point<2>& a, const Point<2>& b) noexcept {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  return dx * dx + dy * dy;
}

/// (x, y) order of unordered vertex pairs: the tie rule of key edges and side splits.
bool pair_less(const Point<2>& a0, const Point<2>& a1, const Point<2>& b0, const Point<2>& b1) noexcept {
  const Point<2>& alo = xy_less(a1, a0) ? a1 : a0;
  const Point<2>& ahi = xy_less(a1, a0) ? a0 : a1;
  const Point<2>& blo = xy_less(b1, b0) ? b1 : b0;
  const Point<2>& bhi = xy_less(b1, b0) ? b0 : b1;
  if (alo != blo) return xy_less(alo, blo);
  return xy_less(ahi, bhi);
}

/// Z-order code of a grid position's top 32 bits per axis: the insertion order of the
/// points (any order gives the same triangulation; this one keeps the walks short).
std::uint64_t morton(const Position<2>& q) noexcept {
  return detail::z_order(static_cast<std::uint32_t>(q[0] >> 20), static_cast<std::uint32_t>(q[1] >> 20));
}

/// Of the leaf's apex height; Triangle uses 0.95 of the off-center distance too.
constexpr double kApexFactor = 0.95;

/// The midpoint of a box edge, from its (x, y)-smaller end: one formula whoever asks (the
/// precomputation below and a split during refinement), so the same edge always gives the
/// same bits. Throws InputError(Resolution) when double precision cannot split the edge.
Point<2> side_midpoint(const Point<2>& p, const Point<2>& q) {
  const Point<2>& a = xy_less(q, p) ? q : p;
  const Point<2>& b = xy_less(q, p) ? p : q;
  const Point<2> mid{a[0] + (b[0] - a[0]) * 0.5, a[1] + (b[1] - a[1]) * 0.5};
  if (mid == a || mid == b)
    throw InputError(InputError::Kind::Resolution,
                     "the mesh must split a box edge of length " + format_exact(std::sqrt(squared_length(a, b))) +
                         " that double precision cannot split: the spread is beyond the mesh's resolution");
  return mid;
}

/// Step 2 without a triangulation: the midpoints that splitting encroached box edges adds.
/// An edge's diametral disc holds its halves' discs, and a point strictly inside one projects
/// strictly inside the edge; midpoints and corners never encroach. So the edges split are
/// exactly those some input encroaches, and for each input they form one path down the
/// halving of the side edge its projection falls in. Inserting these before the inputs keeps
/// their cavities small (splitting after the inputs made every split's cavity the fan of a
/// line of points: quadratic on collinear input).
std::vector<Point<2>> side_midpoints(const Box<2>& box, std::span<const Point<2>> points) {
  const double lo[2] = {box.origin[0], box.origin[1]};
  const double hi[2] = {box.origin[0] + box.side, box.origin[1] + box.side};
  std::vector<Point<2>> out, side;
  for (unsigned u = 0; u < 2; ++u) {  // the axis along the side
    const unsigned w = 1 - u;         // the axis across it
    for (const double c : {lo[w], hi[w]}) {
      const auto at = [&](double t) {
        Point<2> p;
        p[u] = t;
        p[w] = c;
        return p;
      };
      side = {at(lo[u]), at(hi[u])};
      for (const Point<2>& p : points)
        if (p[w] == c) side.push_back(p);
      std::sort(side.begin(), side.end(), [&](const Point<2>& a, const Point<2>& b) { return a[u] < b[u]; });
      side.erase(std::unique(side.begin(), side.end()), side.end());
      for (const Point<2>& p : points) {
        if (p[w] == c) continue;
        const auto it = std::upper_bound(side.begin(), side.end(), p[u],
                                         [&](double t, const Point<2>& v) { return t < v[u]; });
        if (it == side.begin() || it == side.end() || !((it - 1)->at(u) < p[u])) continue;
        Point<2> a = *(it - 1), b = *it;
        while (encroaches(a, b, p)) {
          const Point<2> m = side_midpoint(a, b);
          out.push_back(m);
          if (p[u] < m[u]) b = m;
          else if (p[u] > m[u]) a = m;
          else break;
        }
      }
    }
  }
  std::sort(out.begin(), out.end(), xy_less);
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

class Refiner {
 public:
  Refiner(const Box<2>& box, double min_angle_deg, std::size_t max_vertices, HpuStats& stats)
      : dt_(box), theta_(min_angle_deg), max_vertices_(max_vertices), stats_(stats) {
    // The apex of the leaf sits at height ρ + k = 1 / (2 tan(θ/2)) above pq: the triangle
    // p q c' has the angle θ at c' exactly, which rounding would judge bad again and again
    // (at 30° the refinement then never ends). Like Triangle, place it a little lower
    // (kApexFactor), so that its triangle is strictly better than the bound.
    apex_height_ = kApexFactor * 0.5 / std::tan(min_angle_deg * (std::numbers::pi / 360.0));
    const double s = std::sin(min_angle_deg * (std::numbers::pi / 180.0));
    sin2_theta_ = s * s;
  }

  /// The side midpoints of step 2 (in (x, y) order), then the points in Morton order.
  void insert_inputs(const Box<2>& box, std::span<const Point<2>> points, std::span<const Position<2>> qs) {
    Tid hint = dt_.any_live();
    for (const Point<2>& m : side_midpoints(box, points)) {
      created_.clear();
      if (dt_.insert(m, hint, created_) && !created_.empty()) hint = created_.back();
      ++stats_.side_splits;
    }
    std::vector<std::pair<std::uint64_t, std::size_t>> order(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) order[i] = {morton(qs[i]), i};
    std::sort(order.begin(), order.end());
    for (const auto& [code, i] : order) {
      created_.clear();
      if (dt_.insert(points[i], hint, created_) && !created_.empty()) hint = created_.back();
    }
  }

  /// Step 2's invariant after insert_inputs(): no box edge is encroached. It holds by
  /// construction (side_midpoints); this pass would split any edge that is, and counts it.
  void split_encroached_sides() {
    std::vector<Tid> work;
    for (Tid t = 0; t < dt_.num_slots(); ++t)
      if (dt_.tri(t).alive) work.push_back(t);
    while (!work.empty()) {
      const Tid t = work.back();
      work.pop_back();
      const auto& T = dt_.tri(t);
      if (!T.alive) continue;
      for (int i = 0; i < 3; ++i) {
        if (T.n[i] != Delaunay::kNone) continue;
        const Vid a = T.v[next(i)], b = T.v[prev(i)];
        // No vertex encroaches ab unless the one opposite it does (the circumcircle of t is
        // empty and holds the half of ab's diametral disc inside the box when t's angle
        // there is not obtuse).
        if (!encroaches(dt_.point(a), dt_.point(b), dt_.point(T.v[i]))) continue;
        created_.clear();
        split_side(a, b, t);
        work.insert(work.end(), created_.begin(), created_.end());
        break;
      }
    }
  }

  void refine() {
    for (Tid t = 0; t < dt_.num_slots(); ++t)
      if (dt_.tri(t).alive) consider(t);
    struct Item {
      Triangle key;
      Tid t;
      std::uint32_t gen;
      bool operator<(const Item& o) const { return key < o.key; }
    };
    std::vector<Item> items;
    while (!buckets_.empty()) {
      std::vector<Entry> round = std::move(buckets_.begin()->second);
      buckets_.erase(buckets_.begin());
      items.clear();
      for (const Entry& e : round) {
        const auto& T = dt_.tri(e.t);
        if (T.alive && T.gen == e.gen)
          items.push_back({canonical_triangle(dt_.point(T.v[0]), dt_.point(T.v[1]), dt_.point(T.v[2])), e.t, e.gen});
      }
      if (items.empty()) continue;
      ++stats_.rounds;
      std::sort(items.begin(), items.end());
      items.erase(std::unique(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.key == b.key; }),
                  items.end());
      for (const Item& it : items) {
        const auto& T = dt_.tri(it.t);
        if (T.alive && T.gen == it.gen) split_triangle(it.t);
      }
    }
  }

  std::vector<Triangle> triangles() const { return dt_.triangles(); }
  const Delaunay& triangulation() const noexcept { return dt_; }

 private:
  struct Entry {
    Tid t;
    std::uint32_t gen;
  };
  struct KeyEdge {
    Vid p, q, t;  // the triangle p, q, t is counter-clockwise; pq is its shortest edge
  };

  /// corner_angle_deg, the checker's definition, decides; a filter on sin² of the smallest
  /// angle (opposite the shortest edge: sin = 2·area / (product of the two longer edges))
  /// settles all but the near-ties first, since three atan2 per new triangle cost more
  /// than the rest of its making.
  bool bad(Tid t) const noexcept {
    const auto& v = dt_.tri(t).v;
    const Point<2>&a = dt_.point(v[0]), &b = dt_.point(v[1]), &c = dt_.point(v[2]);
    const double ux = b[0] - a[0], uy = b[1] - a[1], wx = c[0] - a[0], wy = c[1] - a[1];
    const double m = std::max({std::abs(ux), std::abs(uy), std::abs(wx), std::abs(wy)});
    if (m > 0x1p-200 && m < 0x1p200) {  // no overflow or underflow in fourth powers
      const double cross = ux * wy - uy * wx;
      const double lab = ux * ux + uy * uy, lac = wx * wx + wy * wy;
      const double lbc = (wx - ux) * (wx - ux) + (wy - uy) * (wy - uy);
      const double lmin = std::min({lab, lac, lbc});
      const double longer = lab == lmin ? lac * lbc : lac == lmin ? lab * lbc : lab * lac;
      const double sin2 = cross * cross / longer;
      if (sin2 > sin2_theta_ * (1 + 1e-9)) return false;
      if (sin2 < sin2_theta_ * (1 - 1e-9)) return true;
    }
    return corner_angle_deg(a, b, c) < theta_ || corner_angle_deg(b, c, a) < theta_ ||
           corner_angle_deg(c, a, b) < theta_;
  }

  KeyEdge key_edge(Tid t) const noexcept {
    const auto& v = dt_.tri(t).v;
    int best = 0;
    double best_len = 0;
    for (int i = 0; i < 3; ++i) {
      const Point<2>&a = dt_.point(v[next(i)]), &b = dt_.point(v[prev(i)]);
      const double len = squared_length(a, b);
      if (i == 0 || len < best_len ||
          (len == best_len && pair_less(a, b, dt_.point(v[next(best)]), dt_.point(v[prev(best)])))) {
        best = i;
        best_len = len;
      }
    }
    return KeyEdge{v[next(best)], v[prev(best)], v[best]};
  }

  static int size_class(double squared) noexcept { return std::ilogb(squared) >> 1; }

  void consider(Tid t) {
    if (!bad(t)) return;
    const KeyEdge k = key_edge(t);
    buckets_[size_class(squared_length(dt_.point(k.p), dt_.point(k.q)))].push_back({t, dt_.tri(t).gen});
  }

  void consider_created() {
    for (Tid c : created_) consider(c);
  }

  /// The off-center of pq for the counter-clockwise triangle p, q, t, in one fixed sequence
  /// of double operations, in a frame scaled by a power of two (exact) so that the products
  /// neither overflow nor underflow in any accepted box.
  struct OffCenter {
    Point<2> at;
    bool circumcentre;  // the circumcentre rather than the leaf's apex
  };
  OffCenter off_center(const Point<2>& p, const Point<2>& q, const Point<2>& t) const noexcept {
    double bx = q[0] - p[0], by = q[1] - p[1], cx = t[0] - p[0], cy = t[1] - p[1];
    const int e = std::ilogb(std::max({std::abs(bx), std::abs(by), std::abs(cx), std::abs(cy)}));
    bx = std::ldexp(bx, -e), by = std::ldexp(by, -e), cx = std::ldexp(cx, -e), cy = std::ldexp(cy, -e);
    // The midpoint of pq and the apex c' = m + (ρ + k)·J(q − p), J(x, y) = (−y, x).
    const double mx = 0.5 * bx, my = 0.5 * by;
    const double ax = mx - apex_height_ * by, ay = my + apex_height_ * bx;
    // The circumcentre of p, q, t (relative to p).
    const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
    const double d = 2.0 * (bx * cy - by * cx);
    const double ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
    const double du = (ux - mx) * (ux - mx) + (uy - my) * (uy - my);
    const double da = apex_height_ * apex_height_ * b2;
    const bool circumcentre = du <= da;
    const double rx = circumcentre ? ux : ax, ry = circumcentre ? uy : ay;
    return OffCenter{Point<2>{p[0] + std::ldexp(rx, e), p[1] + std::ldexp(ry, e)}, circumcentre};
  }

  void check_size() const {
    if (dt_.num_vertices() > max_vertices_)
      throw InvariantError("dynmesh: hpu refinement did not terminate (over " + std::to_string(max_vertices_) +
                           " vertices)");
  }

  /// Splits the box edge ab (a, b adjacent on a side) at its midpoint; new triangles in created_.
  void split_side(Vid a, Vid b, Tid hint) {
    const Point<2> mid = side_midpoint(dt_.point(a), dt_.point(b));
    if (!dt_.insert(mid, hint, created_)) throw InvariantError("dynmesh: a box edge's midpoint is already a vertex");
    ++stats_.side_splits;
    check_size();
  }

  void requeue(Tid t) {
    if (dt_.tri(t).alive) consider(t);
  }

  void split_triangle(Tid t) {
    const KeyEdge k = key_edge(t);
    const auto [r, was_circumcentre] = off_center(dt_.point(k.p), dt_.point(k.q), dt_.point(k.t));
    if (!std::isfinite(r[0]) || !std::isfinite(r[1])) throw InvariantError("dynmesh: a non-finite off-center");
    const std::uint32_t gen = dt_.tri(t).gen;
    const auto still = [&] { return dt_.tri(t).alive && dt_.tri(t).gen == gen; };
    const Delaunay::Walk w = dt_.walk(t, r);
    if (w.exit_edge >= 0) {
      // Only rounding puts an off-center outside the box (no box edge is encroached, so
      // circumcentres lie inside it): split the side the walk left by.
      const auto& T = dt_.tri(w.t);
      created_.clear();
      split_side(T.v[next(w.exit_edge)], T.v[prev(w.exit_edge)], w.t);
      consider_created();
      if (still()) requeue(t);
      return;
    }
    if (dt_.vertex_at(w.t, r))
      throw InputError(InputError::Kind::Resolution,
                       "an off-center falls on the vertex " + format_exact(r[0]) + " " + format_exact(r[1]) +
                           ": the spread is beyond the mesh's resolution");
    dt_.cavity(w.t, r, cavity_);
    dt_.cavity_box_edges(cavity_, sides_);
    encroached_.clear();
    for (const auto& s : sides_)
      if (encroaches(dt_.point(s[0]), dt_.point(s[1]), r)) encroached_.push_back(s);
    if (!encroached_.empty()) {
      std::sort(encroached_.begin(), encroached_.end(), [&](const auto& x, const auto& y) {
        return pair_less(dt_.point(x[0]), dt_.point(x[1]), dt_.point(y[0]), dt_.point(y[1]));
      });
      Tid hint = w.t;
      for (const auto& s : encroached_) {
        created_.clear();
        split_side(s[0], s[1], dt_.tri(hint).alive ? hint : dt_.any_live());
        consider_created();
        if (!created_.empty()) hint = created_.front();
      }
      if (still()) requeue(t);
      return;
    }
    created_.clear();
    dt_.insert(r, cavity_, created_);
    ++stats_.off_centers;
    if (was_circumcentre) ++stats_.circumcentres;
    check_size();
    consider_created();
  }

  Delaunay dt_;
  double theta_;
  double apex_height_ = 0;
  double sin2_theta_ = 0;
  std::size_t max_vertices_;
  HpuStats& stats_;
  std::map<int, std::vector<Entry>> buckets_;
  std::vector<Tid> created_, cavity_;
  std::vector<std::array<Vid, 2>> sides_, encroached_;
};

void validate_min_angle(double deg) {
  if (!(deg >= kHpuMinAngleLow && deg <= kHpuMinAngleHigh))
    throw InputError(InputError::Kind::Malformed, "--min-angle for hpu must be between 1 and 30 degrees, got " +
                                                      format_exact(deg));
}

}  // namespace

HpuMesh::HpuMesh(const Box<2>& box, std::span<const Point<2>> points, double min_angle_deg)
    : box_(box), min_angle_(min_angle_deg), points_(points.begin(), points.end()) {
  validate_min_angle(min_angle_deg);
  const auto qs = detail::locate_all(box, points);
  detail::check_separated(qs);  // duplicates and the spread's resolution, as T* reports them
  // What double coordinates cannot refine around (the quadtree mesh's rule: near points and
  // points near a side have 4096 ulps of room at the finest level, L/2^R).
  detail::check_resolution(detail::MeshGrid(box), points, qs);
  validate_mesh_box(box);
  // A guard against a refinement that runs away, far above any size the tests have seen.
  const std::size_t max_vertices = 1000 * (points.size() + 4) + (std::size_t{1} << 20);
  Refiner refiner(box, min_angle_deg, max_vertices, stats_);
  refiner.insert_inputs(box, points, qs);
  refiner.split_encroached_sides();
  refiner.refine();
  triangles_ = refiner.triangles();
  stats_.triangles_made = refiner.triangulation().num_made();
  stats_.max_cavity = refiner.triangulation().max_cavity();
}

void HpuMesh::check_invariants() const {
  require_valid_mesh(mesh(), box_, points_, MeshCheckOptions{.min_angle_deg = min_angle_, .delaunay = true});
}

}  // namespace dynmesh
