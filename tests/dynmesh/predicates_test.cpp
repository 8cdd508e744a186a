// predicates_test.cpp — orient2d, incircle, pencil and orient3d (predicates.hpp) against exact
// GMP arithmetic.
//
// Purpose: every case is decided twice, by dynmesh's predicates and by an exact evaluation of
// the same determinant in GMP integers, and the two signs must agree on every case. Three
// families of input, each from fixed seeds (printed through SCOPED_TRACE):
//   random            – 10^6 cases per predicate (fewer in slow builds), from four mixes:
//                       uniform, a small integer grid, wide exponents, tight clusters;
//   nearly degenerate – a few ulps (std::nextafter) off collinear, cocircular and coplanar
//                       inputs, including the 256×256 orient2d grid of Kettner et al. and
//                       its orient3d analogue on a plane;
//   exactly degenerate – lattice points on x²+y²=r², collinear and coplanar lattices, scaled by
//                       powers of two up to 2^±1000, the same rounded by decimal scales
//                       (1e15 … 1e300, 1e-300, subnormal), and mixed magnitudes up to
//                       DBL_MAX.
// Invariants checked: each predicate returns exactly the exact sign (−1, 0, +1) on every case;
// the GMP reference returns the hand-computed signs and 0 on constructed degeneracies; a naive
// double evaluation is caught disagreeing on the nearly degenerate sets, so the harness can
// fail.
// Complexity: O(cases); the GMP reference dominates (well under a microsecond per case).
// Paper: Shewchuk, "Adaptive precision floating-point arithmetic and fast robust geometric
// predicates" (1997) for the determinants; Kettner, Mehlhorn, Pion, Schirra, Yap, "Classroom
// examples of robustness problems in geometric computations" (2008) for the orient2d grid.
// The reference uses that a finite double is m·2^e with an integer m: scaling all inputs of a
// case by one power of two makes them integers exactly, and both determinants are
// homogeneous, so the scale leaves their signs unchanged.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cfenv>
#include <climits>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "../sanitized.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/predicates.hpp"

namespace {

using dynmesh::Point;

/// Sanitizers (CI runs them at -O0) or no optimization: the random families shrink.
#ifdef __OPTIMIZE__
constexpr bool kSlowBuild = test_support::kSanitized;
#else
constexpr bool kSlowBuild = true;
#endif
constexpr std::size_t kRandomCases = kSlowBuild ? 50'000 : 1'000'000;

struct OrientCase {
  Point<2> a, b, c;
};
struct IncircleCase {
  Point<2> a, b, c, d;
};
struct Orient3dCase {
  Point<3> a, b, c, d;
};

std::string describe(const OrientCase& k) {
  return "orient2d" + dynmesh::to_string<2>(k.a) + dynmesh::to_string<2>(k.b) +
         dynmesh::to_string<2>(k.c);
}
std::string describe(const IncircleCase& k) {
  return "incircle" + dynmesh::to_string<2>(k.a) + dynmesh::to_string<2>(k.b) +
         dynmesh::to_string<2>(k.c) + dynmesh::to_string<2>(k.d);
}
std::string describe(const Orient3dCase& k) {
  return "orient3d" + dynmesh::to_string<3>(k.a) + dynmesh::to_string<3>(k.b) +
         dynmesh::to_string<3>(k.c) + dynmesh::to_string<3>(k.d);
}

// --- the exact reference ------------------------------------------------------------------

/// Exact signs of the three determinants in GMP integers. Members are reused scratch space, so
/// evaluation allocates only when a case needs more limbs than the previous ones.
class ExactSign {
 public:
  int orient2d(const OrientCase& k) {
    load(std::array{k.a[0], k.a[1], k.b[0], k.b[1], k.c[0], k.c[1]});
    // det [[bx − ax, by − ay], [cx − ax, cy − ay]]
    bx_ = v_[2] - v_[0];
    by_ = v_[3] - v_[1];
    cx_ = v_[4] - v_[0];
    cy_ = v_[5] - v_[1];
    t1_ = bx_ * cy_;
    t2_ = by_ * cx_;
    det_ = t1_ - t2_;
    return sgn(det_);
  }

  int incircle(const IncircleCase& k) {
    load(std::array{k.a[0], k.a[1], k.b[0], k.b[1], k.c[0], k.c[1], k.d[0], k.d[1]});
    // Translated so that d is the origin: det [[ax, ay, ax²+ay²], [bx, …], [cx, …]], expanded
    // along the lift column. Positive when d is inside the circle of ccw a, b, c.
    ax_ = v_[0] - v_[6];
    ay_ = v_[1] - v_[7];
    bx_ = v_[2] - v_[6];
    by_ = v_[3] - v_[7];
    cx_ = v_[4] - v_[6];
    cy_ = v_[5] - v_[7];
    det_ = 0;
    add_lift_times_minor(ax_, ay_, bx_, by_, cx_, cy_);  // alift · (bx·cy − cx·by)
    add_lift_times_minor(bx_, by_, cx_, cy_, ax_, ay_);  // blift · (cx·ay − ax·cy)
    add_lift_times_minor(cx_, cy_, ax_, ay_, bx_, by_);  // clift · (ax·by − bx·ay)
    return sgn(det_);
  }

  int orient3d(const Orient3dCase& k) {
    load(std::array{k.a[0], k.a[1], k.a[2], k.b[0], k.b[1], k.b[2], k.c[0], k.c[1], k.c[2], k.d[0], k.d[1],
                    k.d[2]});
    // det [b − a, c − a, d − a], expanded along b − a = (bx, by, bz); c − a and d − a are
    // (cx, cy, cz) and (ax, ay, az) here, reusing the 2D scratch names.
    bx_ = v_[3] - v_[0];
    by_ = v_[4] - v_[1];
    bz_ = v_[5] - v_[2];
    cx_ = v_[6] - v_[0];
    cy_ = v_[7] - v_[1];
    cz_ = v_[8] - v_[2];
    ax_ = v_[9] - v_[0];
    ay_ = v_[10] - v_[1];
    az_ = v_[11] - v_[2];
    det_ = bx_ * (cy_ * az_ - cz_ * ay_);
    minor_ = cx_ * az_ - cz_ * ax_;
    det_ -= by_ * minor_;
    minor_ = cx_ * ay_ - cy_ * ax_;
    det_ += bz_ * minor_;
    return sgn(det_);
  }

 private:
  static int sgn(const mpz_class& z) { return (z > 0) - (z < 0); }

  /// v_[i] = xs[i] · 2^−low for the smallest exponent `low` of the case's nonzero inputs.
  template <std::size_t n>
  void load(const std::array<double, n>& xs) {
    int low = INT_MAX;
    for (double x : xs) {
      if (x == 0) continue;
      int e = 0;
      std::frexp(x, &e);
      low = std::min(low, e - 53);
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (xs[i] == 0) {
        v_[i] = 0;
        continue;
      }
      int e = 0;
      const double mantissa = std::ldexp(std::frexp(xs[i], &e), 53);  // an integer, |m| < 2^53
      v_[i] = mantissa;                                                // exact: mpz_set_d
      mpz_mul_2exp(v_[i].get_mpz_t(), v_[i].get_mpz_t(), static_cast<mp_bitcnt_t>(e - 53 - low));
    }
  }

  /// det_ += (px² + py²) · (qx·ry − rx·qy)
  void add_lift_times_minor(const mpz_class& px, const mpz_class& py, const mpz_class& qx,
                            const mpz_class& qy, const mpz_class& rx, const mpz_class& ry) {
    t1_ = px * px;
    t2_ = py * py;
    lift_ = t1_ + t2_;
    t1_ = qx * ry;
    t2_ = rx * qy;
    minor_ = t1_ - t2_;
    t1_ = lift_ * minor_;
    det_ += t1_;
  }

  std::array<mpz_class, 12> v_;
  mpz_class ax_, ay_, az_, bx_, by_, bz_, cx_, cy_, cz_, t1_, t2_, lift_, minor_, det_;
};

// --- tallies ------------------------------------------------------------------------------

/// Agreement of a predicate with the reference over a family of cases.
struct Tally {
  std::size_t cases = 0;
  std::size_t mismatches = 0;
  std::size_t exact_zeros = 0;  // cases whose exact sign is 0: how degenerate the family is
  std::string first_mismatch;

  template <class Case>
  void record(const Case& k, int got, int want) {
    ++cases;
    if (want == 0) ++exact_zeros;
    if (got == want) return;
    if (mismatches++ == 0)
      first_mismatch = describe(k) + ": got " + std::to_string(got) + ", exact " + std::to_string(want);
  }
};

using OrientFn = int (*)(const Point<2>&, const Point<2>&, const Point<2>&);
using IncircleFn = int (*)(const Point<2>&, const Point<2>&, const Point<2>&, const Point<2>&);
using Orient3dFn = int (*)(const Point<3>&, const Point<3>&, const Point<3>&, const Point<3>&);

Tally check(std::span<const OrientCase> cases, OrientFn fn = dynmesh::orient2d) {
  ExactSign exact;
  Tally t;
  for (const auto& k : cases) t.record(k, fn(k.a, k.b, k.c), exact.orient2d(k));
  return t;
}

Tally check(std::span<const IncircleCase> cases, IncircleFn fn = dynmesh::incircle) {
  ExactSign exact;
  Tally t;
  for (const auto& k : cases) t.record(k, fn(k.a, k.b, k.c, k.d), exact.incircle(k));
  return t;
}

Tally check(std::span<const Orient3dCase> cases, Orient3dFn fn = dynmesh::orient3d) {
  ExactSign exact;
  Tally t;
  for (const auto& k : cases) t.record(k, fn(k.a, k.b, k.c, k.d), exact.orient3d(k));
  return t;
}

#define EXPECT_AGREES(tally) \
  EXPECT_EQ((tally).mismatches, 0u) << "of " << (tally).cases << "; first: " << (tally).first_mismatch

// The textbook double-precision determinants, to show the harness catches a non-robust one.
int naive_orient2d(const Point<2>& a, const Point<2>& b, const Point<2>& c) {
  const double det = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  return (det > 0) - (det < 0);
}
int naive_incircle(const Point<2>& a, const Point<2>& b, const Point<2>& c, const Point<2>& d) {
  const double adx = a[0] - d[0], ady = a[1] - d[1], bdx = b[0] - d[0], bdy = b[1] - d[1];
  const double cdx = c[0] - d[0], cdy = c[1] - d[1];
  const double det = (adx * adx + ady * ady) * (bdx * cdy - cdx * bdy) +
                     (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy) +
                     (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady);
  return (det > 0) - (det < 0);
}
int naive_orient3d(const Point<3>& a, const Point<3>& b, const Point<3>& c, const Point<3>& d) {
  const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2], vx = c[0] - a[0], vy = c[1] - a[1],
               vz = c[2] - a[2], wx = d[0] - a[0], wy = d[1] - a[1], wz = d[2] - a[2];
  const double det = ux * (vy * wz - vz * wy) - uy * (vx * wz - vz * wx) + uz * (vx * wy - vy * wx);
  return (det > 0) - (det < 0);
}

// --- generators ---------------------------------------------------------------------------

/// x moved by k representable doubles (k < 0: downwards).
double ulps(double x, int k) {
  for (; k > 0; --k) x = std::nextafter(x, std::numeric_limits<double>::infinity());
  for (; k < 0; ++k) x = std::nextafter(x, -std::numeric_limits<double>::infinity());
  return x;
}
Point<2> ulps(const Point<2>& p, int kx, int ky) { return {ulps(p[0], kx), ulps(p[1], ky)}; }
Point<3> ulps(const Point<3>& p, int kx, int ky, int kz) { return {ulps(p[0], kx), ulps(p[1], ky), ulps(p[2], kz)}; }

template <std::size_t d>
Point<d> scaled(const Point<d>& p, double s) {
  Point<d> out;
  for (std::size_t a = 0; a < d; ++a) out[a] = p[a] * s;
  return out;
}

/// Random points from one of four mixes, picked per case: uniform in [−1, 1]^d; integers in
/// [−4, 4] (many exact zeros); sign·[1, 2)·2^[−30, 30] per coordinate; a cluster of width
/// 1e-9 around a center in [−1e6, 1e6]^d (coordinates a few ulps apart). Coordinates are
/// drawn in axis order, so the 2D sequences do not depend on the 3D use.
template <std::size_t d = 2>
class RandomPoints {
 public:
  explicit RandomPoints(std::uint64_t seed) : rng_(seed) {}

  int next_mix() { return static_cast<int>(rng_() % 4); }

  Point<d> point(int mix) {
    Point<d> p;
    for (std::size_t a = 0; a < d; ++a) {
      switch (mix) {
        case 0: p[a] = unit_(rng_); break;
        case 1: p[a] = static_cast<double>(small_(rng_)); break;
        case 2: p[a] = wide(); break;
        default: p[a] = center_[a] + 1e-9 * unit_(rng_); break;
      }
    }
    return p;
  }

  /// A fresh cluster center (mix 3) for the next case.
  void recenter() {
    for (std::size_t a = 0; a < d; ++a) center_[a] = 1e6 * unit_(rng_);
  }

 private:
  double wide() {
    const double m = 1.0 + 0.5 * (unit_(rng_) + 1.0);
    const double s = (rng_() & 1) ? -1.0 : 1.0;
    return s * std::ldexp(m, exponent_(rng_));
  }

  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> unit_{-1.0, 1.0};
  std::uniform_int_distribution<int> small_{-4, 4};
  std::uniform_int_distribution<int> exponent_{-30, 30};
  Point<d> center_{};
};

/// The integer points of the circle x² + y² = r², sorted by angle (counter-clockwise).
std::vector<Point<2>> lattice_circle(std::int64_t r) {
  std::vector<std::array<std::int64_t, 2>> pts;
  for (std::int64_t x = -r; x <= r; ++x) {
    const auto y = static_cast<std::int64_t>(std::llround(std::sqrt(static_cast<double>(r * r - x * x))));
    if (x * x + y * y != r * r) continue;
    pts.push_back({x, y});
    if (y != 0) pts.push_back({x, -y});
  }
  std::sort(pts.begin(), pts.end(), [](const auto& p, const auto& q) {
    return std::atan2(static_cast<double>(p[1]), static_cast<double>(p[0])) <
           std::atan2(static_cast<double>(q[1]), static_cast<double>(q[0]));
  });
  std::vector<Point<2>> out;
  for (const auto& p : pts) out.push_back({static_cast<double>(p[0]), static_cast<double>(p[1])});
  return out;
}

std::string seed_trace(std::uint64_t seed) { return "seed " + std::to_string(seed); }

// --- conventions: hand-computed signs -----------------------------------------------------

TEST(Predicates, OrientationConvention) {
  const Point<2> o{0, 0}, x{1, 0}, y{0, 1};
  EXPECT_EQ(dynmesh::orient2d(o, x, y), 1);
  EXPECT_EQ(dynmesh::orient2d(o, y, x), -1);
  EXPECT_EQ(dynmesh::orient2d(o, x, Point<2>{2, 0}), 0);
  EXPECT_EQ(dynmesh::orient2d(o, o, y), 0);
}

TEST(Predicates, IncircleConvention) {
  const Point<2> a{1, 0}, b{0, 1}, c{-1, 0};  // ccw on the unit circle
  EXPECT_EQ(dynmesh::incircle(a, b, c, Point<2>{0, 0}), 1);
  EXPECT_EQ(dynmesh::incircle(a, b, c, Point<2>{2, 0}), -1);
  EXPECT_EQ(dynmesh::incircle(a, b, c, Point<2>{0, -1}), 0);
  EXPECT_EQ(dynmesh::incircle(b, a, c, Point<2>{0, 0}), -1);  // clockwise flips the sign
  EXPECT_EQ(dynmesh::incircle(a, a, c, Point<2>{0, 0}), 0);   // repeated point
  // Collinear a, b, c: left of a→c counts as inside (the limit of ccw circles).
  EXPECT_EQ(dynmesh::incircle(Point<2>{0, 0}, Point<2>{1, 0}, Point<2>{2, 0}, Point<2>{0, 1}), 1);
}

TEST(Predicates, ReferenceMatchesHandComputedSigns) {
  ExactSign exact;
  EXPECT_EQ(exact.orient2d({{0, 0}, {1, 0}, {0, 1}}), 1);
  EXPECT_EQ(exact.orient2d({{0, 0}, {0, 1}, {1, 0}}), -1);
  EXPECT_EQ(exact.orient2d({{0.5, 0.5}, {12, 12}, {24, 24}}), 0);
  // b − a points up; c lies left of that line by about 1e-300.
  EXPECT_EQ(exact.orient2d({{1e-300, 0}, {0, 1e300}, {5e-324, 5e-324}}), 1);
  EXPECT_EQ(exact.incircle({{1, 0}, {0, 1}, {-1, 0}, {0, 0}}), 1);
  EXPECT_EQ(exact.incircle({{1, 0}, {0, 1}, {-1, 0}, {2, 0}}), -1);
  EXPECT_EQ(exact.incircle({{1, 0}, {0, 1}, {-1, 0}, {0, -1}}), 0);
  EXPECT_EQ(exact.incircle({{0, 1}, {1, 0}, {-1, 0}, {0, 0}}), -1);
  // Collinear a, b, c: the limit of a ccw circle, the half-plane left of a→c, is "inside".
  EXPECT_EQ(exact.incircle({{0, 0}, {1, 0}, {2, 0}, {0, 1}}), 1);
  EXPECT_EQ(exact.incircle({{0, 0}, {1, 0}, {2, 0}, {0, -1}}), -1);
  EXPECT_EQ(exact.incircle({{0, 0}, {1, 0}, {2, 0}, {5, 0}}), 0);
}

// --- random -------------------------------------------------------------------------------

TEST(Predicates, Orient2dRandomAgreesWithGmp) {
  constexpr std::uint64_t kSeed = 20240611;
  SCOPED_TRACE(seed_trace(kSeed) + ", cases " + std::to_string(kRandomCases));
  RandomPoints gen(kSeed);
  ExactSign exact;
  Tally t;
  for (std::size_t i = 0; i < kRandomCases; ++i) {
    const int mix = gen.next_mix();
    gen.recenter();
    const OrientCase k{gen.point(mix), gen.point(mix), gen.point(mix)};
    t.record(k, dynmesh::orient2d(k.a, k.b, k.c), exact.orient2d(k));
  }
  EXPECT_AGREES(t);
  EXPECT_GT(t.exact_zeros, 0u);  // the integer mix does reach the exact path
}

TEST(Predicates, IncircleRandomAgreesWithGmp) {
  constexpr std::uint64_t kSeed = 20240612;
  SCOPED_TRACE(seed_trace(kSeed) + ", cases " + std::to_string(kRandomCases));
  RandomPoints gen(kSeed);
  ExactSign exact;
  Tally t;
  for (std::size_t i = 0; i < kRandomCases; ++i) {
    const int mix = gen.next_mix();
    gen.recenter();
    const IncircleCase k{gen.point(mix), gen.point(mix), gen.point(mix), gen.point(mix)};
    t.record(k, dynmesh::incircle(k.a, k.b, k.c, k.d), exact.incircle(k));
  }
  EXPECT_AGREES(t);
  EXPECT_GT(t.exact_zeros, 0u);
}

// --- nearly degenerate --------------------------------------------------------------------

/// Kettner et al.'s grid: p = (0.5 + i·2^-53, 0.5 + j·2^-53), i, j < 256, against q = (12, 12),
/// r = (24, 24), all three cyclic rotations. Naive evaluation gets large parts of it wrong.
std::vector<OrientCase> kettner_grid() {
  std::vector<OrientCase> cases;
  const double u = std::ldexp(1.0, -53);
  const Point<2> q{12, 12}, r{24, 24};
  for (int i = 0; i < 256; ++i)
    for (int j = 0; j < 256; ++j) {
      const Point<2> p{0.5 + i * u, 0.5 + j * u};
      cases.push_back({p, q, r});
      cases.push_back({q, r, p});
      cases.push_back({r, p, q});
    }
  return cases;
}

/// c on the segment line through random a, b (rounded), then moved by up to 2 ulps per axis,
/// at scales from 1e-200 to 1e300.
std::vector<OrientCase> near_collinear(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), along(-1.0, 2.0);
  std::uniform_int_distribution<int> nudge(-2, 2);
  std::vector<OrientCase> cases;
  for (double s : {1.0, 0x1p40, 0x1p-40, 1e200, 1e-200, 1e300}) {
    for (int i = 0; i < 5000; ++i) {
      const Point<2> a{s * unit(rng), s * unit(rng)}, b{s * unit(rng), s * unit(rng)};
      const double t = along(rng);
      const Point<2> c{a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
      cases.push_back({a, b, ulps(c, nudge(rng), nudge(rng))});
    }
  }
  return cases;
}

/// Exactly cocircular lattice quadruples (r = 5) around several dyadic centers and power-of-
/// two scales, with d (then a) moved by up to 10 ulps per axis.
std::vector<IncircleCase> perturbed_lattice_circles() {
  const auto circle = lattice_circle(5);  // 12 points, ccw
  std::vector<IncircleCase> cases;
  for (const Point<2> center : {Point<2>{0, 0}, Point<2>{1000.25, -333.5}, Point<2>{0x1p30 + 0.5, 3}})
    for (double s : {1.0, 0x1p-520, 0x1p500}) {
      auto at = [&](std::size_t i) { return scaled(Point<2>{center[0] + circle[i][0], center[1] + circle[i][1]}, s); };
      const Point<2> a = at(0), b = at(2), c = at(5), d = at(8);
      for (int i = -10; i <= 10; ++i)
        for (int j = -10; j <= 10; ++j) {
          cases.push_back({a, b, c, ulps(d, i, j)});
          cases.push_back({ulps(a, i, j), b, c, d});
        }
    }
  return cases;
}

/// Four rounded points of a random circle (ccw by angle), d moved by up to 2 ulps per axis, at
/// scales from 1e-300 to 1e150.
std::vector<IncircleCase> near_cocircular(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), radius(0.1, 1.0), angle(0.0, 6.283185307179586);
  std::uniform_int_distribution<int> nudge(-2, 2);
  std::vector<IncircleCase> cases;
  for (double s : {1.0, 0x1p30, 0x1p-30, 1e150, 1e-150, 1e-300}) {
    for (int i = 0; i < 5000; ++i) {
      const Point<2> o{s * unit(rng), s * unit(rng)};
      const double r = s * radius(rng);
      std::array<double, 4> th{angle(rng), angle(rng), angle(rng), angle(rng)};
      std::sort(th.begin(), th.end());
      auto on = [&](double t) { return Point<2>{o[0] + r * std::cos(t), o[1] + r * std::sin(t)}; };
      cases.push_back({on(th[0]), on(th[1]), on(th[2]), ulps(on(th[3]), nudge(rng), nudge(rng))});
    }
  }
  return cases;
}

TEST(Predicates, Orient2dNearlyDegenerateAgreesWithGmp) {
  const Tally grid = check(kettner_grid());
  EXPECT_AGREES(grid);
  EXPECT_GT(grid.exact_zeros, 0u);
  constexpr std::uint64_t kSeed = 7001;
  SCOPED_TRACE(seed_trace(kSeed));
  const Tally random = check(near_collinear(kSeed));
  EXPECT_AGREES(random);
}

TEST(Predicates, IncircleNearlyDegenerateAgreesWithGmp) {
  const Tally lattice = check(perturbed_lattice_circles());
  EXPECT_AGREES(lattice);
  EXPECT_GT(lattice.exact_zeros, 0u);
  constexpr std::uint64_t kSeed = 7002;
  SCOPED_TRACE(seed_trace(kSeed));
  const Tally random = check(near_cocircular(kSeed));
  EXPECT_AGREES(random);
}

/// The harness can fail: the naive double determinants disagree with GMP on these families.
TEST(Predicates, NaiveDoubleEvaluationIsCaught) {
  EXPECT_GT(check(kettner_grid(), naive_orient2d).mismatches, 0u);
  EXPECT_GT(check(near_collinear(7001), naive_orient2d).mismatches, 0u);
  EXPECT_GT(check(perturbed_lattice_circles(), naive_incircle).mismatches, 0u);
  EXPECT_GT(check(near_cocircular(7002), naive_incircle).mismatches, 0u);
}

// --- exactly degenerate -------------------------------------------------------------------

/// Scales that keep lattice coordinates (< 2^21) exact, down to subnormal-free 2^-1000 and up
/// to 2^1000.
constexpr std::array<double, 5> kExactScales{1.0, 0x1p-1000, 0x1p-500, 0x1p500, 0x1p1000};
/// Scales that round the same lattices: the degeneracy is lost, the exact answer still counts.
constexpr std::array<double, 7> kRoundingScales{1e15, 1e100, 1e300, 1e-300, 1e-310, 0.1, 3e-5};

/// Random quadruples of the 108 lattice points of x² + y² = 1105², translated by an integer
/// center in [−10^6, 10^6]² and scaled by s. Repeated points are allowed.
std::vector<IncircleCase> lattice_quadruples(std::uint64_t seed, double s, int n) {
  static const auto circle = lattice_circle(1105);
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, circle.size() - 1);
  std::uniform_int_distribution<int> shift(-1'000'000, 1'000'000);
  std::vector<IncircleCase> cases;
  for (int i = 0; i < n; ++i) {
    const Point<2> o{static_cast<double>(shift(rng)), static_cast<double>(shift(rng))};
    auto at = [&] {
      const Point<2>& p = circle[pick(rng)];
      return scaled(Point<2>{o[0] + p[0], o[1] + p[1]}, s);
    };
    cases.push_back({at(), at(), at(), at()});
  }
  return cases;
}

/// Triples of o + k·v, k ∈ [−100, 100], for a random integer o ∈ [−10^6, 10^6]² and direction
/// v ∈ [−1000, 1000]², scaled by s.
std::vector<OrientCase> collinear_triples(std::uint64_t seed, double s, int n) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> shift(-1'000'000, 1'000'000), dir(-1000, 1000), step(-100, 100);
  std::vector<OrientCase> cases;
  for (int i = 0; i < n; ++i) {
    const Point<2> o{static_cast<double>(shift(rng)), static_cast<double>(shift(rng))};
    const Point<2> v{static_cast<double>(dir(rng)), static_cast<double>(dir(rng))};
    auto at = [&] {
      const double k = step(rng);
      return scaled(Point<2>{o[0] + k * v[0], o[1] + k * v[1]}, s);
    };
    cases.push_back({at(), at(), at()});
  }
  return cases;
}

TEST(Predicates, Orient2dExactlyDegenerateAgreesWithGmp) {
  constexpr std::uint64_t kSeed = 9001;
  SCOPED_TRACE(seed_trace(kSeed));
  for (double s : kExactScales) {
    SCOPED_TRACE("exact scale " + dynmesh::format_exact(s));
    const Tally t = check(collinear_triples(kSeed, s, 2000));
    EXPECT_AGREES(t);
    EXPECT_EQ(t.exact_zeros, t.cases);  // the reference sees the construction
  }
  for (double s : kRoundingScales) {
    SCOPED_TRACE("rounding scale " + dynmesh::format_exact(s));
    EXPECT_AGREES(check(collinear_triples(kSeed, s, 2000)));
  }
  // Decimal steps along a line are not collinear once rounded.
  std::vector<OrientCase> decimal;
  for (int i = 1; i < 60; ++i)
    for (int j = i + 1; j < 60; j += 3)
      decimal.push_back({{0.1 * i, 0.3 * i}, {0.1 * j, 0.3 * j}, {0.1 * (i + j), 0.3 * (i + j)}});
  EXPECT_AGREES(check(decimal));
}

TEST(Predicates, IncircleExactlyDegenerateAgreesWithGmp) {
  constexpr std::uint64_t kSeed = 9002;
  SCOPED_TRACE(seed_trace(kSeed));
  for (double s : kExactScales) {
    SCOPED_TRACE("exact scale " + dynmesh::format_exact(s));
    const Tally t = check(lattice_quadruples(kSeed, s, 2000));
    EXPECT_AGREES(t);
    EXPECT_EQ(t.exact_zeros, t.cases);
  }
  for (double s : kRoundingScales) {
    SCOPED_TRACE("rounding scale " + dynmesh::format_exact(s));
    EXPECT_AGREES(check(lattice_quadruples(kSeed, s, 2000)));
  }
  // Collinear a, b, c: the degenerate lifted determinant, with d off the line (a point of
  // another line) or on it (a + 2·(b − a), exact on these integers).
  const auto lines = collinear_triples(kSeed, 1.0, 2000);
  const auto others = collinear_triples(kSeed + 1, 1.0, 2000);
  std::vector<IncircleCase> flat;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const auto& [a, b, c] = lines[i];
    flat.push_back({a, b, c, others[i].b});
    flat.push_back({a, b, c, Point<2>{2 * b[0] - a[0], 2 * b[1] - a[1]}});
  }
  const Tally t = check(flat);
  EXPECT_AGREES(t);
  EXPECT_GT(t.exact_zeros, 0u);
}

/// Coordinates drawn per axis from a pool of magnitudes from the smallest subnormal to the
/// largest double, with random signs: repeated values give exact zeros, the spread defeats
/// every filter, and differences of ±DBL_MAX overflow to infinity in double arithmetic.
TEST(Predicates, MixedMagnitudesAgreeWithGmp) {
  constexpr std::array<double, 15> kPool{0.0, 5e-324, 3e-320, 2.2250738585072014e-308, 1e-300,
                                         1e-150, 0.1, 1.0, 3.0, 1e15, 1e15 + 1, 1e150, 1e300,
                                         0x1p-1000, std::numeric_limits<double>::max()};
  constexpr std::uint64_t kSeed = 9003;
  SCOPED_TRACE(seed_trace(kSeed));
  std::mt19937_64 rng(kSeed);
  std::uniform_int_distribution<std::size_t> pick(0, kPool.size() - 1);
  auto coord = [&] { return ((rng() & 1) ? -1.0 : 1.0) * kPool[pick(rng)]; };
  auto point = [&] { return Point<2>{coord(), coord()}; };
  std::vector<OrientCase> orient;
  std::vector<IncircleCase> circle;
  for (int i = 0; i < 20000; ++i) {
    orient.push_back({point(), point(), point()});
    circle.push_back({point(), point(), point(), point()});
  }
  const Tally o = check(orient);
  EXPECT_AGREES(o);
  EXPECT_GT(o.exact_zeros, 0u);
  const Tally c = check(circle);
  EXPECT_AGREES(c);
  EXPECT_GT(c.exact_zeros, 0u);
}

// --- orient3d ----------------------------------------------------------------------------

TEST(Predicates, Orient3dConvention) {
  // The unit tetrahedron is positive (the orientation of docs/FORMATS.md, "`dynmesh mesh` in 3D"); an odd permutation flips it,
  // an even one (a rotation of three corners) keeps it.
  const Point<3> o{0, 0, 0}, x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
  EXPECT_EQ(dynmesh::orient3d(o, x, y, z), 1);
  EXPECT_EQ(dynmesh::orient3d(o, y, x, z), -1);
  EXPECT_EQ(dynmesh::orient3d(x, y, o, z), 1);
  EXPECT_EQ(dynmesh::orient3d(o, x, y, Point<3>{1, 1, 0}), 0);  // coplanar
  EXPECT_EQ(dynmesh::orient3d(o, x, x, z), 0);                  // repeated point
  // Below the plane of a counter-clockwise (seen from +z) triangle: negative.
  EXPECT_EQ(dynmesh::orient3d(o, x, y, Point<3>{0.25, 0.25, -1e-300}), -1);
  // Far from the unit scale the filter overflows or underflows; the exact stage decides.
  for (const double s : {0x1p1000, 0x1p-1000, 5e-324 * 0x1p10}) {
    EXPECT_EQ(dynmesh::orient3d(o, scaled(x, s), scaled(y, s), scaled(z, s)), 1) << s;
    EXPECT_EQ(dynmesh::orient3d(o, scaled(y, s), scaled(x, s), scaled(z, s)), -1) << s;
  }
  // CGAL's sign convention, where the filter does not decide: its exact stage called directly.
  EXPECT_EQ(dynmesh::detail::orient3d_exact(o, x, y, z), 1);
  EXPECT_EQ(dynmesh::detail::orient3d_exact(o, y, x, z), -1);
  EXPECT_EQ(dynmesh::detail::orient3d_exact(o, x, y, Point<3>{1, 1, 0}), 0);
  ExactSign exact;
  EXPECT_EQ(exact.orient3d({o, x, y, z}), 1);
  EXPECT_EQ(exact.orient3d({o, y, x, z}), -1);
  EXPECT_EQ(exact.orient3d({{0.5, 0.5, 0.5}, {12, 12, 12}, {24, 24, 24}, {1, 2, 3}}), 0);
  // The 2D reference's case lifted: a, b, c in the plane z = 0, counter-clockwise by about
  // 1e-300 (seen from +z), and d above it.
  EXPECT_EQ(exact.orient3d({{1e-300, 0, 0}, {0, 1e300, 0}, {5e-324, 5e-324, 0}, {0, 0, 1}}), 1);
  EXPECT_EQ(dynmesh::orient3d({1e-300, 0, 0}, {0, 1e300, 0}, {5e-324, 5e-324, 0}, {0, 0, 1}), 1);
}

/// Random points, as the 2D families, in 3D.
TEST(Predicates, Orient3dRandomAgreesWithGmp) {
  constexpr std::uint64_t kSeed = 20261207;
  SCOPED_TRACE(seed_trace(kSeed) + ", cases " + std::to_string(kRandomCases));
  RandomPoints<3> gen(kSeed);
  ExactSign exact;
  Tally t;
  for (std::size_t i = 0; i < kRandomCases; ++i) {
    const int mix = gen.next_mix();
    gen.recenter();
    const Orient3dCase k{gen.point(mix), gen.point(mix), gen.point(mix), gen.point(mix)};
    t.record(k, dynmesh::orient3d(k.a, k.b, k.c, k.d), exact.orient3d(k));
  }
  EXPECT_AGREES(t);
  EXPECT_GT(t.exact_zeros, 0u);
}

/// Kettner et al.'s grid on a plane: a = (0.5 + i·2^-53, 0.5 + j·2^-53, 1) near the plane
/// z = x + y through b, c, d, i, j < 256, in the four cyclic rotations.
std::vector<Orient3dCase> planar_grid() {
  std::vector<Orient3dCase> cases;
  const double u = std::ldexp(1.0, -53);
  const Point<3> b{12, 12, 24}, c{24, 12, 36}, d{3, 20, 23};
  for (int i = 0; i < 256; ++i)
    for (int j = 0; j < 256; ++j) {
      const Point<3> a{0.5 + i * u, 0.5 + j * u, 1.0};
      cases.push_back({a, b, c, d});
      cases.push_back({b, c, d, a});
      cases.push_back({c, d, a, b});
      cases.push_back({d, a, b, c});
    }
  return cases;
}

/// d on the plane through random a, b, c (rounded), then moved by up to 2 ulps per axis, at
/// scales from 1e-200 to 1e300.
std::vector<Orient3dCase> near_coplanar(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), along(-1.0, 2.0);
  std::uniform_int_distribution<int> nudge(-2, 2);
  std::vector<Orient3dCase> cases;
  for (double s : {1.0, 0x1p40, 0x1p-40, 1e200, 1e-200, 1e300}) {
    for (int i = 0; i < 5000; ++i) {
      const auto random_point = [&] { return Point<3>{s * unit(rng), s * unit(rng), s * unit(rng)}; };
      const Point<3> a = random_point(), b = random_point(), c = random_point();
      const double t1 = along(rng), t2 = along(rng);
      Point<3> d;
      for (std::size_t k = 0; k < 3; ++k) d[k] = a[k] + t1 * (b[k] - a[k]) + t2 * (c[k] - a[k]);
      cases.push_back({a, b, c, ulps(d, nudge(rng), nudge(rng), nudge(rng))});
    }
  }
  return cases;
}

TEST(Predicates, Orient3dNearlyDegenerateAgreesWithGmp) {
  const Tally grid = check(planar_grid());
  EXPECT_AGREES(grid);
  EXPECT_GT(grid.exact_zeros, 0u);
  constexpr std::uint64_t kSeed = 7003;
  SCOPED_TRACE(seed_trace(kSeed));
  const Tally random = check(near_coplanar(kSeed));
  EXPECT_AGREES(random);
  // The harness can fail here: the textbook double determinant disagrees with GMP.
  EXPECT_GT(check(planar_grid(), naive_orient3d).mismatches, 0u);
  EXPECT_GT(check(near_coplanar(kSeed), naive_orient3d).mismatches, 0u);
}

/// Quadruples of o + i·u + j·v, i, j ∈ [−100, 100], for a random integer o ∈ [−10^6, 10^6]³
/// and directions u, v ∈ [−1000, 1000]³, scaled by s: coplanar (and below 2^21, so exact
/// under the power-of-two scales).
std::vector<Orient3dCase> coplanar_quadruples(std::uint64_t seed, double s, int n) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> shift(-1'000'000, 1'000'000), dir(-1000, 1000), step(-100, 100);
  std::vector<Orient3dCase> cases;
  const auto draw = [&](std::uniform_int_distribution<int>& dist) {
    return Point<3>{static_cast<double>(dist(rng)), static_cast<double>(dist(rng)), static_cast<double>(dist(rng))};
  };
  for (int i = 0; i < n; ++i) {
    const Point<3> o = draw(shift), u = draw(dir), v = draw(dir);
    auto at = [&] {
      const double j = step(rng), k = step(rng);
      return scaled(Point<3>{o[0] + j * u[0] + k * v[0], o[1] + j * u[1] + k * v[1], o[2] + j * u[2] + k * v[2]}, s);
    };
    cases.push_back({at(), at(), at(), at()});
  }
  return cases;
}

TEST(Predicates, Orient3dExactlyDegenerateAgreesWithGmp) {
  constexpr std::uint64_t kSeed = 9004;
  SCOPED_TRACE(seed_trace(kSeed));
  for (double s : kExactScales) {
    SCOPED_TRACE("exact scale " + dynmesh::format_exact(s));
    const Tally t = check(coplanar_quadruples(kSeed, s, 2000));
    EXPECT_AGREES(t);
    EXPECT_EQ(t.exact_zeros, t.cases);  // the reference sees the construction
  }
  for (double s : kRoundingScales) {
    SCOPED_TRACE("rounding scale " + dynmesh::format_exact(s));
    EXPECT_AGREES(check(coplanar_quadruples(kSeed, s, 2000)));
  }
}

/// As MixedMagnitudesAgreeWithGmp: a pool from the smallest subnormal to DBL_MAX.
TEST(Predicates, Orient3dMixedMagnitudesAgreeWithGmp) {
  constexpr std::array<double, 15> kPool{0.0, 5e-324, 3e-320, 2.2250738585072014e-308, 1e-300,
                                         1e-150, 0.1, 1.0, 3.0, 1e15, 1e15 + 1, 1e150, 1e300,
                                         0x1p-1000, std::numeric_limits<double>::max()};
  constexpr std::uint64_t kSeed = 9005;
  SCOPED_TRACE(seed_trace(kSeed));
  std::mt19937_64 rng(kSeed);
  auto coord = [&] { return ((rng() & 1) ? -1.0 : 1.0) * kPool[rng() % kPool.size()]; };
  auto point = [&] { return Point<3>{coord(), coord(), coord()}; };
  std::vector<Orient3dCase> cases;
  for (int i = 0; i < 20000; ++i) cases.push_back({point(), point(), point(), point()});
  const Tally t = check(cases);
  EXPECT_AGREES(t);
  EXPECT_GT(t.exact_zeros, 0u);
}

// --- the pencil of circles through p and q (DynHPU's leaves) -------------------------------

/// The definition, in rationals: is |x − c|² − |p − c|² (c = m + h·J(q − p)) positive?
int pencil_reference(const Point<2>& p, const Point<2>& q, double h, const Point<2>& x) {
  const mpq_class px(p[0]), py(p[1]), qx(q[0]), qy(q[1]), xx(x[0]), xy(x[1]), hh(h);
  const mpq_class cx = (px + qx) / 2 - hh * (qy - py), cy = (py + qy) / 2 + hh * (qx - px);
  const mpq_class d = (xx - cx) * (xx - cx) + (xy - cy) * (xy - cy) - (px - cx) * (px - cx) - (py - cy) * (py - cy);
  return sgn(d);
}

TEST(Predicates, PencilAgreesWithTheCircleDefinition) {
  constexpr std::uint64_t kSeed = 20261123;
  SCOPED_TRACE(seed_trace(kSeed));
  RandomPoints gen(kSeed);
  std::mt19937_64 rng(kSeed);
  // The leaves' and apexes' heights at 1°, 20.7° and 30°, exact dyadic ones, 0 and negative.
  const std::array<double, 9> heights{0.5 / std::tan(std::numbers::pi / 180), 0.5 / std::tan(20.7 * std::numbers::pi / 180),
                                      0.5 / std::tan(std::numbers::pi / 6), 0.95 * 0.5 / std::tan(15 * std::numbers::pi / 180),
                                      0.5, 1.0, 0.0, -0.75, 3.0};
  std::size_t zeros = 0;
  for (std::size_t i = 0; i < kRandomCases / 4; ++i) {
    const int mix = gen.next_mix();
    gen.recenter();
    const Point<2> p = gen.point(mix), q = gen.point(mix), x = gen.point(mix);
    const double h = heights[rng() % heights.size()];
    const int want = pencil_reference(p, q, h, x);
    zeros += want == 0;
    ASSERT_EQ(dynmesh::pencil(p, q, h, x), want) << dynmesh::to_string<2>(p) << dynmesh::to_string<2>(q) << " h=" << h
                                                  << " x=" << dynmesh::to_string<2>(x);
  }
  EXPECT_GT(zeros, 0u);  // p, q or x repeated, or on the circle: the exact path is reached
  // Points on a circle with a dyadic centre, and their neighbours one ulp away: p = (0, 0),
  // q = (2, 0), h = 0.5 has centre (1, 1) and radius √2.
  const Point<2> p{0, 0}, q{2, 0};
  for (const Point<2>& on : {Point<2>{2, 2}, Point<2>{0, 2}, Point<2>{1 + std::sqrt(2.0), 1}}) {
    for (int dx = -2; dx <= 2; ++dx)
      for (int dy = -2; dy <= 2; ++dy) {
        Point<2> x = on;
        for (int k = 0; k < std::abs(dx); ++k) x[0] = std::nextafter(x[0], dx < 0 ? -1e300 : 1e300);
        for (int k = 0; k < std::abs(dy); ++k) x[1] = std::nextafter(x[1], dy < 0 ? -1e300 : 1e300);
        EXPECT_EQ(dynmesh::pencil(p, q, 0.5, x), pencil_reference(p, q, 0.5, x)) << dynmesh::to_string<2>(x);
      }
  }
  EXPECT_EQ(dynmesh::pencil(p, q, 0.5, Point<2>{2, 2}), 0);
  EXPECT_EQ(dynmesh::pencil(p, q, 0.5, Point<2>{1, 1}), -1);
  EXPECT_EQ(dynmesh::pencil(p, q, 0.5, Point<2>{1, -1}), 1);
}

/// The pencil's filter has no range test: products that underflow or overflow, and heights
/// from 0 to beyond 2^60, must still give the definition's sign.
TEST(Predicates, PencilMixedMagnitudesAgreeWithTheCircleDefinition) {
  constexpr std::array<double, 13> kPool{0.0, 5e-324, 3e-320, 2.2250738585072014e-308, 1e-300, 1e-150, 0.1,
                                         1.0, 3.0, 1e15, 1e150, 1e300, std::numeric_limits<double>::max()};
  constexpr std::array<double, 8> kHeights{0.0, 5e-324, 1e-200, 0.5, 1.3, 0x1p60, 0x1p61, 1e200};
  constexpr std::uint64_t kSeed = 20261128;
  SCOPED_TRACE(seed_trace(kSeed));
  std::mt19937_64 rng(kSeed);
  auto coord = [&] { return ((rng() & 1) ? -1.0 : 1.0) * kPool[rng() % kPool.size()]; };
  auto point = [&] { return Point<2>{coord(), coord()}; };
  std::size_t zeros = 0, nonzero = 0;
  for (int i = 0; i < 20000; ++i) {
    // Points near one another at a random scale as well, where the filter can decide
    // (offsets below the pool's last, DBL_MAX, so that every coordinate stays finite).
    const double s = kPool[rng() % (kPool.size() - 1)];
    const Point<2> p = point(), q = i % 2 ? point() : Point<2>{p[0] + s, p[1] - 0.5 * s};
    const Point<2> x = i % 3 ? point() : Point<2>{p[0] + 0.25 * s, p[1] + s};
    const double h = ((rng() & 1) ? -1.0 : 1.0) * kHeights[rng() % kHeights.size()];
    if (!(std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(x[0]) && std::isfinite(x[1])))
      continue;  // an offset from a coordinate near DBL_MAX overflowed
    const int want = pencil_reference(p, q, h, x);
    zeros += want == 0;
    nonzero += want != 0;
    ASSERT_EQ(dynmesh::pencil(p, q, h, x), want) << dynmesh::to_string<2>(p) << dynmesh::to_string<2>(q) << " h=" << h
                                                  << " x=" << dynmesh::to_string<2>(x);
  }
  EXPECT_GT(zeros, 0u);
  EXPECT_GT(nonzero, 0u);
}

/// Far from the unit scale the inline filters overflow (or underflow) and cannot decide; the
/// exact stage then rescales the call by a power of two and filters it again. Random cases
/// scaled by 2^±960 must agree with GMP and reach exact arithmetic exactly as often as the
/// same cases unscaled (the signs and the filters' decisions are scale-free); without the
/// rescale, every scaled in-circle call and most others would.
TEST(Predicates, FarFromTheUnitScaleTheFiltersStillDecide) {
  constexpr std::uint64_t kSeed = 20261206;
  SCOPED_TRACE(seed_trace(kSeed));
  RandomPoints gen(kSeed);
  RandomPoints<3> gen3(kSeed + 1);
  std::mt19937_64 rng(kSeed);
  std::array<std::vector<OrientCase>, 3> orient;
  std::array<std::vector<IncircleCase>, 3> circle;
  std::array<std::vector<Orient3dCase>, 3> solid;
  std::array<std::uint64_t, 3> pencil_exact{};
  constexpr std::array<int, 3> kScales{0, 960, -960};
  const auto at = []<std::size_t d>(const Point<d>& p, int e) {
    Point<d> out;
    for (std::size_t k = 0; k < d; ++k) out[k] = std::ldexp(p[k], e);
    return out;
  };
  const auto exact_scale = [&](const auto& p) {
    return at(at(p, 960), -960) == p && at(at(p, -960), 960) == p;  // nothing rounded
  };
  for (std::size_t i = 0; i < kRandomCases / 20; ++i) {
    const int mix = gen.next_mix();
    gen.recenter();
    gen3.recenter();
    const Point<3> p = gen3.point(mix), q = gen3.point(mix), r = gen3.point(mix), t = gen3.point(mix);
    if (exact_scale(p) && exact_scale(q) && exact_scale(r) && exact_scale(t))
      for (std::size_t s = 0; s < kScales.size(); ++s)
        solid[s].push_back({at(p, kScales[s]), at(q, kScales[s]), at(r, kScales[s]), at(t, kScales[s])});
    const Point<2> a = gen.point(mix), b = gen.point(mix), c = gen.point(mix), d = gen.point(mix);
    if (!(exact_scale(a) && exact_scale(b) && exact_scale(c) && exact_scale(d))) continue;
    const double h = 0.5 / std::tan(20.7 * std::numbers::pi / 180) * (rng() % 2 ? 1 : -1);
    for (std::size_t s = 0; s < kScales.size(); ++s) {
      const int e = kScales[s];
      orient[s].push_back({at(a, e), at(b, e), at(c, e)});
      circle[s].push_back({at(a, e), at(b, e), at(c, e), at(d, e)});
      const std::uint64_t before = dynmesh::detail::exact_stage_calls();
      ASSERT_EQ(dynmesh::pencil(at(a, e), at(b, e), h, at(c, e)), pencil_reference(a, b, h, c)) << "scale 2^" << e;
      pencil_exact[s] += dynmesh::detail::exact_stage_calls() - before;
    }
  }
  std::array<std::uint64_t, 3> orient_exact{}, circle_exact{}, solid_exact{};
  // The exact-stage calls of one family, whose signs must all agree with GMP.
  const auto exact_calls = [](const auto& cases) {
    const std::uint64_t before = dynmesh::detail::exact_stage_calls();
    const Tally t = check(cases);
    const std::uint64_t calls = dynmesh::detail::exact_stage_calls() - before;
    EXPECT_AGREES(t);
    return calls;
  };
  for (std::size_t s = 0; s < kScales.size(); ++s) {
    SCOPED_TRACE("scale 2^" + std::to_string(kScales[s]));
    orient_exact[s] = exact_calls(orient[s]);
    circle_exact[s] = exact_calls(circle[s]);
    solid_exact[s] = exact_calls(solid[s]);
  }
  std::printf("[ Predicates ] %zu cases: exact-stage calls orient2d %llu, incircle %llu, pencil %llu, orient3d %llu "
              "(of %zu) at the unit scale\n",
              orient[0].size(), static_cast<unsigned long long>(orient_exact[0]),
              static_cast<unsigned long long>(circle_exact[0]), static_cast<unsigned long long>(pencil_exact[0]),
              static_cast<unsigned long long>(solid_exact[0]), solid[0].size());
  EXPECT_GT(orient_exact[0] + circle_exact[0], 0u);  // the degenerate cases of the mixes reach it
  EXPECT_GT(solid_exact[0], 0u);
  for (std::size_t s = 1; s < kScales.size(); ++s) {
    EXPECT_EQ(orient_exact[s], orient_exact[0]) << "orient2d at 2^" << kScales[s];
    EXPECT_EQ(circle_exact[s], circle_exact[0]) << "incircle at 2^" << kScales[s];
    EXPECT_EQ(pencil_exact[s], pencil_exact[0]) << "pencil at 2^" << kScales[s];
    EXPECT_EQ(solid_exact[s], solid_exact[0]) << "orient3d at 2^" << kScales[s];
  }
}

/// The filters' own arithmetic stays in the normal range on meshing input: a subnormal
/// result costs a microcode assist on x86, and a subnormal room for underflow in the
/// in-circle filter would make one on every call. IEEE 754 raises the underflow flag for an inexact subnormal
/// result, so a clean flag after many calls says no call computed one.
TEST(Predicates, FiltersComputeNoSubnormalOnMeshingInput) {
  constexpr std::uint64_t kSeed = 20261130;
  SCOPED_TRACE(seed_trace(kSeed));
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // Coordinates from the unit square to a box of side 2^20, and points about 2^-20 apart.
  for (const double scale : {1.0, 0x1p20, 0x1p-20}) {
    SCOPED_TRACE("scale " + std::to_string(scale));
    std::feclearexcept(FE_ALL_EXCEPT);
    int sum = 0;
    for (int i = 0; i < 1000; ++i) {
      const auto pt = [&] { return Point<2>{1.5 + u(rng) * scale, 0.25 + u(rng) * scale}; };
      const Point<2> a = pt(), b = pt(), c = pt(), d = pt();
      sum += dynmesh::orient2d(a, b, c) + dynmesh::incircle(a, b, c, d) + dynmesh::pencil(a, b, u(rng), c);
      const auto pt3 = [&] { return Point<3>{1.5 + u(rng) * scale, 0.25 + u(rng) * scale, -3 + u(rng) * scale}; };
      sum += dynmesh::orient3d(pt3(), pt3(), pt3(), pt3());
    }
    EXPECT_FALSE(std::fetestexcept(FE_UNDERFLOW)) << "a filter computed a subnormal number (sum " << sum << ")";
  }
}

}  // namespace
