// dynmesh/box.hpp — the domain box and exact point location.
//
// Purpose: the box [o, o+L)^d that the quadtree subdivides, the rule that derives it from the
// initial points (docs/FORMATS.md, "The domain box"), and the exact location rule of
// docs/DESIGN.md, "The quadtree contract":
//     q = floor((x − o) · (2^52 / L))   per coordinate, in IEEE double exactly as written:
//     one division 2^52 / L (a power of two over L), one subtraction, one multiplication,
//     one floor. A point is inside the box iff every q lies in [0, 2^52).
// Membership is decided by q alone: the rule, not the comparison x < o + L, defines the box.
// The lower end is exact (x − o has the exact sign, so q ≥ 0 iff x ≥ o); at the upper end
// rounding may put a coordinate at or within ulps of o + L on either side. The derived box's
// middle third holds the initial points with a wide margin, so this only matters for edits.
// This file must not be compiled with -ffast-math or -ffp-contract=fast semantics changing
// these expressions (GCC does not contract a subtraction followed by a multiplication).
//
// For messages about a spread beyond the resolution: spread_text() states L/s for a pair of
// points, and stretching_point() finds the point that, far from the rest, stretches a derived
// box (a stray 1e17 among terrain coordinates makes L so large that near points collide).
// Invariants: validate_box() accepts only boxes with finite origin, finite L > 0 and finite
// 2^52 / L; locate() on such a box returns q with every coordinate < 2^52.
// Complexity: derive_box and stretching_point O(n·d); locate and spread_text O(d).
// Paper: Acar & Hudson, Section 2 ("an initial bounding box of the point set, with side
// length L").
#pragma once

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>

#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh {

template <std::size_t d>
  requires SupportedDim<d>
struct Box {
  Point<d> origin{};  // o: the lower corner
  double side = 1.0;  // L: the side length

  /// 2^52 / L, the factor of the location rule (one IEEE division, as written).
  double scale() const noexcept { return 0x1p52 / side; }

  friend bool operator==(const Box&, const Box&) = default;
};

/// Throws InputError(OutsideBox) unless o is finite, L is finite and > 0, 2^52 / L is finite
/// and o + L is finite (so that every cell boundary is a finite number).
template <std::size_t d>
void validate_box(const Box<d>& box) {
  if (!(std::isfinite(box.side) && box.side > 0.0))
    throw InputError(InputError::Kind::OutsideBox,
                     "domain box side L must be finite and positive, got " + format_exact(box.side));
  if (!std::isfinite(box.scale()))
    throw InputError(InputError::Kind::OutsideBox,
                     "domain box side L is too small: 2^52 / L overflows (L = " +
                         format_exact(box.side) + ")");
  for (std::size_t a = 0; a < d; ++a) {
    if (!std::isfinite(box.origin[a]) || !std::isfinite(box.origin[a] + box.side))
      throw InputError(InputError::Kind::OutsideBox,
                       "domain box origin must be finite and o + L must be finite");
  }
}

/// docs/FORMATS.md, "The domain box", in IEEE double exactly as written:
///   w = max over axes of (max − min); if w == 0 then w = 1;
///   o_axis = (min + max) / 2 − 1.5 · w;  L = 3 · w.
/// Throws InputError(Empty) on no points, InputError(NotFinite) on a NaN or infinite
/// coordinate, and InputError(OutsideBox) when the resulting box is unusable (coordinates so
/// large that min + max or 3·w overflow, or w so small that 2^52 / L overflows).
template <std::size_t d>
Box<d> derive_box(std::span<const Point<d>> points) {
  if (points.empty())
    throw InputError(InputError::Kind::Empty, "cannot derive the domain box from an empty point set");
  Point<d> lo = points[0], hi = points[0];
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t a = 0; a < d; ++a) {
      const double x = points[i][a];
      if (!std::isfinite(x))
        throw InputError(InputError::Kind::NotFinite,
                         "point " + std::to_string(i) + " has a NaN or infinite coordinate");
      if (x < lo[a]) lo[a] = x;
      if (x > hi[a]) hi[a] = x;
    }
  }
  double w = 0.0;
  for (std::size_t a = 0; a < d; ++a) {
    const double extent = hi[a] - lo[a];
    if (extent > w) w = extent;
  }
  if (w == 0.0) w = 1.0;
  Box<d> box;
  for (std::size_t a = 0; a < d; ++a) box.origin[a] = (lo[a] + hi[a]) / 2 - 1.5 * w;
  box.side = 3 * w;
  validate_box(box);
  return box;
}

/// The point whose removal shrinks the box derive_box() gives the most, and the side L that
/// box would have without it. Only a point extreme on some axis can shrink it, so each
/// axis' two lowest and two highest coordinates decide. std::nullopt for fewer than three
/// points. Coordinates must be finite.
struct BoxStretch {
  std::size_t index = 0;    // into the points
  double side_without = 0;  // L of the box derived from the other points
};
template <std::size_t d>
std::optional<BoxStretch> stretching_point(std::span<const Point<d>> points) {
  if (points.size() < 3) return std::nullopt;
  constexpr double inf = std::numeric_limits<double>::infinity();
  struct End {
    double value[2] = {inf, inf};  // the best two (lowest of x, or of −x for the high end)
    std::size_t index = 0;         // of value[0]
    void add(double x, std::size_t i) {
      if (x < value[0]) {
        value[1] = value[0];
        value[0] = x;
        index = i;
      } else if (x < value[1]) {
        value[1] = x;
      }
    }
  };
  End lo[d], hi[d];
  for (std::size_t i = 0; i < points.size(); ++i)
    for (std::size_t a = 0; a < d; ++a) {
      lo[a].add(points[i][a], i);
      hi[a].add(-points[i][a], i);
    }
  std::optional<BoxStretch> best;
  for (std::size_t a = 0; a < d; ++a)
    for (const std::size_t c : {lo[a].index, hi[a].index}) {
      double w = 0.0;
      for (std::size_t b = 0; b < d; ++b)
        w = std::fmax(w, -hi[b].value[hi[b].index == c] - lo[b].value[lo[b].index == c]);
      const double side = 3 * (w == 0.0 ? 1.0 : w);  // as derive_box
      if (!best || side < best->side_without) best = BoxStretch{c, side};
    }
  return best;
}

/// "spread L/s = 3.33e+15 (log2 51.6) with L = 3 and s = 9e-16" for two points of the box at
/// Euclidean distance s (log2 computed as log2 L − log2 s, so neither overflows), for
/// messages about a spread beyond the resolution.
template <std::size_t d>
std::string spread_text(const Box<d>& box, const Point<d>& p, const Point<d>& q) {
  double m = 0.0, sum = 0.0;  // s = m·sqrt(sum), scaled so that no square under- or overflows
  for (std::size_t a = 0; a < d; ++a) m = std::fmax(m, std::fabs(p[a] - q[a]));
  for (std::size_t a = 0; a < d && m > 0.0; ++a) sum += ((p[a] - q[a]) / m) * ((p[a] - q[a]) / m);
  const double lg = m > 0.0 ? std::log2(box.side) - std::log2(m) - 0.5 * std::log2(sum)
                            : std::numeric_limits<double>::infinity();
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, lg, std::chars_format::fixed, 1);
  return "spread L/s = " + format_brief(std::exp2(lg), 3) + " (log2 " + std::string(buf, r.ptr) +
         ") with L = " + format_brief(box.side) + " and s = " + format_brief(m * std::sqrt(sum));
}

/// The location rule. Returns std::nullopt when the point is outside the box (some q outside
/// [0, 2^52), including NaN coordinates). The box must satisfy validate_box().
template <std::size_t d>
std::optional<Position<d>> try_locate(const Box<d>& box, const Point<d>& x) noexcept {
  const double s = box.scale();
  Position<d> q{};
  for (std::size_t a = 0; a < d; ++a) {
    const double t = (x[a] - box.origin[a]) * s;
    const double f = std::floor(t);
    if (!(f >= 0.0 && f < 0x1p52)) return std::nullopt;
    q[a] = static_cast<std::uint64_t>(f);
  }
  return q;
}

/// The location rule; throws InputError(NotFinite) for a NaN or infinite coordinate and
/// InputError(OutsideBox) for a point outside the box. `file`/`line` go into the message.
template <std::size_t d>
Position<d> locate(const Box<d>& box, const Point<d>& x, const std::string& file = {},
                   std::size_t line = 0) {
  for (std::size_t a = 0; a < d; ++a)
    if (!std::isfinite(x[a]))
      throw InputError(InputError::Kind::NotFinite, "NaN or infinite coordinate", file, line);
  if (auto q = try_locate(box, x)) return *q;
  throw InputError(InputError::Kind::OutsideBox, "point is outside the domain box", file, line);
}

}  // namespace dynmesh
