// octree_mesh_bound_test.cpp — the proof that every dihedral angle of the octree's tetrahedral
// mesh lies in [kOctreeMinDihedral, kOctreeMaxDihedral] (octree_mesh.hpp): exhaustive
// enumeration of the templates, outward-rounded interval and affine arithmetic over the
// point region.
//
// Purpose: the machine part of docs/OCTREE_MESH.md, "The dihedral bound, proved".
//   * Enumeration. Every tetrahedron of the mesh is one of Kuhn's six, or (apex, triangle)
//     with the triangle on one face of a leaf and the apex the leaf's centre or a block's
//     point. The rule that triangulates a face reads the split state of nine cells; all 2^9
//     assignments, for the 6 faces of a leaf and the 24 outer faces of a block, go through the
//     real cone_face: a superset of every legal neighbourhood. The cross-checks show that
//     tetrahedralize_leaf and tetrahedralize_block emit exactly these per-face cones.
//   * Continuum. A block's point is free in the cube |p − v|∞ ≤ s/2 around its grid vertex v.
//     A template's coordinates are interval variables; a box that is not certified is bisected
//     along the apex's widest axis, at most kMaxBisections times per path. A pass proves the
//     bounds for every point of the region; no position is sampled.
//   * Enclosures. The naive interval evaluation first; when it is too wide, affine arithmetic
//     (first-order forms over the template's variables, remainders and rounding errors bounded
//     from above), intersected with it. Normals are computed from a corner other than the
//     apex, so the apex enters each of them linearly.
//   * Rounding. In a box that is not dyadic, grid vertices round and the location of a point
//     can be off by a few ulps; meshed cells are ≥ 2^13 ulps wide (detail/mesh_grid.hpp). So a
//     grid coordinate is a variable within s·2^-11 of its exact value, one variable per axis
//     and grid coordinate (BasicMeshGrid::coord depends on nothing else, so corners that share
//     a grid coordinate share its double), and the point region is widened by s·2^-10.
//     docs/OCTREE_MESH.md states the derivation and the one case it does not cover.
// Invariants checked: the interval and affine operations enclose the exact (GMP) results; every
// template is positively oriented with its six dihedral angles in the bounds; the same
// machinery refuses false bounds (a 14° minimum, a 160° maximum).
// Complexity: 546 templates (18 distinct triangles per face), about 250 000 boxes, ~4 s in
// Release; under AddressSanitizer every fourth template.
// Paper: Moore, "Interval Analysis" (1966), outward rounding; Comba & Stolfi, "Affine
// arithmetic" (1993), and Stolfi & de Figueiredo (1997) for the Chebyshev approximation of
// 1/√x; Kuhn's subdivision of the cube.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iostream>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/detail/mesh_grid.hpp"
#include "dynmesh/detail/octree_mesh_rules.hpp"
#include "dynmesh/octree_mesh.hpp"
#include "dynmesh/tet_mesh.hpp"
#include "../sanitized.hpp"

namespace {

using namespace dynmesh;
using detail::GridPoint3;
using detail::OctreeGrid;

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------- interval arithmetic

/// std::nextafter(x, ∓∞) for finite x, by one step of the bit pattern (the neighbour of a
/// finite double is the next or previous integer of its bits, 0 aside); kept inline because
/// the proof spends its time here. Tested against std::nextafter below.
double down(double x) {
  if (!std::isfinite(x)) return x;
  if (x == 0) return -std::numeric_limits<double>::denorm_min();
  const auto bits = std::bit_cast<std::uint64_t>(x);
  return std::bit_cast<double>(x > 0 ? bits - 1 : bits + 1);
}
double up(double x) {
  if (!std::isfinite(x)) return x;
  if (x == 0) return std::numeric_limits<double>::denorm_min();
  const auto bits = std::bit_cast<std::uint64_t>(x);
  return std::bit_cast<double>(x > 0 ? bits + 1 : bits - 1);
}

/// The closed interval [lo, hi]. Each operation computes its bounds in IEEE double and moves
/// them one ulp outward: an IEEE operation (std::sqrt included) is correctly rounded, so its
/// error is below one ulp and the result encloses the exact operation on every member of the
/// operands. A NaN anywhere widens the result to the whole line, so nothing is ever certified
/// from a NaN.
struct Interval {
  double lo = 0, hi = 0;

  static Interval point(double x) { return {x, x}; }
  static Interval around(double x, double radius) { return {down(x - radius), up(x + radius)}; }
  double mid() const { return 0.5 * (lo + hi); }
  double width() const { return hi - lo; }
};

Interval hull(const double (&p)[4]) {
  for (double x : p)
    if (std::isnan(x)) return {-kInf, kInf};
  return {down(*std::min_element(p, p + 4)), up(*std::max_element(p, p + 4))};
}

Interval operator+(const Interval& a, const Interval& b) { return {down(a.lo + b.lo), up(a.hi + b.hi)}; }
Interval operator-(const Interval& a, const Interval& b) { return {down(a.lo - b.hi), up(a.hi - b.lo)}; }
Interval operator*(const Interval& a, const Interval& b) {
  return hull({a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi});
}
/// a / b; the whole line when b holds 0.
Interval operator/(const Interval& a, const Interval& b) {
  if (!(b.lo > 0 || b.hi < 0)) return {-kInf, kInf};
  return hull({a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi});
}
/// x² over a (tighter than a·a when a holds 0: a square is never negative).
Interval square(const Interval& a) {
  if (a.lo >= 0) return {down(a.lo * a.lo), up(a.hi * a.hi)};
  if (a.hi <= 0) return {down(a.hi * a.hi), up(a.lo * a.lo)};
  return {0.0, up(std::max(a.lo * a.lo, a.hi * a.hi))};
}
/// √x over the non-negative part of a.
Interval sqrt(const Interval& a) {
  return {a.lo > 0 ? std::max(0.0, down(std::sqrt(a.lo))) : 0.0, up(std::sqrt(std::max(a.hi, 0.0)))};
}
Interval intersect(const Interval& a, const Interval& b) { return {std::max(a.lo, b.lo), std::min(a.hi, b.hi)}; }
const Interval& value(const Interval& a) { return a; }

// ------------------------------------------------------------------------ affine arithmetic

/// A template has at most this many variables (a block: 3 for its point and at most 3 grid
/// coordinates per axis; a leaf: its 4 corners share grid coordinates).
constexpr std::size_t kVars = 12;

constexpr double kUnitRoundoff = 0x1p-53;
/// Covers the absolute error of a product that underflows (≤ 2^-1075); nothing here comes near.
constexpr double kTiny = 0x1p-1000;

double mul_up(double a, double b) { return up(a * b); }  // ≥ a·b for a, b ≥ 0

/// An upper bound of a sum of non-negative doubles, without rounding each step: recursive
/// summation of m ≤ 2^20 terms errs by less than m·u·sum < 2^-32·sum, so (1 + 2^-32) times the
/// computed sum, rounded up, bounds the exact one.
class UpperSum {
 public:
  void add(double v) { s_ += v; }
  double bound() const { return up(s_ * (1 + 0x1p-32)); }

 private:
  double s_ = 0;
};

/// The rounding errors of one affine operation. A double v computed by one correctly rounded
/// + or × from exact operands is within u·|exact| < 2u·|v| of it (kTiny more on underflow), and
/// errors of a chain add up.
class Roundoff {
 public:
  void rounded(double v) {
    values_.add(std::fabs(v));
    ++count_;
  }
  void term(double t) { terms_.add(t); }  // t ≥ 0, itself an upper bound
  double bound() const {
    return up(up(mul_up(values_.bound(), 2 * kUnitRoundoff) + terms_.bound()) + count_ * kTiny);
  }

 private:
  UpperSum values_, terms_;
  int count_ = 0;
};

/// An affine form: the set c + Σ a_i·ε_i + e over ε ∈ [−1, 1]^n, |e| ≤ r. The ε_i are the
/// template's variables scaled to [−1, 1], shared by every form of one evaluation, so linear
/// dependencies cancel exactly (Comba & Stolfi's affine arithmetic); every nonlinear remainder
/// and every rounding error goes into r, bounded from above.
struct Affine {
  double c = 0;
  std::array<double, kVars> a{};
  double r = 0;
  std::size_t n = 0;

  /// Σ|a_i| + r: x lies in [c − radius, c + radius].
  double radius() const {
    UpperSum s;
    s.add(r);
    for (std::size_t i = 0; i < n; ++i) s.add(std::fabs(a[i]));
    return s.bound();
  }
  Interval range() const {
    const double rad = radius();
    return {down(c - rad), up(c + rad)};
  }
};

/// The variable i over [lo, hi]: centre and half-width (rounded so that the form covers it).
Affine variable(std::size_t i, std::size_t n, const Interval& x) {
  Affine f;
  f.n = n;
  f.c = x.mid();
  f.a[i] = std::max(up(x.hi - f.c), up(f.c - x.lo));
  return f;
}

/// The constant x (exact) in an evaluation over n variables.
Affine constant(double x, std::size_t n) {
  Affine f;
  f.n = n;
  f.c = x;
  return f;
}

Affine add_or_sub(const Affine& x, const Affine& y, double sign) {
  Affine z;
  z.n = std::max(x.n, y.n);
  Roundoff e;
  z.c = x.c + sign * y.c;
  e.rounded(z.c);
  for (std::size_t i = 0; i < z.n; ++i) {
    z.a[i] = x.a[i] + sign * y.a[i];
    e.rounded(z.a[i]);
  }
  e.term(x.r);
  e.term(y.r);
  z.r = e.bound();
  return z;
}
Affine operator+(const Affine& x, const Affine& y) { return add_or_sub(x, y, 1); }
Affine operator-(const Affine& x, const Affine& y) { return add_or_sub(x, y, -1); }

/// (x_c + X)(y_c + Y) = x_c·y_c + x_c·Y + y_c·X + X·Y, |X·Y| ≤ rad(X)·rad(Y).
Affine operator*(const Affine& x, const Affine& y) {
  Affine z;
  z.n = std::max(x.n, y.n);
  Roundoff e;
  z.c = x.c * y.c;
  e.rounded(z.c);
  for (std::size_t i = 0; i < z.n; ++i) {
    const double t1 = x.c * y.a[i], t2 = y.c * x.a[i];
    z.a[i] = t1 + t2;
    e.rounded(t1);
    e.rounded(t2);
    e.rounded(z.a[i]);
  }
  e.term(mul_up(std::fabs(x.c), y.r));
  e.term(mul_up(std::fabs(y.c), x.r));
  e.term(mul_up(x.radius(), y.radius()));
  z.r = e.bound();
  return z;
}

/// (x_c + X)² = x_c² + 2·x_c·X + X², with X² in [0, rad²]: its midpoint joins the centre.
Affine square(const Affine& x) {
  Affine z;
  z.n = x.n;
  Roundoff e;
  const double rad = x.radius(), half = mul_up(mul_up(rad, rad), 0.5);
  const double c2 = x.c * x.c;
  z.c = c2 + half;
  e.rounded(c2);
  e.rounded(z.c);
  for (std::size_t i = 0; i < z.n; ++i) {
    z.a[i] = (2 * x.c) * x.a[i];  // 2·x_c is exact
    e.rounded(z.a[i]);
  }
  e.term(mul_up(2 * std::fabs(x.c), x.r));
  e.term(half);
  z.r = e.bound();
  return z;
}

/// 1/√x by its Chebyshev line over the range [lo, hi] (Stolfi & de Figueiredo): α the slope
/// of the chord, g(x) = 1/√x − α·x convex, so g lies between its minimum (bounded below by the
/// tangent at ξ, where the derivative is near α) and its larger end value. Any α and ξ are
/// sound: they only make the bound looser. Needs range > 0.
Affine inv_sqrt(const Affine& x) {
  Affine z;
  z.n = x.n;
  const Interval range = x.range();
  if (!(range.lo > 0 && range.hi < kInf)) {
    z.r = kInf;  // nothing certifiable
    return z;
  }
  auto f = [](double v) { return Interval::point(1) / sqrt(Interval::point(v)); };
  auto g = [&](double v, double alpha) { return f(v) - Interval::point(alpha) * Interval::point(v); };
  const double lo = range.lo, hi = range.hi;
  const double alpha = hi > lo ? (1 / std::sqrt(hi) - 1 / std::sqrt(lo)) / (hi - lo) : -0.5 / (lo * std::sqrt(lo));
  const double xi = std::clamp(std::pow(-2 * alpha, -2.0 / 3), lo, hi);  // f'(ξ) = −ξ^(−3/2)/2 = α
  const Interval slope_at_xi = Interval::point(-0.5) / (Interval::point(xi) * sqrt(Interval::point(xi))) -
                               Interval::point(alpha);
  const double g_min = std::min((g(xi, alpha) + slope_at_xi * (Interval::point(lo) - Interval::point(xi))).lo,
                                (g(xi, alpha) + slope_at_xi * (Interval::point(hi) - Interval::point(xi))).lo);
  const double g_max = std::max(g(lo, alpha).hi, g(hi, alpha).hi);
  // 1/√x = α·x + ζ ± δ, ζ the middle of [g_min, g_max].
  const double zeta = 0.5 * (g_min + g_max);
  const double delta = std::max(up(g_max - zeta), up(zeta - g_min));
  Roundoff e;
  const double ax = alpha * x.c;
  z.c = ax + zeta;
  e.rounded(ax);
  e.rounded(z.c);
  for (std::size_t i = 0; i < z.n; ++i) {
    z.a[i] = alpha * x.a[i];
    e.rounded(z.a[i]);
  }
  e.term(mul_up(std::fabs(alpha), x.r));
  e.term(delta);
  z.r = e.bound();
  return z;
}
Interval inv_sqrt(const Interval& x) { return Interval::point(1) / sqrt(x); }
Interval value(const Affine& x) { return x.range(); }

// --------------------------------------------------------------- the measures of a template

template <class T>
using Vec = std::array<T, 3>;

template <class T>
Vec<T> operator-(const Vec<T>& a, const Vec<T>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
template <class T>
Vec<T> cross(const Vec<T>& a, const Vec<T>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
template <class T>
T dot(const Vec<T>& a, const Vec<T>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
template <class T>
T norm2(const Vec<T>& a) {
  return square(a[0]) + square(a[1]) + square(a[2]);
}

/// Edge (i, j) and the two other corners k, l: the dihedral at the edge lies between faces
/// (i, j, k) and (i, j, l).
constexpr unsigned kEdges[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}, {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};

template <class T>
struct Measures {
  T det;                  // det(P1 − P0, P2 − P0, P3 − P0): > 0 for a positive tetrahedron
  std::array<T, 6> cos;   // cos θ of the dihedral at each edge of kEdges
};

/// (P_j − P_i) × (P_k − P_i), the normal of triangle (i, j, k), computed from a corner other
/// than 0 (a cyclic rotation gives the same vector): corner 0, the apex, then appears in one
/// factor only, so the normal is linear in it and its enclosures stay tight.
template <class T>
Vec<T> normal(const std::array<Vec<T>, 4>& p, unsigned i, unsigned j, unsigned k) {
  if (i == 0) return cross(p[k] - p[j], p[i] - p[j]);
  return cross(p[j] - p[i], p[k] - p[i]);
}

/// The measures of the tetrahedron p, in T = Interval or Affine. False when a face's normal
/// may vanish (then no cosine is defined).
template <class T>
bool measure(const std::array<Vec<T>, 4>& p, Measures<T>& m) {
  // det(P1 − P0, P2 − P0, P3 − P0) = (P0 − P1)·((P3 − P1) × (P2 − P1)): P0 in one factor.
  m.det = dot(p[0] - p[1], cross(p[3] - p[1], p[2] - p[1]));
  for (unsigned k = 0; k < 6; ++k) {
    const auto& e = kEdges[k];
    // Both normals are orthogonal to the edge, and their angle is the angle between the two
    // faces inside the tetrahedron: cos θ = n_k·n_l / (|n_k|·|n_l|).
    const Vec<T> nk = normal(p, e[0], e[1], e[2]), nl = normal(p, e[0], e[1], e[3]);
    const T dk = norm2(nk), dl = norm2(nl);
    if (!(value(dk).lo > 0 && value(dl).lo > 0)) return false;
    m.cos[k] = dot(nk, nl) * inv_sqrt(dk) * inv_sqrt(dl);
  }
  return true;
}

// -------------------------------------------------------------------------------- templates

/// A tetrahedron (apex, a, b, c) whose coordinates are variables over intervals. Corner k's
/// coordinate on axis a is vars[at[k][a]]. Two grid corners with the same grid coordinate on
/// an axis share its variable: their doubles are equal whatever the rounding.
struct Template {
  std::vector<Interval> vars;
  std::array<std::array<std::uint8_t, 3>, 4> at{};
};

using Frame3 = std::array<double, 3>;

class TemplateBuilder {
 public:
  /// Corner k is free in `region` (a block's point).
  TemplateBuilder& free_corner(unsigned k, const Vec<Interval>& region) {
    for (unsigned a = 0; a < 3; ++a) t_.at[k][a] = add(region[a]);
    return *this;
  }
  /// Corner k is the grid vertex at x, each coordinate within `radius` of it.
  TemplateBuilder& grid_corner(unsigned k, const Frame3& x, double radius) {
    for (unsigned a = 0; a < 3; ++a) {
      const auto [it, fresh] = grid_.try_emplace({a, x[a]}, 0);
      if (fresh) it->second = add(Interval::around(x[a], radius));
      t_.at[k][a] = it->second;
    }
    return *this;
  }
  Template done() const { return t_; }

 private:
  std::uint8_t add(const Interval& x) {
    EXPECT_LT(t_.vars.size(), kVars);
    t_.vars.push_back(x);
    return static_cast<std::uint8_t>(t_.vars.size() - 1);
  }
  Template t_;
  std::map<std::pair<unsigned, double>, std::uint8_t> grid_;
};

std::array<Vec<Interval>, 4> corners(const Template& t, const std::vector<Interval>& x) {
  std::array<Vec<Interval>, 4> p;
  for (unsigned k = 0; k < 4; ++k)
    for (unsigned a = 0; a < 3; ++a) p[k][a] = x[t.at[k][a]];
  return p;
}

/// Naive enclosure of the measures over the box x.
bool enclose_naive(const Template& t, const std::vector<Interval>& x, Measures<Interval>& m) {
  return measure(corners(t, x), m);
}

/// The affine enclosure of the measures over the box x.
bool enclose_affine(const Template& t, const std::vector<Interval>& x, Measures<Interval>& m) {
  std::array<Vec<Affine>, 4> p;
  for (unsigned k = 0; k < 4; ++k)
    for (unsigned a = 0; a < 3; ++a) p[k][a] = variable(t.at[k][a], x.size(), x[t.at[k][a]]);
  Measures<Affine> f;
  if (!measure(p, f)) return false;
  m.det = f.det.range();
  for (unsigned k = 0; k < 6; ++k) m.cos[k] = f.cos[k].range();
  return true;
}

// ------------------------------------------------------------------------------ the proof

/// The bounds to certify, in degrees, and the cosines compared against: cos_min ≤ cos(min)
/// and cos_max ≥ cos(max), a hair on the safe side of the double cosine (whose error is far
/// below 1e-12), so that cos θ ≤ cos_min proves θ ≥ min and cos θ ≥ cos_max proves θ ≤ max.
struct AngleBounds {
  double min_deg, max_deg, cos_min, cos_max;
  AngleBounds(double lo, double hi)
      : min_deg(lo),
        max_deg(hi),
        cos_min(std::cos(lo * std::numbers::pi / 180) - 1e-12),
        cos_max(std::cos(hi * std::numbers::pi / 180) + 1e-12) {}
};

/// What a proof saw: the certified cosine extremes over every box it accepted (so the angles
/// they give bracket every dihedral of the mesh), its effort, and why it failed.
struct ProofStats {
  std::size_t templates = 0, boxes = 0, affine_boxes = 0;
  int deepest = 0;
  double cos_lo = 1, cos_hi = -1;
  bool failed = false;
  std::string failure;

  // acos is not correctly rounded: these are reports, the proof is the comparison of cosines.
  double min_angle_deg() const { return std::acos(std::min(1.0, cos_hi)) * 180 / std::numbers::pi; }
  double max_angle_deg() const { return std::acos(std::max(-1.0, cos_lo)) * 180 / std::numbers::pi; }
};

/// Positive, and every cosine in [cos_max, cos_min] (false on a NaN).
bool within(const Measures<Interval>& m, const AngleBounds& bounds) {
  if (!(m.det.lo > 0)) return false;
  for (const Interval& c : m.cos)
    if (!(c.hi <= bounds.cos_min && c.lo >= bounds.cos_max)) return false;
  return true;
}

/// Certifies the template over the box x: positive orientation and all six angles in bounds.
/// The naive enclosure first (enough for a leaf's templates); then affine arithmetic, whose
/// enclosure is intersected with the naive one (both hold).
bool certify(const Template& t, const std::vector<Interval>& x, const AngleBounds& bounds, ProofStats& stats) {
  Measures<Interval> naive, m;
  const bool has_naive = enclose_naive(t, x, naive);
  if (has_naive && within(naive, bounds)) {
    m = naive;
  } else {
    ++stats.affine_boxes;
    if (!enclose_affine(t, x, m)) return false;
    if (has_naive) {
      m.det = intersect(naive.det, m.det);
      for (unsigned k = 0; k < 6; ++k) m.cos[k] = intersect(naive.cos[k], m.cos[k]);
      // Both enclose the same values: disjoint enclosures would be a bug, not a proof.
      bool empty = m.det.lo > m.det.hi;
      for (const Interval& c : m.cos) empty = empty || c.lo > c.hi;
      if (empty) {
        ADD_FAILURE() << "the naive and affine enclosures are disjoint";
        return false;
      }
    }
    if (!within(m, bounds)) return false;
  }
  for (const Interval& c : m.cos) {
    stats.cos_lo = std::min(stats.cos_lo, c.lo);
    stats.cos_hi = std::max(stats.cos_hi, c.hi);
  }
  return true;
}

/// At most this many bisections of one template's apex region along any path.
constexpr int kMaxBisections = 24;

/// The six dihedral angles of a double tetrahedron, in degrees (for reports and samples).
std::array<double, 6> dihedral_angles(const std::array<Frame3, 4>& t) {
  std::array<Vec<Interval>, 4> p;
  for (unsigned k = 0; k < 4; ++k)
    for (unsigned a = 0; a < 3; ++a) p[k][a] = Interval::point(t[k][a]);
  Measures<Interval> m;
  std::array<double, 6> out{};
  if (!measure(p, m)) return out;
  for (unsigned k = 0; k < 6; ++k) out[k] = std::acos(std::clamp(m.cos[k].mid(), -1.0, 1.0)) * 180 / std::numbers::pi;
  return out;
}

std::string describe(const std::vector<Interval>& x) {
  std::ostringstream os;
  os.precision(17);
  for (const Interval& i : x) os << " [" << i.lo << ", " << i.hi << "]";
  return os.str();
}

/// Proves the template over the box x, bisecting the apex's widest coordinate while undecided.
/// False (with the reason in stats) when a path needs more than kMaxBisections.
bool prove(const Template& t, const std::vector<Interval>& x, const AngleBounds& bounds, int depth,
           ProofStats& stats) {
  ++stats.boxes;
  stats.deepest = std::max(stats.deepest, depth);
  if (certify(t, x, bounds, stats)) return true;
  if (depth == kMaxBisections) {
    std::array<Frame3, 4> centre;
    for (unsigned k = 0; k < 4; ++k)
      for (unsigned a = 0; a < 3; ++a) centre[k][a] = x[t.at[k][a]].mid();
    std::ostringstream os;
    os << "undecided after " << depth << " bisections; variables" << describe(x) << "; corners (apex first):";
    for (const Frame3& c : centre) os << " (" << c[0] << ", " << c[1] << ", " << c[2] << ")";
    os << "; angles at the centre:";
    for (double a : dihedral_angles(centre)) os << ' ' << a;
    stats.failed = true;
    stats.failure = os.str();
    return false;
  }
  std::uint8_t split = t.at[0][0];
  for (unsigned a = 1; a < 3; ++a)
    if (x[t.at[0][a]].width() > x[split].width()) split = t.at[0][a];
  const double m = x[split].mid();
  std::vector<Interval> left = x, right = x;
  left[split].hi = m;
  right[split].lo = m;
  return prove(t, left, bounds, depth + 1, stats) && prove(t, right, bounds, depth + 1, stats);
}

// ------------------------------------------------------------------------- the enumeration

/// The templates are built in the unit box (dyadic: every grid vertex is an exact double) at
/// level 3, away from the box sides, and read in a frame in units of the cell side s
/// (translation by a grid vertex and scaling by 8: exact).
constexpr int kLevel = 3;
constexpr std::uint64_t kSide = std::uint64_t{1} << (kMaxLevel - kLevel);
const Box<3> kUnitBox{{0, 0, 0}, 1.0};

/// The rounding margins, in units of s (header comment): a grid coordinate's radius, and the
/// widening of the point region.
constexpr double kVertexMargin = 0x1p-11;
constexpr double kPointMargin = 0x1p-10;

using Offset = std::array<int, 3>;
using Triangle = std::array<GridPoint3, 3>;

/// The nine level-m cells whose split state can decide the triangulation of face
/// (axis, upper): on the face's side (offset 0 or out along `axis`), the cell across
/// (out, 0, 0) and the cells that touch one edge of the face (one other offset ±1).
std::array<Offset, 9> face_neighbours(unsigned axis, bool upper) {
  const int out = upper ? 1 : -1;
  std::array<Offset, 9> nb{};
  unsigned n = 0;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x) {
        const Offset o{x, y, z};
        if (o[axis] != 0 && o[axis] != out) continue;
        const int others = (o[(axis + 1) % 3] != 0) + (o[(axis + 2) % 3] != 0);
        if ((o[axis] == out && others == 0) || others == 1) nb[n++] = o;
      }
  EXPECT_EQ(n, 9u);
  return nb;
}

/// The triangles of face (axis, upper) of the level-kLevel cell at `lo` when the cells of
/// face_neighbours are split as the bits of `assignment` say: the real cone_face's output.
std::vector<Triangle> face_triangles(const GridPoint3& lo, unsigned axis, bool upper, unsigned assignment) {
  const std::array<Offset, 9> nb = face_neighbours(axis, upper);
  auto split = [&](int dx, int dy, int dz) {
    for (unsigned i = 0; i < 9; ++i)
      if (nb[i] == Offset{dx, dy, dz}) return ((assignment >> i) & 1u) != 0;
    ADD_FAILURE() << "cone_face read the cell at offset (" << dx << ", " << dy << ", " << dz
                  << "), outside its face's nine";
    return false;
  };
  std::vector<Triangle> out;
  detail::octree_detail::cone_face(lo, kLevel, axis, upper, split,
                                   [&](const GridPoint3& a, const GridPoint3& b, const GridPoint3& c) {
                                     out.push_back({a, b, c});
                                   });
  return out;
}

/// Coordinates in units of s relative to the grid vertex `origin`.
struct Frame {
  OctreeGrid grid{kUnitBox};
  Point<3> origin;
  explicit Frame(const GridPoint3& o) : origin(grid.vertex(o)) {}
  Frame3 operator()(const Point<3>& x) const {
    constexpr double scale = 1 << kLevel;
    return {(x[0] - origin[0]) * scale, (x[1] - origin[1]) * scale, (x[2] - origin[2]) * scale};
  }
  Frame3 operator()(const GridPoint3& g) const { return (*this)(grid.vertex(g)); }
};

/// The triangle's rotation that starts at its least corner (the same oriented triangle).
std::array<Frame3, 3> least_first(const std::array<Frame3, 3>& t) {
  const std::size_t k = static_cast<std::size_t>(std::min_element(t.begin(), t.end()) - t.begin());
  return {t[k], t[(k + 1) % 3], t[(k + 2) % 3]};
}

/// One family of templates: the distinct triangles (in the frame) that share an apex.
struct Family {
  std::set<std::array<Frame3, 3>> triangles;
  std::size_t assignments = 0, emitted = 0;
};

/// The block around the level-kLevel grid vertex v = (4, 4, 4): its cells v − 1 + b.
GridPoint3 block_vertex() { return {4 * kSide, 4 * kSide, 4 * kSide}; }
GridPoint3 block_cell_lo(unsigned b) {
  GridPoint3 g = block_vertex();
  for (unsigned a = 0; a < 3; ++a) g[a] = g[a] - kSide + ((b >> a) & 1u) * kSide;
  return g;
}

/// The block's 8 cells × 3 outer faces (upper = b_axis) × 512 assignments; frame origin v.
Family block_family() {
  const Frame frame(block_vertex());
  Family f;
  for (unsigned b = 0; b < 8; ++b)
    for (unsigned axis = 0; axis < 3; ++axis)
      for (unsigned assignment = 0; assignment < 512; ++assignment) {
        ++f.assignments;
        for (const Triangle& t : face_triangles(block_cell_lo(b), axis, ((b >> axis) & 1u) != 0, assignment)) {
          ++f.emitted;
          f.triangles.insert(least_first({frame(t[0]), frame(t[1]), frame(t[2])}));
        }
      }
  return f;
}

/// The leaf of level-kLevel index (3, 3, 3).
CellId<3> leaf_cell() {
  CellId<3> c;
  c.level = kLevel;
  c.index = {3, 3, 3};
  return c;
}
GridPoint3 leaf_lo() { return detail::octree_detail::cell_corner(leaf_cell()); }
GridPoint3 leaf_centre() {
  const GridPoint3 lo = leaf_lo();
  return {lo[0] + kSide / 2, lo[1] + kSide / 2, lo[2] + kSide / 2};
}

/// The leaf's 6 faces × 512 assignments; frame origin its centre.
Family leaf_family() {
  const Frame frame(leaf_centre());
  Family f;
  for (unsigned axis = 0; axis < 3; ++axis)
    for (bool upper : {false, true})
      for (unsigned assignment = 0; assignment < 512; ++assignment) {
        ++f.assignments;
        for (const Triangle& t : face_triangles(leaf_lo(), axis, upper, assignment)) {
          ++f.emitted;
          f.triangles.insert(least_first({frame(t[0]), frame(t[1]), frame(t[2])}));
        }
      }
  return f;
}

/// Kuhn's six tetrahedra of the leaf, from the real tetrahedralize_leaf, in its frame.
std::vector<std::array<Frame3, 4>> kuhn_tetrahedra() {
  const Frame frame(leaf_centre());
  std::vector<Tetrahedron> tets;
  detail::tetrahedralize_leaf(frame.grid, leaf_cell(), 0, tets);
  std::vector<std::array<Frame3, 4>> out;
  for (const Tetrahedron& t : tets) out.push_back({frame(t.v[0]), frame(t.v[1]), frame(t.v[2]), frame(t.v[3])});
  return out;
}

/// The point region around v (the frame's origin), widened by the rounding margin.
Vec<Interval> point_region() {
  const double r = 0.5 + kPointMargin;
  return {Interval{-r, r}, Interval{-r, r}, Interval{-r, r}};
}

/// The templates: Kuhn's six, the empty leaf's cones (apex: the centre, a grid vertex), the
/// block's cones (apex: the point region).
std::vector<Template> all_templates() {
  std::vector<Template> out;
  for (const auto& t : kuhn_tetrahedra()) {
    TemplateBuilder b;
    for (unsigned k = 0; k < 4; ++k) b.grid_corner(k, t[k], kVertexMargin);
    out.push_back(b.done());
  }
  for (const auto& t : leaf_family().triangles) {
    TemplateBuilder b;
    b.grid_corner(0, {0, 0, 0}, kVertexMargin);
    for (unsigned k = 0; k < 3; ++k) b.grid_corner(k + 1, t[k], kVertexMargin);
    out.push_back(b.done());
  }
  for (const auto& t : block_family().triangles) {
    TemplateBuilder b;
    b.free_corner(0, point_region());
    for (unsigned k = 0; k < 3; ++k) b.grid_corner(k + 1, t[k], kVertexMargin);
    out.push_back(b.done());
  }
  return out;
}

/// The proof for `bounds` over every `stride`-th template (1: all); stops at the first
/// template it cannot certify.
ProofStats prove_all(const AngleBounds& bounds, std::size_t stride) {
  ProofStats stats;
  const std::vector<Template> templates = all_templates();
  for (std::size_t i = 0; i < templates.size(); i += stride) {
    ++stats.templates;
    if (!prove(templates[i], templates[i].vars, bounds, 0, stats)) break;
  }
  return stats;
}

/// Sampled (not proved) extremes: grid vertices exact, a block's point on the lattice of step
/// `step` (in units of s) over its region, corners included, no rounding margins.
struct Sampled {
  double min = 180, max = 0;
  Frame3 min_apex{}, max_apex{};
};

Sampled sample_extremes(int per_half_side) {
  Sampled s;
  auto see = [&](const std::array<Frame3, 4>& t) {
    for (double a : dihedral_angles(t)) {
      if (a < s.min) s.min = a, s.min_apex = t[0];
      if (a > s.max) s.max = a, s.max_apex = t[0];
    }
  };
  for (const auto& t : kuhn_tetrahedra()) see(t);
  for (const auto& t : leaf_family().triangles) see({Frame3{0, 0, 0}, t[0], t[1], t[2]});
  const Family blocks = block_family();
  const double step = 0.5 / per_half_side;
  for (int i = -per_half_side; i <= per_half_side; ++i)
    for (int j = -per_half_side; j <= per_half_side; ++j)
      for (int k = -per_half_side; k <= per_half_side; ++k)
        for (const auto& t : blocks.triangles) see({Frame3{i * step, j * step, k * step}, t[0], t[1], t[2]});
  return s;
}

/// Under AddressSanitizer (CI's -O0 job) the proof visits every fourth template only; the
/// full proof is the build without it.
constexpr std::size_t kTemplateStride = test_support::kSanitized ? 4 : 1;

/// 6 Kuhn + 6 faces × 18 + 24 faces × 18: a face's distinct triangles are the 8 of its
/// quarters, the 2 of its diagonal, and the fans' 4 whole-edge and 8 half-edge triangles, 4
/// of which are quarter triangles.
constexpr std::size_t kTriangleKinds = 18;
constexpr std::size_t kTemplates = 6 + 6 * kTriangleKinds + 24 * kTriangleKinds;

// ------------------------------------------------------------------------------- the tests

bool contains(const Interval& i, const mpq_class& v) { return mpq_class(i.lo) <= v && v <= mpq_class(i.hi); }

TEST(OctreeMeshBoundInterval, OutwardStepIsNextafter) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> mant(-1, 1);
  std::uniform_int_distribution<int> exp(-1074, 1023);
  for (int i = 0; i < 100000; ++i) {
    const double x = std::ldexp(mant(rng), exp(rng));
    ASSERT_EQ(down(x), std::nextafter(x, -kInf)) << x;
    ASSERT_EQ(up(x), std::nextafter(x, kInf)) << x;
  }
  for (double x : {0.0, -0.0, std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::max(),
                   std::numeric_limits<double>::max()}) {
    EXPECT_EQ(down(x), std::nextafter(x, -kInf)) << x;
    EXPECT_EQ(up(x), std::nextafter(x, kInf)) << x;
  }
}

TEST(OctreeMeshBoundInterval, EnclosesExactResults) {
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> coord(-4, 4), width(0, 1e-3), unit(0, 1);
  for (int trial = 0; trial < 2000; ++trial) {
    // Two intervals and a member of each; the operations on the members, exactly in GMP.
    Interval a, b;
    double x[2];
    for (int k = 0; k < 2; ++k) {
      const double c = coord(rng), w = width(rng);
      (k ? b : a) = Interval{c - w, c + w};
      x[k] = std::min(c + w, c - w + 2 * w * unit(rng));
    }
    const mpq_class qa(x[0]), qb(x[1]);
    EXPECT_TRUE(contains(a + b, qa + qb));
    EXPECT_TRUE(contains(a - b, qa - qb));
    EXPECT_TRUE(contains(a * b, qa * qb));
    EXPECT_TRUE(contains(square(a), qa * qa));
    if (b.lo > 0 || b.hi < 0) {
      EXPECT_TRUE(contains(a / b, qa / qb));
    }
    const mpq_class e = (qa * qb - qa) * (qa * qb - qa) + qb * qb;  // nested: (a·b − a)² + b·b
    EXPECT_TRUE(contains(square(a * b - a) + b * b, e));
    // √: lo² ≤ x ≤ hi², exactly.
    const Interval r = sqrt(square(a) + b * b);
    const mpq_class v = qa * qa + qb * qb;
    EXPECT_LE(mpq_class(r.lo) * mpq_class(r.lo), v);
    EXPECT_GE(mpq_class(r.hi) * mpq_class(r.hi), v);
    EXPECT_GE(r.lo, 0.0);
  }
  // The rounding is outward even when the double result is exact.
  const Interval t = Interval::point(0.5) * Interval::point(0.25);
  EXPECT_LT(t.lo, 0.125);
  EXPECT_GT(t.hi, 0.125);
  // Nothing certifiable comes out of a division by an interval holding 0.
  const Interval w = Interval::point(1) / Interval{-1, 1};
  EXPECT_EQ(w.lo, -kInf);
  EXPECT_EQ(w.hi, kInf);
}

TEST(OctreeMeshBoundInterval, AffineFormsEncloseExactResults) {
  // Three variables over random intervals; a polynomial and 1/√ of a positive one, as affine
  // forms; at random members, the exact values (GMP) lie in the forms' ranges.
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> coord(-2, 2), width(0, 0.5), unit(0, 1);
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<Interval> box(3);
    for (Interval& i : box) {
      const double c = coord(rng), w = width(rng);
      i = Interval{c - w, c + w};
    }
    std::array<Affine, 3> v;
    for (std::size_t i = 0; i < 3; ++i) v[i] = variable(i, 3, box[i]);
    const Affine poly = v[0] * v[1] - square(v[2]) + v[0] * v[0] * v[2];
    const Affine positive = square(v[0]) + square(v[1] - v[2]) + constant(4, 3);
    const Affine root = inv_sqrt(positive);
    const Interval pr = poly.range(), rr = root.range();
    ASSERT_TRUE(std::isfinite(pr.lo) && std::isfinite(pr.hi) && rr.lo > 0 && std::isfinite(rr.hi));
    for (int s = 0; s < 20; ++s) {
      mpq_class q[3];
      for (std::size_t i = 0; i < 3; ++i)
        q[i] = mpq_class(std::min(box[i].hi, box[i].lo + unit(rng) * box[i].width()));
      EXPECT_TRUE(contains(pr, q[0] * q[1] - q[2] * q[2] + q[0] * q[0] * q[2])) << trial;
      const mpq_class x = q[0] * q[0] + (q[1] - q[2]) * (q[1] - q[2]) + 4;
      // lo ≤ 1/√x ≤ hi ⇔ lo²·x ≤ 1 ≤ hi²·x (lo > 0).
      EXPECT_LE(mpq_class(rr.lo) * mpq_class(rr.lo) * x, 1) << trial;
      EXPECT_GE(mpq_class(rr.hi) * mpq_class(rr.hi) * x, 1) << trial;
    }
  }
}

TEST(OctreeMeshBoundInterval, AffineMeasuresEncloseSamples) {
  // Random tetrahedra near the regular corner, boxes of random widths; the affine enclosure
  // alone (not intersected with the naive one) must contain every sampled value.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2), unit(0, 1), radius(1e-4, 5e-2);
  const Frame3 base[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int trial = 0; trial < 300; ++trial) {
    TemplateBuilder b;
    const double r = radius(rng);
    b.free_corner(0, {Interval::around(jitter(rng), r), Interval::around(jitter(rng), r),
                      Interval::around(jitter(rng), r)});
    for (unsigned k = 1; k < 4; ++k)
      b.grid_corner(k, {base[k][0] + jitter(rng), base[k][1] + jitter(rng), base[k][2] + jitter(rng)}, r / 4);
    const Template t = b.done();
    Measures<Interval> m;
    ASSERT_TRUE(enclose_affine(t, t.vars, m));
    for (int s = 0; s < 20; ++s) {
      std::vector<Interval> x(t.vars.size());
      for (std::size_t i = 0; i < x.size(); ++i)
        x[i] = Interval::point(std::min(t.vars[i].hi, t.vars[i].lo + unit(rng) * t.vars[i].width()));
      Measures<Interval> at;
      ASSERT_TRUE(enclose_naive(t, x, at));  // a point box: a tight enclosure of the value
      EXPECT_LE(m.det.lo, at.det.hi);
      EXPECT_GE(m.det.hi, at.det.lo);
      for (unsigned k = 0; k < 6; ++k) {
        EXPECT_LE(m.cos[k].lo, at.cos[k].hi) << trial;
        EXPECT_GE(m.cos[k].hi, at.cos[k].lo) << trial;
      }
    }
  }
}

TEST(OctreeMeshBoundInterval, CertifiesTheRegularCorner) {
  // The corner tetrahedron (0, e_x, e_y, e_z): three angles of 90°, three of acos(1/√3) ≈ 54.7°.
  const Frame3 c[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  TemplateBuilder b;
  for (unsigned k = 0; k < 4; ++k) b.grid_corner(k, c[k], 0);
  const Template t = b.done();
  Measures<Interval> naive, affine;
  ASSERT_TRUE(enclose_naive(t, t.vars, naive));
  ASSERT_TRUE(enclose_affine(t, t.vars, affine));
  for (const Measures<Interval>& m : {naive, affine}) {
    EXPECT_TRUE(m.det.lo <= 1 && 1 <= m.det.hi);  // det(e_x, e_y, e_z)
    for (unsigned k = 0; k < 6; ++k) {
      const double want = kEdges[k][0] == 0 ? 0 : 1 / std::sqrt(3.0);  // apex edges: 90°
      EXPECT_NEAR(m.cos[k].mid(), want, 1e-12) << k;
    }
  }
  ProofStats stats;
  EXPECT_TRUE(certify(t, t.vars, AngleBounds(54, 91), stats));
  EXPECT_NEAR(stats.min_angle_deg(), 54.7356, 1e-3);
  EXPECT_NEAR(stats.max_angle_deg(), 90.0, 1e-3);
  EXPECT_FALSE(certify(t, t.vars, AngleBounds(55, 91), stats));   // 54.7° < 55°
  EXPECT_FALSE(certify(t, t.vars, AngleBounds(54, 89.9), stats));  // 90° > 89.9°
  Template flipped = t;  // corners 1 and 2 swapped: negative, refused
  std::swap(flipped.at[1], flipped.at[2]);
  EXPECT_FALSE(certify(flipped, flipped.vars, AngleBounds(1, 179), stats));
}

TEST(OctreeMeshBound, EnumerationMatchesTetrahedralizeLeaf) {
  const OctreeGrid grid(kUnitBox);
  const CellId<3> cell = leaf_cell();
  const Point<3> centre = grid.vertex(leaf_centre());
  std::mt19937_64 rng(7);
  for (double density : {0.0, 0.03, 0.1, 0.3, 0.7}) {
    std::bernoulli_distribution bit(density);
    for (int trial = 0; trial < 200; ++trial) {
      std::uint32_t mask = 0;
      for (unsigned k = 0; k < 27; ++k)
        if (k != detail::leaf_bit(0, 0, 0) && bit(rng)) mask |= std::uint32_t{1} << k;
      std::vector<Tetrahedron> got, want;
      detail::tetrahedralize_leaf(grid, cell, mask, got);
      if ((mask & detail::kFaceEdgeNeighbours) == 0) {
        detail::tetrahedralize_leaf(grid, cell, 0, want);  // Kuhn's six, certified as such
        ASSERT_EQ(want.size(), 6u);
      } else {
        for (unsigned axis = 0; axis < 3; ++axis)
          for (bool upper : {false, true}) {
            const auto nb = face_neighbours(axis, upper);
            unsigned assignment = 0;
            for (unsigned i = 0; i < 9; ++i)
              if ((mask >> detail::leaf_bit(nb[i][0], nb[i][1], nb[i][2])) & 1u) assignment |= 1u << i;
            for (const Triangle& t : face_triangles(leaf_lo(), axis, upper, assignment))
              want.push_back(canonical_tetrahedron(centre, grid.vertex(t[0]), grid.vertex(t[1]), grid.vertex(t[2])));
          }
      }
      std::sort(got.begin(), got.end());
      std::sort(want.begin(), want.end());
      ASSERT_EQ(got, want) << "mask " << mask;
    }
  }
}

TEST(OctreeMeshBound, EnumerationMatchesTetrahedralizeBlock) {
  const OctreeGrid grid(kUnitBox);
  const GridPoint3 v = block_vertex();
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> step(0, 64);
  for (double density : {0.0, 0.03, 0.1, 0.3, 0.7}) {
    std::bernoulli_distribution bit(density);
    for (int trial = 0; trial < 200; ++trial) {
      // The owner: the block cell on p's side of v; p in its half-cell at v, dyadic.
      const unsigned corner = static_cast<unsigned>(trial) & 7u, own = detail::owner_position(corner);
      CellId<3> owner;
      owner.level = kLevel;
      Point<3> p = grid.vertex(v);
      for (unsigned a = 0; a < 3; ++a) {
        const unsigned ba = (own >> a) & 1u;
        owner.index[a] = (v[a] >> (kMaxLevel - kLevel)) - 1 + ba;
        p[a] += (ba ? 1 : -1) * step(rng) * 0x1p-6 * 0.5 / (1 << kLevel);
      }
      std::uint64_t mask = 0;
      for (unsigned k = 0; k < 64; ++k)
        if (bit(rng)) mask |= std::uint64_t{1} << k;
      std::vector<Tetrahedron> got, want;
      detail::tetrahedralize_block(grid, owner, corner, p, mask, got);
      for (unsigned b = 0; b < 8; ++b)
        for (unsigned axis = 0; axis < 3; ++axis) {
          const bool upper = ((b >> axis) & 1u) != 0;
          const auto nb = face_neighbours(axis, upper);
          unsigned assignment = 0;
          for (unsigned i = 0; i < 9; ++i) {
            int f[3];  // the block frame: the cell v − 2 + f
            for (unsigned a = 0; a < 3; ++a) f[a] = 1 + static_cast<int>((b >> a) & 1u) + nb[i][a];
            if ((mask >> detail::block_bit(f[0], f[1], f[2])) & 1u) assignment |= 1u << i;
          }
          for (const Triangle& t : face_triangles(block_cell_lo(b), axis, upper, assignment))
            want.push_back(canonical_tetrahedron(p, grid.vertex(t[0]), grid.vertex(t[1]), grid.vertex(t[2])));
        }
      std::sort(got.begin(), got.end());
      std::sort(want.begin(), want.end());
      ASSERT_EQ(got, want) << "mask " << mask << " corner " << corner;
    }
  }
}

TEST(OctreeMeshBound, EnumerationCounts) {
  const Family leaf = leaf_family(), block = block_family();
  EXPECT_EQ(leaf.assignments, 6u * 512);
  EXPECT_EQ(block.assignments, 24u * 512);
  EXPECT_EQ(leaf.triangles.size(), 6 * kTriangleKinds);
  EXPECT_EQ(block.triangles.size(), 24 * kTriangleKinds);
  EXPECT_EQ(all_templates().size(), kTemplates);
  RecordProperty("block_assignments", std::to_string(block.assignments));
  RecordProperty("block_triangles_emitted", std::to_string(block.emitted));
}

TEST(OctreeMeshBound, ProvesTheStatedBounds) {
  const auto start = std::chrono::steady_clock::now();
  const ProofStats stats = prove_all(AngleBounds(kOctreeMinDihedral, kOctreeMaxDihedral), kTemplateStride);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(stats.failed) << stats.failure;
  EXPECT_EQ(stats.templates, (kTemplates + kTemplateStride - 1) / kTemplateStride);
  std::cout << "[proof] every dihedral angle in [" << kOctreeMinDihedral << ", " << kOctreeMaxDihedral
            << "] degrees: " << stats.templates << " of " << kTemplates << " templates, " << stats.boxes
            << " boxes (" << stats.affine_boxes << " affine), deepest path " << stats.deepest << " bisections, "
            << seconds << " s; the accepted boxes bracket the angles in [" << stats.min_angle_deg() << ", "
            << stats.max_angle_deg() << "]\n";
  RecordProperty("certified_bracket_min_deg", std::to_string(stats.min_angle_deg()));
  RecordProperty("certified_bracket_max_deg", std::to_string(stats.max_angle_deg()));
}

TEST(OctreeMeshBound, RefusesFalseBounds) {
  // The sampled extremes (13.16°, 164.21°) violate these: the proof must fail on them.
  for (const AngleBounds& wrong : {AngleBounds(14.0, kOctreeMaxDihedral), AngleBounds(kOctreeMinDihedral, 160.0)}) {
    const ProofStats stats = prove_all(wrong, 1);
    EXPECT_TRUE(stats.failed) << "proved the false bounds [" << wrong.min_deg << ", " << wrong.max_deg << "]";
  }
}

TEST(OctreeMeshBound, SampledExtremes) {
  // Not a proof: the extremes the proof's bounds must contain, for the docs. The block's
  // extremes lie at the corners of the point region, which every lattice holds.
  const Sampled s = sample_extremes(test_support::kSanitized ? 1 : 4);
  std::cout << "[sampled] dihedral angles in [" << s.min << ", " << s.max << "] degrees; min at apex ("
            << s.min_apex[0] << ", " << s.min_apex[1] << ", " << s.min_apex[2] << "), max at apex ("
            << s.max_apex[0] << ", " << s.max_apex[1] << ", " << s.max_apex[2] << ") in units of s from v\n";
  RecordProperty("sampled_min_deg", std::to_string(s.min));
  RecordProperty("sampled_max_deg", std::to_string(s.max));
  EXPECT_GE(s.min, kOctreeMinDihedral);
  EXPECT_LE(s.max, kOctreeMaxDihedral);
}

}  // namespace
