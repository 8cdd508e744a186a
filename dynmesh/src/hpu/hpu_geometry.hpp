// hpu_geometry.hpp (private) — the pure geometry of the hpu mesh, shared by its static twin
// (hpu_mesh.cpp, class Refiner) and its self-adjusting version (hpu_cells_program.hpp).
//
// Purpose: every mesher of the hpu rules (the twin, hpu_mesh.cpp; the cell refiner,
// cell_refiner.cpp; the self-adjusting program) must take the same decisions on the same
// bits, so every formula
// that produces a coordinate or a class (side midpoints, off-centers, circumradii, size
// classes, Morton codes, the leaf and apex heights) and the loose test live here once, as
// functions of points only (no triangulation, no vertex ids).
// Invariants: each function is one fixed sequence of double operations on its arguments;
// where the result must not depend on the argument order (side_midpoint, circumradius_above) it
// first puts the arguments in (x, y) order.
// Complexity: O(1) each; side_midpoints O(n log n + n·halvings).
// Paper: Üngör, "Off-centers" (2004); Acar & Hudson, Figure 5 (DynHPU); Ruppert (1995) and
// Shewchuk's Triangle for encroached subsegments.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <sac/splitmix64.hpp>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/predicates.hpp"
#include "geometry/powers_of_two.hpp"
#include "geometry/z_order.hpp"

namespace dynmesh::detail {

/// The hpu mesh's angle bound must be in [1, 30] degrees (hpu_mesh.hpp).
inline void validate_min_angle(double deg) {
  if (!(deg >= 1.0 && deg <= 30.0))
    throw InputError(InputError::Kind::Malformed, "--min-angle for hpu must be between 1 and 30 degrees, got " +
                                                      format_exact(deg));
}

inline double squared_length(const Point<2>& a, const Point<2>& b) noexcept {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  return dx * dx + dy * dy;
}

/// (x, y) order of unordered point pairs: the tie rule of key edges and side splits.
inline bool pair_less(const Point<2>& a0, const Point<2>& a1, const Point<2>& b0, const Point<2>& b1) noexcept {
  const Point<2>& alo = xy_less(a1, a0) ? a1 : a0;
  const Point<2>& ahi = xy_less(a1, a0) ? a0 : a1;
  const Point<2>& blo = xy_less(b1, b0) ? b1 : b0;
  const Point<2>& bhi = xy_less(b1, b0) ? b0 : b1;
  if (alo != blo) return xy_less(alo, blo);
  return xy_less(ahi, bhi);
}

/// Of the leaf's apex height; Triangle uses 0.95 of the off-center distance too.
inline constexpr double kApexFactor = 0.95;
/// k is taken this much lower (hpu_mesh.hpp, rule 2).
inline constexpr double kLeafMargin = 1.0 - 0x1p-30;

/// The apex height h = 0.95·(ρ + k) relative to |pq|, for the angle bound in degrees.
inline double apex_height(double min_angle_deg) noexcept {
  return kApexFactor * 0.5 / std::tan(min_angle_deg * (std::numbers::pi / 360.0));
}

/// The leaf height k = 1 / (2 tan θ), a little lower (kLeafMargin): a leaf that is slightly
/// too small only ever calls more pairs loose, so every angle of the result clears θ by more
/// than the checker's rounding.
inline double leaf_height(double min_angle_deg) noexcept {
  return kLeafMargin * 0.5 / std::tan(min_angle_deg * (std::numbers::pi / 180.0));
}

/// The size class of an edge of squared length `squared`: ⌊log2 |pq|⌋.
inline int size_class(double squared) noexcept { return exponent_of(squared) >> 1; }
/// ⌊log2 |ab|⌋ as size_class(|ab|²) gives it, computed in a frame scaled by a power of two
/// (exact), so that |ab|² neither overflows in a huge box nor underflows to 0 in a tiny one
/// (fuzz_hpu_mesh found the int overflow that followed). a ≠ b.
inline int edge_class(const Point<2>& a, const Point<2>& b) noexcept {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const int e = exponent_of(std::max(std::abs(dx), std::abs(dy)));
  const double sx = scale_down_by(dx, e), sy = scale_down_by(dy, e);
  return e + (exponent_of(sx * sx + sy * sy) >> 1);
}

/// The Morton code of p on the box's 2^32 grid (clamped): the initial queue order.
inline std::uint64_t morton_of(const Box<2>& box, const Point<2>& p) noexcept {
  const auto axis = [&](unsigned a) {
    const double u = (p[a] - box.origin[a]) / box.side * 0x1p32;
    return static_cast<std::uint32_t>(std::clamp(u, 0.0, 0x1p32 - 1));
  };
  return z_order(axis(0), axis(1));
}

/// (Morton, (x, y)) order of points in the box.
inline bool morton_less(const Box<2>& box, const Point<2>& a, const Point<2>& b) noexcept {
  const std::uint64_t ca = morton_of(box, a), cb = morton_of(box, b);
  if (ca != cb) return ca < cb;
  return xy_less(a, b);
}

/// A point's round in the biased randomized insertion order (BRIO, Amenta, Choi & Rote
/// 2003): the trailing zero bits of a hash of its coordinates (capped at 24), so about half
/// the points are at level 0, a quarter at 1, and so on; a function of the point alone.
inline int brio_level(const Point<2>& p) noexcept {
  std::uint64_t h = std::bit_cast<std::uint64_t>(p[0] + 0.0) * sac::kGoldenGamma;
  h ^= std::bit_cast<std::uint64_t>(p[1] + 0.0) + 0x632be59bd9b4e019ULL + (h << 6) + (h >> 2);
  return std::min(std::countr_zero(sac::mix64(h)), 24);
}

/// The order in which the hpu mesh takes its non-corner vertices (the input list, and the
/// first queue entries): BRIO level descending, then (Morton, xy) within a level. Why not
/// plain Morton order: each insertion re-makes the big triangles just ahead of it, so in
/// Morton order a change at one point would re-run every later insertion along that
/// frontier, and off-centers along the data's hull would re-make the long triangles out to
/// the box one after another. Coarse random rounds first cut those chains to O(1) expected
/// length, as in randomized incremental construction.
inline bool insertion_less(const Box<2>& box, const Point<2>& a, const Point<2>& b) noexcept {
  const int la = brio_level(a), lb = brio_level(b);
  if (la != lb) return la > lb;
  return morton_less(box, a, b);
}

/// A point with insertion_less's BRIO level and Morton code computed once, for an order
/// that compares each point many times (the input list's map, the first entries' sort):
/// keys compare as insertion_less compares their points. insertion_less stays the
/// definition, which HpuInputs::check_invariants() sorts by.
struct InsertionKey {
  int level;
  std::uint64_t code;
  Point<2> p;
  friend bool operator<(const InsertionKey& a, const InsertionKey& b) noexcept {
    if (a.level != b.level) return a.level > b.level;
    if (a.code != b.code) return a.code < b.code;
    return xy_less(a.p, b.p);
  }
};
inline InsertionKey insertion_key(const Box<2>& box, const Point<2>& p) noexcept {
  return {brio_level(p), morton_of(box, p), p};
}

/// The midpoint of a box edge, from its (x, y)-smaller end: one formula whoever asks (the
/// precomputation and a split during refinement), so the same edge always gives the same
/// bits. Throws InputError(Resolution) when double precision cannot split the edge.
inline Point<2> side_midpoint(const Point<2>& p, const Point<2>& q) {
  const Point<2>& a = xy_less(q, p) ? q : p;
  const Point<2>& b = xy_less(q, p) ? p : q;
  const Point<2> mid{a[0] + (b[0] - a[0]) * 0.5, a[1] + (b[1] - a[1]) * 0.5};
  if (mid == a || mid == b)
    throw InputError(InputError::Kind::Resolution,
                     "the mesh must split a box edge of length " + format_exact(std::sqrt(squared_length(a, b))) +
                         " that double precision cannot split: the spread is beyond the mesh's resolution");
  return mid;
}

/// The midpoints of p's path down the halvings of the box edge a-b (a[u] < p[u] < b[u],
/// u the axis along the side): while p encroaches the edge, its midpoint, then the half
/// p projects into. Appended to out, longest edge first.
inline void halving_path(Point<2> a, Point<2> b, const Point<2>& p, unsigned u, std::vector<Point<2>>& out) {
  while (encroaches(a, b, p)) {
    const Point<2> m = side_midpoint(a, b);
    out.push_back(m);
    if (p[u] < m[u]) b = m;
    else if (p[u] > m[u]) a = m;
    else break;
  }
}

/// The midpoints that splitting encroached box edges adds, computed from the points alone,
/// (x, y)-sorted. An edge's diametral disc holds its halves' discs, and a point strictly
/// inside one projects strictly inside the edge; midpoints and corners never encroach. So
/// the edges split are exactly those some input encroaches, and for each input they form
/// one path down the halving of the side edge its projection falls in. Inserting these
/// before the inputs keeps their cavities small (splitting after the inputs made every
/// split's cavity the fan of a line of points: quadratic on collinear input).
inline std::vector<Point<2>> side_midpoints(const Box<2>& box, std::span<const Point<2>> points) {
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
        halving_path(*(it - 1), *it, p, u, out);
      }
    }
  }
  std::sort(out.begin(), out.end(), xy_less);
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// How far the continuation rule of class j looks (hpu_mesh.hpp, rule 3): a vertex goes on
/// while its star has a triangle of circumradius above 2^(j+1+kGoOnReach), or a loose edge
/// of a class above j, which the star's walked triangles decide. A reach of 1 rather than 0
/// lets fewer collects run (a vertex whose star has only slightly larger triangles stops
/// sooner); a larger reach saves no more.
inline constexpr int kGoOnReach = 1;

/// Is the circumradius of a, b, c above 2^(j+1) (the continuation rule, kGoOnReach)? In one
/// fixed sequence of double operations from the corner that is smallest in (x, y) order, so
/// that any reader of the same triangle gets the same answer, and in a frame scaled by a
/// power of two (exact) so that the squares neither overflow in a huge box nor underflow in
/// a tiny one: the same decisions as the unscaled formula wherever that one is finite. A
/// degenerate (flat) triangle counts as above.
inline bool circumradius_above(const Point<2>& a, const Point<2>& b, const Point<2>& c, int j) noexcept {
  const Point<2>*P = &a, *Q = &b, *R = &c;
  if (xy_less(*Q, *P) && xy_less(*Q, *R)) std::tie(P, Q, R) = std::tuple{Q, R, P};
  else if (xy_less(*R, *P) && xy_less(*R, *Q)) std::tie(P, Q, R) = std::tuple{R, P, Q};
  double bx = (*Q)[0] - (*P)[0], by = (*Q)[1] - (*P)[1], cx = (*R)[0] - (*P)[0], cy = (*R)[1] - (*P)[1];
  const double m = std::max({std::abs(bx), std::abs(by), std::abs(cx), std::abs(cy)});
  if (!(m > 0)) return true;
  const int e = exponent_of(m);
  bx = scale_down_by(bx, e), by = scale_down_by(by, e), cx = scale_down_by(cx, e), cy = scale_down_by(cy, e);
  const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  const double d = 2.0 * (bx * cy - by * cx);
  const double ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
  // R² > 4^(j+1)  ⇔  (R·2^-e)² > 2^(2(j+1) − 2e); the exponent is clamped (pow2 saturates).
  const long k = std::clamp(2L * (static_cast<long>(j) + 1 - e), -4000L, 4000L);
  return ux * ux + uy * uy > pow2(static_cast<int>(k));
}

/// p→q is ccw-loose: its ccw-leaf (height `leaf`) holds no vertex. t is the third corner of
/// the triangle on its left (null: the outside of the box), u the one on its right (null:
/// a box side). When pq is a Delaunay edge, t and u are the vertices nearest the leaf on
/// either side, so they decide.
inline bool loose(const Point<2>& p, const Point<2>& q, double leaf, const Point<2>* t, const Point<2>* u) noexcept {
  if (!t) return false;
  if (pencil(p, q, leaf, *t) < 0) return false;
  return !u || pencil(p, q, leaf, *u) >= 0;
}

struct OffCenter {
  Point<2> at;
  bool circumcentre;
};

/// The off-center of pq for the counter-clockwise triangle p, q, t, t being pq's Delaunay
/// neighbour on the left: the apex of the leaf (height `apex`), or the circumcentre of p,
/// q, t when that is no farther from pq's midpoint (the crescent holds t). One fixed
/// sequence of double operations, in a frame scaled by a power of two (exact) so that the
/// products neither overflow nor underflow in any accepted box.
inline OffCenter off_center(const Point<2>& p, const Point<2>& q, const Point<2>& t, double apex) noexcept {
  double bx = q[0] - p[0], by = q[1] - p[1], cx = t[0] - p[0], cy = t[1] - p[1];
  const int e = exponent_of(std::max({std::abs(bx), std::abs(by), std::abs(cx), std::abs(cy)}));
  bx = scale_down_by(bx, e), by = scale_down_by(by, e), cx = scale_down_by(cx, e), cy = scale_down_by(cy, e);
  const double mx = 0.5 * bx, my = 0.5 * by;
  const double ax = mx - apex * by, ay = my + apex * bx;
  const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  const double d = 2.0 * (bx * cy - by * cx);
  const double ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
  const double du = (ux - mx) * (ux - mx) + (uy - my) * (uy - my);
  const double da = apex * apex * b2;
  const bool circumcentre = du <= da;
  const double rx = circumcentre ? ux : ax, ry = circumcentre ? uy : ay;
  // rx · 2^e: one multiply by an exact power of two (e ≥ -1074), rounded once as ldexp is.
  return OffCenter{Point<2>{p[0] + rx * pow2(e), p[1] + ry * pow2(e)}, circumcentre};
}

/// The box side the segment from pq's midpoint m to r (outside the box) crosses first
/// (0 bottom, 1 right, 2 top, 3 left) and the crossing's coordinate along that side,
/// clamped to the box.
struct SideCrossing {
  int side;
  double along;
};
inline SideCrossing side_crossed(const Box<2>& box, const Point<2>& p, const Point<2>& q, const Point<2>& r) noexcept {
  const double lo[2] = {box.origin[0], box.origin[1]};
  const double hi[2] = {box.origin[0] + box.side, box.origin[1] + box.side};
  const double m[2] = {0.5 * p[0] + 0.5 * q[0], 0.5 * p[1] + 0.5 * q[1]};
  int side = -1;
  double best = 2;
  const auto consider = [&](int s, unsigned axis, double bound) {
    const double f = (bound - m[axis]) / (r[axis] - m[axis]);
    if (f < best) best = f, side = s;
  };
  if (r[1] < lo[1]) consider(0, 1, lo[1]);
  if (r[0] > hi[0]) consider(1, 0, hi[0]);
  if (r[1] > hi[1]) consider(2, 1, hi[1]);
  if (r[0] < lo[0]) consider(3, 0, lo[0]);
  const unsigned along = side % 2 == 0 ? 0 : 1;
  return SideCrossing{side, std::clamp(m[along] + best * (r[along] - m[along]), lo[along], hi[along])};
}

/// The vertices on the box's sides, by side (0 bottom, 1 right, 2 top, 3 left) and keyed by
/// the coordinate along it: the box edges are consecutive entries. Shared by both refiners,
/// so that a split picks the same edge in each.
template <class Vid>
class BoxSides {
 public:
  explicit BoxSides(const Box<2>& box)
      : lo_{box.origin[0], box.origin[1]}, hi_{box.origin[0] + box.side, box.origin[1] + box.side} {}

  /// Records v at p if p lies on a side (a corner on two).
  void note(const Point<2>& p, Vid v) {
    if (p[1] == lo_[1]) line_[0][p[0]] = v;
    if (p[0] == hi_[0]) line_[1][p[1]] = v;
    if (p[1] == hi_[1]) line_[2][p[0]] = v;
    if (p[0] == lo_[0]) line_[3][p[1]] = v;
  }

  /// The edge of side s around the coordinate x: the one holding x in [a, b), clamped to the
  /// side's first and last edges (the refiners' rule for an off-center beyond the box).
  std::array<Vid, 2> edge_around(int s, double x) const {
    const auto& line = line_[s];
    auto it = line.upper_bound(x);
    if (it == line.end()) --it;
    if (it == line.begin()) ++it;
    return {std::prev(it)->second, it->second};
  }

  /// The edge of side s whose open interval holds x, as (lower, upper) along the side; none
  /// when x is a vertex's coordinate or beyond the side.
  std::optional<std::array<Vid, 2>> edge_holding(int s, double x) const {
    const auto& line = line_[s];
    const auto it = line.upper_bound(x);
    if (it == line.begin() || it == line.end() || !(std::prev(it)->first < x)) return std::nullopt;
    return std::array<Vid, 2>{std::prev(it)->second, it->second};
  }

 private:
  double lo_[2], hi_[2];
  std::map<double, Vid> line_[4];
};

/// Figure 5's loop, one for every refiner: while a queue is left, a round takes the whole
/// queue of the smallest class, collects every entry's loose pairs (collect(entry, i, j),
/// i its index in `batch`, appends to `pairs`), then processes the pairs in that order
/// (process(p, q, j)); entries made meanwhile wait in their queues for later rounds.
template <class Entry, class Vid, class Collect, class Process>
void run_rounds(std::map<int, std::vector<Entry>>& queues, std::vector<Entry>& batch,
                std::vector<std::array<Vid, 2>>& pairs, std::size_t& rounds, Collect&& collect, Process&& process) {
  while (!queues.empty()) {
    const auto it = queues.begin();
    const int j = it->first;
    batch.swap(it->second);
    queues.erase(it);
    ++rounds;
    pairs.clear();
    for (std::size_t i = 0; i < batch.size(); ++i) collect(batch[i], i, j);
    for (const auto& [p, q] : pairs) process(p, q, j);
    batch.clear();
  }
}

/// The order of the first queue entries: the four box corners (vertices 0-3) first in
/// (Morton, x, y) order, then the other vertices in insertion_less order. Returns indices.
inline std::vector<std::uint32_t> first_entry_order(const Box<2>& box, std::span<const Point<2>> pts) {
  std::vector<std::pair<InsertionKey, std::uint32_t>> keys(pts.size());
  for (std::uint32_t v = 0; v < keys.size(); ++v) {
    keys[v] = {insertion_key(box, pts[v]), v};
    if (v < 4) keys[v].first.level = INT_MAX;  // the corners first
  }
  std::sort(keys.begin(), keys.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::uint32_t> out(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) out[i] = keys[i].second;
  return out;
}

}  // namespace dynmesh::detail
