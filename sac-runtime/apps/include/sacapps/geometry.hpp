// sacapps/geometry.hpp — points and the predicates of quickhull and diameter.
//
// Purpose: one definition of every geometric formula, shared by the self-adjusting programs
// and their conventional twins, so that both make the same floating-point decisions and their
// results compare exactly. The predicates are the plain floating-point formulas (not exact
// arithmetic): near-degenerate inputs may get a slightly wrong hull, but both twins get the
// same one.
// Invariants: a Site is a point with the id of the list element it came from; all orders
// are strict total orders on Sites (ties broken by id), so "the lowest" or "the farthest" of
// a set does not depend on the order in which the set is scanned or combined.
// Complexity: O(1) each.
// Follows the quickhull and diameter benchmarks of Acar, Blelloch, Blume, Harper,
// Tangwongsan (TOPLAS 2009) and Hammer, Acar, Chen, "CEAL" (PLDI 2009).
#pragma once

#include <cstdint>

#include <sac/sac.hpp>

namespace sacapps {

struct Point {
  double x = 0;
  double y = 0;
  friend bool operator==(const Point&, const Point&) = default;
};

/// A point and the id of its list element: what the hull computations pass around.
struct Site {
  static constexpr std::uint64_t kNone = ~std::uint64_t{0};
  Point p;
  std::uint64_t id = kNone;

  bool valid() const { return id != kNone; }
  friend bool operator==(const Site&, const Site&) = default;
  std::size_t hash() const {
    return sac::hash_combine(sac::Hash<std::uint64_t>{}(id),
                             sac::hash_combine(sac::Hash<double>{}(p.x), sac::Hash<double>{}(p.y)));
  }
};

namespace geom {

/// Twice the signed area of (a, b, p): > 0 when p is left of the directed line a->b.
inline double cross(const Point& a, const Point& b, const Point& p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

/// The projection of p - a on b - a (unnormalised).
inline double along(const Point& a, const Point& b, const Point& p) {
  return (p.x - a.x) * (b.x - a.x) + (p.y - a.y) * (b.y - a.y);
}

inline double dist2(const Point& a, const Point& b) {
  const double dx = a.x - b.x;
  const double dy = a.y - b.y;
  return dx * dx + dy * dy;
}

/// Strictly right of the directed line a->b (points on the line are not).
inline bool right_of(const Site& a, const Site& b, const Point& p) {
  return cross(a.p, b.p, p) < 0;
}

/// The orders of the extreme points: s is lower (higher) than t by y, then x; among equal
/// points the smaller id wins both, so duplicates of an extreme point count once.
inline bool lower(const Site& s, const Site& t) {
  if (s.p.y != t.p.y) return s.p.y < t.p.y;
  if (s.p.x != t.p.x) return s.p.x < t.p.x;
  return s.id < t.id;
}
inline bool higher(const Site& s, const Site& t) {
  if (s.p.y != t.p.y) return s.p.y > t.p.y;
  if (s.p.x != t.p.x) return s.p.x > t.p.x;
  return s.id < t.id;
}

/// s is farther right of a->b than t. Ties (equal distance: both on a parallel to a->b) go to
/// the one nearer b, which is a hull vertex; then to the smaller id (duplicate points).
inline bool farther(const Site& a, const Site& b, const Site& s, const Site& t) {
  const double cs = cross(a.p, b.p, s.p);
  const double ct = cross(a.p, b.p, t.p);
  if (cs != ct) return cs < ct;
  const double ps = along(a.p, b.p, s.p);
  const double pt = along(a.p, b.p, t.p);
  if (ps != pt) return ps > pt;
  return s.id < t.id;
}

}  // namespace geom
}  // namespace sacapps
