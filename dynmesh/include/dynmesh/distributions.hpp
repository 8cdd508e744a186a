// dynmesh/distributions.hpp — deterministic point generators and the spread of a point set.
//
// Purpose: the point distributions of the tests, the stability experiments (`dynmesh
// stability --dist NAME`, docs/FORMATS.md) and the benchmarks, reproducible from a seed:
//   uniform    – uniform in [0, 1)^d.
//   clusters   – Gaussian clusters of several radii (8 clusters, standard deviations from
//                1e-1 down to 1e-4 geometrically, centres uniform in [0.2, 0.8]^d).
//   spiral     – 2D: an Archimedean spiral of 4 turns around (0.5, 0.5), radius up to 0.5;
//                3D: a spherical spiral of 8 turns on the sphere of radius 0.5; stratified
//                along the curve.
//   shrinking  – a cluster that shrinks geometrically towards (0.5, ...): K octaves, octave j
//                a jittered-lattice pattern in the shell 2^-j·[0.25, 0.5] around the centre
//                (so the distances of successive octaves to the centre halve), ⌈n/K⌉ points
//                per octave. K is first estimated from n and `spread`, then corrected by the
//                measured spread (each octave doubles it), so that L/s ≈ spread independently
//                of n: |log2(L/s) − log2(spread)| ≲ 1. When n points cannot have so small a
//                spread, K = 1 gives the smallest this construction reaches, about 10·n^(1/d).
//   grid       – n distinct sites of the integer lattice {0..g−1}^d, g = ⌈n^(1/d)⌉ (exact
//                integers: aligned, cocircular and cospherical subsets abound).
//   collinear  – points exactly on one segment in a generic direction (dyadic start, direction
//                and parameters, so no coordinate is rounded), stratified along it.
//   boundary   – points whose coordinates lie exactly on cell boundaries: the set contains
//                (0,…,0) and (W,…,W) with W = kBoundaryExtent, so its derived box is
//                o = (−W,…,−W), L = 3W exactly, and every other coordinate is the boundary
//                −W + 3W·i/2^l between cells of level l (l in [2, 24]), i.e. a dyadic fraction
//                of the box. W = 593738·2^-19 is chosen so that the location rule's rounding
//                puts about half of these coordinates at q = i·2^(52−l) (the upper cell) and
//                half at q = i·2^(52−l) − 1 (the lower cell); with L = 3 all would land on
//                the upper side. This distribution exercises both.
//   curves     – points along random smooth curves, spaced much more closely along each curve
//                than the curves are apart (like contours, coastlines and scan lines):
//                max(2, round(√n/4)) Fourier-perturbed star-shaped loops of radius 0.02 to
//                0.08 (3D: in random planes, with a small out-of-plane wobble), half of them
//                cut to open arcs, centres in [0.15, 0.85]^d, every point in [0.03, 0.97]^d.
//                The points are shared out in proportion to the curves' lengths, at stratified
//                arc lengths, so the spacing is the same on every curve; the median distance
//                to the nearest other curve is some 30 to 150 times that spacing in 2D (more
//                in 3D), independently of n. curve_points gives the points curve by curve.
// Every generator returns exactly n distinct points (distinct located positions in their
// derived box, as far as the construction guarantees: exactly for grid, collinear and
// boundary; with overwhelming probability for the others) in a seeded random order.
//
// Determinism: the random source is std::mt19937_64 (its output is fixed by the standard);
// uniform doubles, bounded integers (bitmask rejection), shuffles and normal deviates
// (Box–Muller) are computed here, never by std:: distributions or std::shuffle, whose
// output differs across standard libraries. The clusters, spiral and shrinking generators
// call libm's log/pow/sin/cos, which are identical on one platform and may differ in the last bit
// across C libraries; the other generators use + − × / only (curves also the correctly rounded
// sqrt, and a rational parametrization of the circle instead of sin and cos).
//
// closest_pair_distance: expected O(n) randomized-grid algorithm (Rabin; Khuller & Matias)
// with a fixed internal seed, so the result is deterministic (it is exact in any case).
//
// Invariants: generate() output is a function of (distribution, d, n, seed, spread).
// Complexity: O(n) expected for every generator and for closest_pair_distance.
// Paper: Acar & Hudson, Section 1 (the spread L/s governs the update bound O(lg L/s)).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <random>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh {

/// The extent W of the `boundary` distribution (see above): 593738 · 2^-19 ≈ 1.1325.
inline constexpr double kBoundaryExtent = 593738.0 / 524288.0;

/// A seeded random source with library-independent transforms.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : gen_(seed) {}

  std::uint64_t bits() { return gen_(); }
  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(gen_() >> 11) * 0x1p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [0, n), n ≥ 1, unbiased (bitmask rejection).
  std::uint64_t below(std::uint64_t n);
  /// Standard normal deviate (Box–Muller; the second deviate of each pair is kept).
  double normal();

  /// Fisher–Yates with below().
  template <class T>
  void shuffle(std::vector<T>& v) {
    for (std::size_t i = v.size(); i > 1; --i) std::swap(v[i - 1], v[static_cast<std::size_t>(below(i))]);
  }

 private:
  std::mt19937_64 gen_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

enum class Distribution { Uniform, Clusters, Spiral, Shrinking, Grid, Collinear, Boundary, Curves };

std::span<const Distribution> all_distributions() noexcept;
std::string_view distribution_name(Distribution dist) noexcept;
std::optional<Distribution> parse_distribution(std::string_view name) noexcept;

/// n points of `dist` in dimension d. `spread` is the target L/s of `shrinking` (≥ 2; other
/// distributions ignore it). Throws std::invalid_argument for a bad spread.
template <std::size_t d>
std::vector<Point<d>> generate(Distribution dist, std::size_t n, std::uint64_t seed, double spread = 0x1p20);

/// The points of generate(Distribution::Curves, n, seed), curve by curve and in order along
/// each curve: generate() returns their concatenation in a seeded random order.
template <std::size_t d>
std::vector<std::vector<Point<d>>> curve_points(std::size_t n, std::uint64_t seed);

/// The peers' benchmark inputs: n points (x, y) from CPython's random.Random(seed), drawn as
/// `x = rng.random(); y = rng.random()` n times (seed 1 makes the unif1e4 / unif1e5 inputs
/// against which Triangle's and CGAL's mesh sizes are quoted). Bit-identical to CPython's
/// doubles: MT19937 seeded by init_by_array({seed}), 53-bit fractions.
std::vector<Point<2>> python_uniform(std::size_t n, std::uint32_t seed = 1);

/// The smallest distance between two of the points (+infinity for fewer than two points,
/// 0 if two are equal). Precondition: the ratio of the points' extent to that distance is
/// below 2^60 (true for any set with distinct located positions); otherwise
/// std::domain_error.
template <std::size_t d>
double closest_pair_distance(std::span<const Point<d>> points);

/// log2(L / s) with L the box side and s the closest pair distance (docs/FORMATS.md,
/// `dynmesh stability`): +infinity when s = 0, −infinity for fewer than two points.
template <std::size_t d>
double log2_spread(const Box<d>& box, std::span<const Point<d>> points);

}  // namespace dynmesh
