// distributions.cpp — the generators of dynmesh/distributions.hpp.
#include "dynmesh/distributions.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "sac/splitmix64.hpp"

namespace dynmesh {

std::uint64_t Rng::below(std::uint64_t n) {
  if (n == 0) throw std::invalid_argument("Rng::below(0)");
  // Bitmask rejection: draw bits under the next power of two, reject values ≥ n (fewer than
  // two draws expected). Unbiased and exactly reproducible.
  const std::uint64_t mask = n == 1 ? 0 : ~std::uint64_t{0} >> std::countl_zero(n - 1);
  std::uint64_t x = gen_() & mask;
  while (x >= n) x = gen_() & mask;
  return x;
}

double Rng::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = 1.0 - uniform();  // (0, 1]: log is finite
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  const double t = 2.0 * std::numbers::pi * u2;
  spare_ = r * std::sin(t);
  has_spare_ = true;
  return r * std::cos(t);
}

namespace {

constexpr std::array<Distribution, 8> kAll = {Distribution::Uniform,   Distribution::Clusters, Distribution::Spiral,
                                              Distribution::Shrinking, Distribution::Grid,     Distribution::Collinear,
                                              Distribution::Boundary,  Distribution::Curves};

template <std::size_t d>
double distance(const Point<d>& a, const Point<d>& b) {
  double s = 0;
  for (std::size_t k = 0; k < d; ++k) s += (a[k] - b[k]) * (a[k] - b[k]);
  return std::sqrt(s);
}

template <std::size_t d>
std::vector<Point<d>> uniform_points(std::size_t n, Rng& rng) {
  std::vector<Point<d>> pts(n);
  for (auto& p : pts)
    for (std::size_t a = 0; a < d; ++a) p[a] = rng.uniform();
  return pts;
}

template <std::size_t d>
std::vector<Point<d>> cluster_points(std::size_t n, Rng& rng) {
  const std::size_t clusters = std::max<std::size_t>(1, std::min<std::size_t>(n, 8));
  std::vector<Point<d>> centre(clusters);
  std::vector<double> sigma(clusters);
  for (std::size_t c = 0; c < clusters; ++c) {
    for (std::size_t a = 0; a < d; ++a) centre[c][a] = rng.uniform(0.2, 0.8);
    // 1e-1 · (1e-3)^(c / (clusters − 1)): several radii, from 1e-1 to 1e-4.
    sigma[c] = clusters == 1 ? 0.1 : 0.1 * std::pow(1e-3, static_cast<double>(c) / static_cast<double>(clusters - 1));
  }
  std::vector<Point<d>> pts(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t c = i % clusters;  // equal shares, then shuffled
    for (std::size_t a = 0; a < d; ++a) pts[i][a] = centre[c][a] + sigma[c] * rng.normal();
  }
  rng.shuffle(pts);
  return pts;
}

template <std::size_t d>
std::vector<Point<d>> spiral_points(std::size_t n, Rng& rng) {
  std::vector<Point<d>> pts(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = (static_cast<double>(k) + rng.uniform(0.25, 0.75)) / static_cast<double>(n);
    if constexpr (d == 2) {
      const double turns = 4.0;
      const double r = 0.5 * t, th = 2.0 * std::numbers::pi * turns * t;
      pts[k] = {0.5 + r * std::cos(th), 0.5 + r * std::sin(th)};
    } else {
      const double turns = 8.0;
      const double z = 1.0 - 2.0 * t, s = std::sqrt(std::max(0.0, 1.0 - z * z));
      const double th = 2.0 * std::numbers::pi * turns * t;
      pts[k] = {0.5 + 0.5 * s * std::cos(th), 0.5 + 0.5 * s * std::sin(th), 0.5 + 0.5 * z};
    }
  }
  rng.shuffle(pts);
  return pts;
}

// --- shrinking ----------------------------------------------------------------------------
// Octave j (j = 0..K−1) has scale r_j = 0.5 · 2^-j and holds points c + r_j·u, u from a
// jittered lattice pattern in the shell |u| ∈ [0.5 + 0.567h, 1 − 0.567h]: lattice spacing h,
// sites h·z with |h·z| ∈ [0.5 + h, 1 − h], jitter ±h/4 per axis. Two points of one octave are
// ≥ r_j·h/2 apart; adjacent octaves are separated by a gap of ≥ 0.85·h·r_j. So the closest
// pair is about r_{K−1}·h (between h/2 and ~h), and the extent about 2·r_0 = 1.

constexpr double kShellVolume2 = std::numbers::pi * (1.0 - 0.25);            // area of 0.5 ≤ |u| ≤ 1
constexpr double kShellVolume3 = 4.0 / 3.0 * std::numbers::pi * (1.0 - 0.125);  // volume of 0.5 ≤ |u| ≤ 1

template <std::size_t d>
std::vector<std::array<long, d>> shell_sites(double h) {
  std::vector<std::array<long, d>> sites;
  const long lim = static_cast<long>(std::ceil(1.0 / h));
  std::array<long, d> z{};
  for (std::size_t a = 0; a < d; ++a) z[a] = -lim;
  while (true) {
    double r2 = 0;
    for (std::size_t a = 0; a < d; ++a) r2 += (h * static_cast<double>(z[a])) * (h * static_cast<double>(z[a]));
    const double r = std::sqrt(r2);
    if (r >= 0.5 + h && r <= 1.0 - h) sites.push_back(z);
    std::size_t a = 0;
    while (a < d && z[a] == lim) z[a++] = -lim;
    if (a == d) break;
    ++z[a];
  }
  return sites;
}

/// Lattice spacing for m points per octave: about (shell volume / (1.5·m))^(1/d), capped at
/// 0.25, and reduced until the shell holds at least 1.5·m sites.
template <std::size_t d>
double shell_spacing_estimate(std::size_t m) {
  const double vol = d == 2 ? kShellVolume2 : kShellVolume3;
  return std::min(0.25, std::pow(vol / (1.5 * static_cast<double>(m)), 1.0 / static_cast<double>(d)));
}

/// The shrinking set with exactly k octaves (k ≤ n).
template <std::size_t d>
std::vector<Point<d>> shrinking_with_octaves(std::size_t n, std::size_t k, Rng& rng) {
  const std::size_t m = (n + k - 1) / k;
  double h = shell_spacing_estimate<d>(m);
  std::vector<std::array<long, d>> sites = shell_sites<d>(h);
  const std::size_t want = m + m / 2;
  while (sites.size() < want) {
    h *= 0.9;
    sites = shell_sites<d>(h);
  }
  std::vector<Point<d>> pts;
  pts.reserve(n);
  std::vector<std::size_t> idx(sites.size());
  for (std::size_t j = 0; j < k && pts.size() < n; ++j) {
    const double r = 0.5 * std::ldexp(1.0, -static_cast<int>(j));
    const std::size_t take = std::min(m, n - pts.size());
    // A random subset of `take` sites: partial Fisher–Yates.
    std::iota(idx.begin(), idx.end(), std::size_t{0});
    for (std::size_t t = 0; t < take; ++t) std::swap(idx[t], idx[t + static_cast<std::size_t>(rng.below(idx.size() - t))]);
    for (std::size_t t = 0; t < take; ++t) {
      Point<d> p;
      for (std::size_t a = 0; a < d; ++a) {
        const double u = h * static_cast<double>(sites[idx[t]][a]) + rng.uniform(-0.25, 0.25) * h;
        p[a] = 0.5 + r * u;
      }
      pts.push_back(p);
    }
  }
  rng.shuffle(pts);
  return pts;
}

template <std::size_t d>
std::vector<Point<d>> shrinking_points(std::size_t n, double spread, Rng& rng) {
  if (n == 0) return {};
  const std::size_t kmax = std::min<std::size_t>(n, 60);
  // First guess from the estimate spread(K) ≈ 3·(1 − h) / (r_{K−1}·h·0.75), then correct K by
  // the measured spread (each octave doubles it); every attempt restarts from the same random
  // state, so the result is a function of the seed.
  std::size_t k = 1;
  double best_err = std::numeric_limits<double>::infinity();
  for (std::size_t c = 1; c <= kmax; ++c) {
    const double h = shell_spacing_estimate<d>((n + c - 1) / c);
    const double r_last = 0.5 * std::ldexp(1.0, -static_cast<int>(c - 1));
    const double err = std::abs(std::log2(3.0 * (1.0 - h) / (r_last * h * 0.75)) - std::log2(spread));
    if (err < best_err) {
      best_err = err;
      k = c;
    }
  }
  const Rng start = rng;
  std::vector<Point<d>> best;
  best_err = std::numeric_limits<double>::infinity();
  std::vector<std::size_t> tried;
  for (int attempt = 0; attempt < 4; ++attempt) {
    Rng r = start;
    std::vector<Point<d>> pts = shrinking_with_octaves<d>(n, k, r);
    if (n < 2) return pts;
    tried.push_back(k);
    const double diff = std::log2(spread) - log2_spread<d>(derive_box<d>(pts), pts);
    if (std::abs(diff) < best_err) {
      best_err = std::abs(diff);
      best = std::move(pts);
    }
    const double step = std::round(diff);
    if (step == 0) break;
    const double next = std::clamp(static_cast<double>(k) + step, 1.0, static_cast<double>(kmax));
    k = static_cast<std::size_t>(next);
    if (std::find(tried.begin(), tried.end(), k) != tried.end()) break;
  }
  return best;
}

// --- curves -----------------------------------------------------------------------------------
// K = max(2, round(√n / 4)) curves (at most n), each a Fourier-perturbed star-shaped loop
// around a centre c uniform in [0.15, 0.85]^d: c + R·(ρ(θ)·(cos θ·e1 + sin θ·e2) + h(θ)·e3), with
//   ρ(θ) = 1 + Σ_{j=2..4} (a_j cos jθ + b_j sin jθ),  |a_j|, |b_j| ≤ 0.3/j, so ρ ∈ [0.54, 1.46];
//   R uniform in [0.02, 0.08], so every point lies within 0.118 of c, in [0.03, 0.97]^d;
//   2D: e1, e2 the axes, h = 0; 3D: (e1, e2, e3) a random orthonormal frame and the wobble
//   h(θ) = Σ_{j=1,2} (α_j cos jθ + β_j sin jθ), |α_j|, |β_j| ≤ 0.05.
// A loop is star-shaped (ρ > 0), so it never crosses itself. Half the curves (at random) are
// open arcs: a random fraction in [0.25, 0.75] of their loop, from a random start. Each curve
// gets one point, and the other n − K are shared out in proportion to the curves' lengths
// (largest remainders), so that the spacing is the same on every curve (as a digitizer or a
// scanner samples); a curve's m points lie at stratified arc lengths, (i + u)·ℓ/m with u
// uniform in [0.25, 0.75] for its length ℓ, so two neighbours on a curve are between 0.5 and
// 1.5 spacings apart. Why the curves are far apart for their spacing, at every n: K curves of
// mean length ℓ̄ ≈ 0.25 spaced over an area A ≈ 0.6 are about A/(K·ℓ̄) apart, and the
// spacing along them is K·ℓ̄/n, so the ratio is A·n/(K·ℓ̄)² ≈ 16·A/ℓ̄² ≈ 150 for K = √n/4;
// the median distance from a point to the nearest other curve is many spacings (the curves
// cross here and there), more in 3D.
//
// No libm: cos θ and sin θ come from the rational parametrization of the circle,
// ((1 − u²)/(1 + u²), 2u/(1 + u²)) for u in [0, 1) on each quarter turn, and the harmonics
// from complex powers, so only + − × / and the correctly rounded sqrt (the arc lengths and the
// 3D frame) are used: the points are the same bits on every platform. Arc lengths come from a
// polygon of 8m + 32 vertices on the curve; a point's parameter is interpolated linearly
// between two of its vertices and the curve evaluated there, so every point lies on the
// smooth curve itself.

/// One curve: centre, radius, frame, shape coefficients, and the parameter range [t0, t0 + span)
/// of the loop's parameter t in [0, 1) (one turn).
template <std::size_t d>
struct CurveShape {
  Point<d> centre{};
  double radius = 0;
  std::array<Point<d>, 3> frame{};  // e1, e2, e3 (e3 unused in 2D)
  std::array<double, 5> a{}, b{};   // ρ's coefficients, j = 2..4
  std::array<double, 3> alpha{}, beta{};  // 3D wobble, j = 1..2
  double t0 = 0, span = 1;
};

/// A point (cos θ, sin θ) of the unit circle for the parameter t in [0, 1) of one turn, without
/// libm: quarter turn q = ⌊4t⌋, and within it u = 4t − q = tan(θ'/2) of the angle θ' past
/// q·90°, so θ grows smoothly and monotonically with t within each quarter.
inline std::array<double, 2> circle_point(double t) {
  const double q4 = 4.0 * t;
  const double q = std::floor(q4);
  const double u = q4 - q;
  const double den = 1.0 + u * u;
  const double x = (1.0 - u * u) / den, y = 2.0 * u / den;
  switch (static_cast<int>(q) & 3) {
    case 0: return {x, y};
    case 1: return {-y, x};
    case 2: return {-x, -y};
    default: return {y, -x};
  }
}

template <std::size_t d>
Point<d> curve_at(const CurveShape<d>& c, double t) {
  t -= std::floor(t);  // one turn
  const auto [x, y] = circle_point(t);
  // z^j = (cos jθ, sin jθ) by complex multiplication.
  double re = x, im = y, rho = 1.0, h = 0.0;
  for (std::size_t j = 1; j <= 4; ++j) {
    if (j >= 2) {
      const double r2 = re * x - im * y, i2 = re * y + im * x;
      re = r2;
      im = i2;
      rho += c.a[j] * re + c.b[j] * im;
    }
    if (j <= 2) h += c.alpha[j] * re + c.beta[j] * im;
  }
  Point<d> p = c.centre;
  for (std::size_t k = 0; k < d; ++k) {
    double off = rho * (x * c.frame[0][k] + y * c.frame[1][k]);
    if constexpr (d == 3) off += h * c.frame[2][k];
    p[k] += c.radius * off;
  }
  return p;
}

/// A unit vector uniform on the sphere, orthogonal to `against` when given (rejection from
/// the cube; + − × / and sqrt only).
inline Point<3> random_unit(Rng& rng, const Point<3>* against) {
  for (;;) {
    Point<3> v{rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
    if (against) {
      const double dot = v[0] * (*against)[0] + v[1] * (*against)[1] + v[2] * (*against)[2];
      for (std::size_t k = 0; k < 3; ++k) v[k] -= dot * (*against)[k];
    }
    const double n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if (n2 > 1.0 || n2 < 0x1p-10) continue;
    const double len = std::sqrt(n2);
    for (double& x : v) x /= len;
    return v;
  }
}

template <std::size_t d>
CurveShape<d> random_curve(Rng& rng) {
  CurveShape<d> c;
  for (std::size_t k = 0; k < d; ++k) c.centre[k] = rng.uniform(0.15, 0.85);
  c.radius = rng.uniform(0.02, 0.08);
  for (std::size_t j = 2; j <= 4; ++j) {
    const double bound = 0.3 / static_cast<double>(j);
    c.a[j] = rng.uniform(-bound, bound);
    c.b[j] = rng.uniform(-bound, bound);
  }
  if constexpr (d == 2) {
    c.frame[0] = {1, 0};
    c.frame[1] = {0, 1};
  } else {
    c.frame[0] = random_unit(rng, nullptr);
    c.frame[1] = random_unit(rng, &c.frame[0]);
    const Point<3>& e1 = c.frame[0];
    const Point<3>& e2 = c.frame[1];
    c.frame[2] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (std::size_t j = 1; j <= 2; ++j) {
      c.alpha[j] = rng.uniform(-0.05, 0.05);
      c.beta[j] = rng.uniform(-0.05, 0.05);
    }
  }
  if (rng.below(2) == 1) {  // an open arc
    c.t0 = rng.uniform();
    c.span = rng.uniform(0.25, 0.75);
  }
  return c;
}

/// The cumulative lengths of a polygon of `vertices` + 1 vertices on curve c, vertex v at
/// parameter t0 + span·v/vertices: entry v is the length up to vertex v.
template <std::size_t d>
std::vector<double> polygon_lengths(const CurveShape<d>& c, std::size_t vertices) {
  std::vector<double> length(vertices + 1, 0.0);
  Point<d> prev = curve_at<d>(c, c.t0);
  for (std::size_t v = 1; v <= vertices; ++v) {
    const Point<d> p = curve_at<d>(c, c.t0 + c.span * static_cast<double>(v) / static_cast<double>(vertices));
    length[v] = length[v - 1] + distance<d>(prev, p);
    prev = p;
  }
  return length;
}

/// m points of curve c at stratified arc lengths (see above), in order along the curve.
template <std::size_t d>
std::vector<Point<d>> points_along(const CurveShape<d>& c, std::size_t m, Rng& rng) {
  const std::size_t vertices = 8 * m + 32;
  const std::vector<double> length = polygon_lengths<d>(c, vertices);
  const double total = length[vertices];
  std::vector<Point<d>> pts;
  pts.reserve(m);
  std::size_t v = 0;
  for (std::size_t i = 0; i < m; ++i) {
    const double s = (static_cast<double>(i) + rng.uniform(0.25, 0.75)) * total / static_cast<double>(m);
    while (v + 1 < vertices && length[v + 1] < s) ++v;
    const double seg = length[v + 1] - length[v];
    const double f = seg > 0 ? std::clamp((s - length[v]) / seg, 0.0, 1.0) : 0.0;
    const double t = (static_cast<double>(v) + f) / static_cast<double>(vertices);
    pts.push_back(curve_at<d>(c, c.t0 + c.span * t));
  }
  return pts;
}

template <std::size_t d>
std::vector<std::vector<Point<d>>> curves_by_curve(std::size_t n, Rng& rng) {
  if (n == 0) return {};
  const double k_estimate = std::round(std::sqrt(static_cast<double>(n)) / 4.0);
  const std::size_t k = std::min(n, std::max<std::size_t>(2, static_cast<std::size_t>(k_estimate)));
  std::vector<CurveShape<d>> shapes;
  std::vector<double> length(k);
  double total = 0;
  for (std::size_t c = 0; c < k; ++c) {
    shapes.push_back(random_curve<d>(rng));
    length[c] = polygon_lengths<d>(shapes[c], 256).back();
    total += length[c];
  }
  // One point each, the rest in proportion to length: whole shares first (capped, so rounding
  // cannot hand out more than n), then one more to the largest remainders, the first on ties.
  std::vector<std::size_t> m(k, 1);
  std::vector<double> remainder(k);
  std::size_t given = k;
  for (std::size_t c = 0; c < k; ++c) {
    const double share = static_cast<double>(n - k) * length[c] / total;
    const double whole = std::floor(share);
    const std::size_t add = std::min(static_cast<std::size_t>(whole), n - given);
    m[c] += add;
    given += add;
    remainder[c] = share - whole;
  }
  std::vector<std::size_t> order(k);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return remainder[a] > remainder[b]; });
  for (std::size_t i = 0; given < n; i = (i + 1) % k, ++given) ++m[order[i]];

  std::vector<std::vector<Point<d>>> curves;
  curves.reserve(k);
  for (std::size_t c = 0; c < k; ++c) curves.push_back(points_along<d>(shapes[c], m[c], rng));
  return curves;
}

template <std::size_t d>
std::vector<Point<d>> curve_distribution(std::size_t n, Rng& rng) {
  std::vector<Point<d>> pts;
  pts.reserve(n);
  for (const auto& curve : curves_by_curve<d>(n, rng)) pts.insert(pts.end(), curve.begin(), curve.end());
  rng.shuffle(pts);
  return pts;
}

// --- lattice, line, boundary ------------------------------------------------------------------

template <std::size_t d>
std::vector<Point<d>> grid_points(std::size_t n, Rng& rng) {
  if (n == 0) return {};
  std::uint64_t g = 1;
  auto power = [](std::uint64_t b) {
    std::uint64_t p = 1;
    for (std::size_t a = 0; a < d; ++a) p *= b;
    return p;
  };
  while (power(g) < n) ++g;
  const std::uint64_t sites = power(g);
  std::vector<std::uint64_t> idx(sites);
  std::iota(idx.begin(), idx.end(), std::uint64_t{0});
  for (std::size_t t = 0; t < n; ++t) std::swap(idx[t], idx[t + static_cast<std::size_t>(rng.below(sites - t))]);
  std::vector<Point<d>> pts(n);
  for (std::size_t t = 0; t < n; ++t) {
    std::uint64_t s = idx[t];
    for (std::size_t a = 0; a < d; ++a) {
      pts[t][a] = static_cast<double>(s % g);
      s /= g;
    }
  }
  return pts;  // already in random order
}

template <std::size_t d>
std::vector<Point<d>> collinear_points(std::size_t n, Rng& rng) {
  // start + t·dir with dyadic start, dir and t = (4k + r) / 2^m: every coordinate is exact, so
  // the points are exactly collinear (not only up to rounding), in a generic direction.
  constexpr std::array<double, 3> start3 = {0.125, 0.25, 0.375};
  constexpr std::array<double, 3> dir3 = {0.75, 0.625, 0.4375};
  int m = 2;
  while ((std::uint64_t{1} << m) < 4 * static_cast<std::uint64_t>(n)) ++m;
  std::vector<Point<d>> pts(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = std::ldexp(static_cast<double>(4 * k + rng.below(4)), -m);
    for (std::size_t a = 0; a < d; ++a) pts[k][a] = start3[a] + t * dir3[a];
  }
  rng.shuffle(pts);
  return pts;
}

/// Boost's hash_combine over the coordinates' std::hash (not splitmix64: no finaliser). It
/// must stay bit-stable: it orders the buckets of the set that drops repeated points.
template <std::size_t d>
struct PointBitsHash {
  std::size_t operator()(const Point<d>& p) const noexcept {
    std::uint64_t h = 0x243f6a8885a308d3ULL;
    for (std::size_t a = 0; a < d; ++a) {
      h ^= std::hash<double>{}(p[a]) + sac::kGoldenGamma + (h << 6) + (h >> 2);
    }
    return static_cast<std::size_t>(h);
  }
};

template <std::size_t d>
std::vector<Point<d>> boundary_points(std::size_t n, Rng& rng) {
  std::vector<Point<d>> pts;
  pts.reserve(n);
  std::unordered_set<Point<d>, PointBitsHash<d>> seen;
  auto add = [&](const Point<d>& p) {
    if (seen.insert(p).second) pts.push_back(p);
  };
  const double w = kBoundaryExtent;
  Point<d> lo{}, hi{};
  for (std::size_t a = 0; a < d; ++a) hi[a] = w;
  if (n >= 1) add(lo);
  if (n >= 2) add(hi);
  while (pts.size() < n) {
    Point<d> p;
    for (std::size_t a = 0; a < d; ++a) {
      // Derived box: o = −w, L = 3w (all exact). Boundaries of level l lie at
      // −w + 3w·i/2^l; those in [0, w] have i in [⌈2^l/3⌉, ⌊2^(l+1)/3⌋]. Every such value is
      // an exact double (w has 20 significant bits, i < 2^25).
      const int l = 2 + static_cast<int>(rng.below(23));
      const std::uint64_t cells = std::uint64_t{1} << l;
      const std::uint64_t ilo = (cells + 2) / 3, ihi = (2 * cells) / 3;
      const std::uint64_t i = ilo + rng.below(ihi - ilo + 1);
      p[a] = -w + (3.0 * w) * std::ldexp(static_cast<double>(i), -l);
    }
    add(p);
  }
  rng.shuffle(pts);
  return pts;
}

// --- closest pair ------------------------------------------------------------------------------

template <std::size_t d>
struct KeyHash {
  std::size_t operator()(const std::array<std::int64_t, d>& k) const noexcept {
    std::uint64_t h = sac::kGoldenGamma;
    for (std::size_t a = 0; a < d; ++a) h = sac::mix64(h ^ static_cast<std::uint64_t>(k[a]));
    return static_cast<std::size_t>(h);
  }
};

}  // namespace

std::span<const Distribution> all_distributions() noexcept { return kAll; }

std::string_view distribution_name(Distribution dist) noexcept {
  switch (dist) {
    case Distribution::Uniform: return "uniform";
    case Distribution::Clusters: return "clusters";
    case Distribution::Spiral: return "spiral";
    case Distribution::Shrinking: return "shrinking";
    case Distribution::Grid: return "grid";
    case Distribution::Collinear: return "collinear";
    case Distribution::Boundary: return "boundary";
    case Distribution::Curves: return "curves";
  }
  return "unknown";
}

std::optional<Distribution> parse_distribution(std::string_view name) noexcept {
  for (const Distribution dist : kAll)
    if (distribution_name(dist) == name) return dist;
  return std::nullopt;
}

template <std::size_t d>
std::vector<Point<d>> generate(Distribution dist, std::size_t n, std::uint64_t seed, double spread) {
  if (!(spread >= 2.0) || !std::isfinite(spread))
    throw std::invalid_argument("dynmesh::generate: spread must be finite and at least 2");
  Rng rng(seed);
  switch (dist) {
    case Distribution::Uniform: return uniform_points<d>(n, rng);
    case Distribution::Clusters: return cluster_points<d>(n, rng);
    case Distribution::Spiral: return spiral_points<d>(n, rng);
    case Distribution::Shrinking: return shrinking_points<d>(n, spread, rng);
    case Distribution::Grid: return grid_points<d>(n, rng);
    case Distribution::Collinear: return collinear_points<d>(n, rng);
    case Distribution::Boundary: return boundary_points<d>(n, rng);
    case Distribution::Curves: return curve_distribution<d>(n, rng);
  }
  throw std::invalid_argument("dynmesh::generate: unknown distribution");
}

template <std::size_t d>
double closest_pair_distance(std::span<const Point<d>> points) {
  const std::size_t n = points.size();
  if (n < 2) return std::numeric_limits<double>::infinity();
  // Random insertion order (fixed seed), grid of cell side delta = the current closest
  // distance; a point closer than delta to an inserted one lies in the 3^d block around its
  // cell. When delta shrinks, the grid is rebuilt: expected O(n) in total.
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), std::uint32_t{0});
  Rng rng(0x5eed'c105'e5a1'0001ULL);
  rng.shuffle(order);
  Point<d> lo = points[0], hi = points[0];
  for (const auto& p : points)
    for (std::size_t a = 0; a < d; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  double delta = distance<d>(points[order[0]], points[order[1]]);
  if (delta == 0) return 0;

  using Key = std::array<std::int64_t, d>;
  std::unordered_map<Key, std::uint32_t, KeyHash<d>> head;  // cell -> first point in chain
  std::vector<std::uint32_t> next(n, std::numeric_limits<std::uint32_t>::max());
  auto key_of = [&](const Point<d>& p) {
    Key k;
    for (std::size_t a = 0; a < d; ++a) {
      const double c = std::floor((p[a] - lo[a]) / delta);
      if (!(c < 0x1p60)) throw std::domain_error("closest_pair_distance: spread beyond 2^60");
      k[a] = static_cast<std::int64_t>(c);
    }
    return k;
  };
  auto insert = [&](std::uint32_t i) {
    const Key k = key_of(points[i]);
    auto [it, fresh] = head.try_emplace(k, i);
    next[i] = fresh ? std::numeric_limits<std::uint32_t>::max() : it->second;
    if (!fresh) it->second = i;
  };
  auto rebuild = [&](std::size_t upto) {
    head.clear();
    for (std::size_t t = 0; t < upto; ++t) insert(order[t]);
  };
  rebuild(2);
  for (std::size_t t = 2; t < n; ++t) {
    const std::uint32_t i = order[t];
    const Point<d>& p = points[i];
    const Key k = key_of(p);
    double best = delta;
    for (int code = 0; code < (d == 2 ? 9 : 27); ++code) {
      Key nb = k;
      int rest = code;
      for (std::size_t a = 0; a < d; ++a) {
        nb[a] += rest % 3 - 1;
        rest /= 3;
      }
      const auto it = head.find(nb);
      if (it == head.end()) continue;
      for (std::uint32_t j = it->second; j != std::numeric_limits<std::uint32_t>::max(); j = next[j])
        best = std::min(best, distance<d>(p, points[j]));
    }
    if (best == 0) return 0;
    if (best < delta) {
      delta = best;
      rebuild(t + 1);
    } else {
      insert(i);
    }
  }
  return delta;
}

template <std::size_t d>
double log2_spread(const Box<d>& box, std::span<const Point<d>> points) {
  if (points.size() < 2) return -std::numeric_limits<double>::infinity();
  const double s = closest_pair_distance<d>(points);
  if (s == 0) return std::numeric_limits<double>::infinity();
  return std::log2(box.side / s);
}

template <std::size_t d>
std::vector<std::vector<Point<d>>> curve_points(std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  return curves_by_curve<d>(n, rng);
}

template std::vector<Point<2>> generate<2>(Distribution, std::size_t, std::uint64_t, double);
template std::vector<Point<3>> generate<3>(Distribution, std::size_t, std::uint64_t, double);
template std::vector<std::vector<Point<2>>> curve_points<2>(std::size_t, std::uint64_t);
template std::vector<std::vector<Point<3>>> curve_points<3>(std::size_t, std::uint64_t);
template double closest_pair_distance<2>(std::span<const Point<2>>);
template double closest_pair_distance<3>(std::span<const Point<3>>);
template double log2_spread<2>(const Box<2>&, std::span<const Point<2>>);
template double log2_spread<3>(const Box<3>&, std::span<const Point<3>>);

namespace {

/// CPython's random.Random(seed).random(): MT19937 seeded by init_by_array({seed}), then
/// (a >> 5, b >> 6) of two outputs as a 53-bit fraction.
class PythonRandom {
 public:
  explicit PythonRandom(std::uint32_t seed) {
    init_genrand(19650218u);
    const std::uint32_t key[1] = {seed};
    std::size_t i = 1, j = 0;
    for (std::size_t k = 624; k > 0; --k) {
      mt_[i] = (mt_[i] ^ ((mt_[i - 1] ^ (mt_[i - 1] >> 30)) * 1664525u)) + key[j] + static_cast<std::uint32_t>(j);
      if (++i >= 624) {
        mt_[0] = mt_[623];
        i = 1;
      }
      if (++j >= 1) j = 0;
    }
    for (std::size_t k = 623; k > 0; --k) {
      mt_[i] = (mt_[i] ^ ((mt_[i - 1] ^ (mt_[i - 1] >> 30)) * 1566083941u)) - static_cast<std::uint32_t>(i);
      if (++i >= 624) {
        mt_[0] = mt_[623];
        i = 1;
      }
    }
    mt_[0] = 0x8000'0000u;
    index_ = 624;
  }
  double random() {
    const std::uint32_t a = next() >> 5, b = next() >> 6;
    return (a * 67108864.0 + b) * (1.0 / 9007199254740992.0);
  }

 private:
  void init_genrand(std::uint32_t s) {
    mt_[0] = s;
    for (std::size_t i = 1; i < 624; ++i)
      mt_[i] = 1812433253u * (mt_[i - 1] ^ (mt_[i - 1] >> 30)) + static_cast<std::uint32_t>(i);
  }
  std::uint32_t next() {
    if (index_ >= 624) {
      for (std::size_t k = 0; k < 624; ++k) {
        const std::uint32_t y = (mt_[k] & 0x8000'0000u) | (mt_[(k + 1) % 624] & 0x7fff'ffffu);
        mt_[k] = mt_[(k + 397) % 624] ^ (y >> 1) ^ ((y & 1u) ? 0x9908'b0dfu : 0u);
      }
      index_ = 0;
    }
    std::uint32_t y = mt_[index_++];
    y ^= y >> 11;
    y ^= (y << 7) & 0x9d2c'5680u;
    y ^= (y << 15) & 0xefc6'0000u;
    y ^= y >> 18;
    return y;
  }
  std::uint32_t mt_[624];
  std::size_t index_ = 0;
};

}  // namespace

std::vector<Point<2>> python_uniform(std::size_t n, std::uint32_t seed) {
  PythonRandom rng(seed);
  std::vector<Point<2>> pts(n);
  for (auto& p : pts) {
    p[0] = rng.random();
    p[1] = rng.random();
  }
  return pts;
}

}  // namespace dynmesh
