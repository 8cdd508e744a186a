// Micro-benchmarks of dynmesh's exact predicates (Google Benchmark; dynmesh_micro, linked
// with benchmark_main).
//
// Purpose: the cost of one orient2d / incircle call on the two paths of CGAL's filtered
// predicates: random inputs, which the floating-point filter decides, and exactly degenerate
// inputs (collinear integer triples, quadruples of lattice points on x² + y² = 1105²), whose
// exact sign is 0, so every call falls through to the exact GMP evaluation.
// Invariants: one benchmark iteration is one predicate call, so the reported time is ns per
// call; the calls cycle through 1024 precomputed cases (fixed seeds; setup excluded from
// timing), small enough to stay in cache.
// Complexity: O(1) per call.
// Paper: Shewchuk (1997); Kettner et al. (2008) for why degenerate inputs are the ones that
// matter. Figures go to bench/RESULTS.md, not here.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "dynmesh/point.hpp"
#include "dynmesh/predicates.hpp"

namespace {

using dynmesh::Point;

constexpr std::size_t kCases = 1024;  // a power of two: the index wraps with a mask

struct Triple {
  Point<2> a, b, c;
};
struct Quadruple {
  Point<2> a, b, c, d;
};

std::vector<Triple> random_triples() {
  std::mt19937_64 rng(101);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  auto point = [&] { return Point<2>{unit(rng), unit(rng)}; };
  std::vector<Triple> cases;
  for (std::size_t i = 0; i < kCases; ++i) cases.push_back({point(), point(), point()});
  return cases;
}

/// o + k·v for integers o, v and three distinct k: exactly collinear, no repeated point.
std::vector<Triple> collinear_triples() {
  std::mt19937_64 rng(102);
  std::uniform_int_distribution<int> shift(-1'000'000, 1'000'000), dir(1, 1000), step(1, 100);
  std::vector<Triple> cases;
  for (std::size_t i = 0; i < kCases; ++i) {
    const Point<2> o{double(shift(rng)), double(shift(rng))}, v{double(dir(rng)), double(-dir(rng))};
    auto at = [&](int k) { return Point<2>{o[0] + k * v[0], o[1] + k * v[1]}; };
    cases.push_back({at(0), at(step(rng)), at(-step(rng))});
  }
  return cases;
}

std::vector<Quadruple> random_quadruples() {
  std::mt19937_64 rng(103);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  auto point = [&] { return Point<2>{unit(rng), unit(rng)}; };
  std::vector<Quadruple> cases;
  for (std::size_t i = 0; i < kCases; ++i) cases.push_back({point(), point(), point(), point()});
  return cases;
}

/// Four lattice points of x² + y² = 1105² (there are 108), moved by an integer offset: exactly
/// cocircular.
std::vector<Quadruple> cocircular_quadruples() {
  constexpr std::int64_t r = 1105;
  std::vector<Point<2>> circle;
  for (std::int64_t x = -r; x <= r; ++x) {
    const auto y = std::llround(std::sqrt(double(r * r - x * x)));
    if (x * x + y * y != r * r) continue;
    circle.push_back({double(x), double(y)});
    if (y != 0) circle.push_back({double(x), double(-y)});
  }
  std::mt19937_64 rng(104);
  std::uniform_int_distribution<std::size_t> pick(0, circle.size() - 1);
  std::uniform_int_distribution<int> shift(-1'000'000, 1'000'000);
  std::vector<Quadruple> cases;
  for (std::size_t i = 0; i < kCases; ++i) {
    const Point<2> o{double(shift(rng)), double(shift(rng))};
    auto at = [&] {
      const Point<2>& p = circle[pick(rng)];
      return Point<2>{o[0] + p[0], o[1] + p[1]};
    };
    cases.push_back({at(), at(), at(), at()});
  }
  return cases;
}

void run_orient2d(benchmark::State& state, const std::vector<Triple>& cases) {
  std::size_t i = 0;
  for (auto _ : state) {
    const Triple& k = cases[i++ & (kCases - 1)];
    benchmark::DoNotOptimize(dynmesh::orient2d(k.a, k.b, k.c));
  }
  state.SetItemsProcessed(state.iterations());
}

void run_incircle(benchmark::State& state, const std::vector<Quadruple>& cases) {
  std::size_t i = 0;
  for (auto _ : state) {
    const Quadruple& k = cases[i++ & (kCases - 1)];
    benchmark::DoNotOptimize(dynmesh::incircle(k.a, k.b, k.c, k.d));
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_orient2d_random(benchmark::State& state) { run_orient2d(state, random_triples()); }
void BM_incircle_random(benchmark::State& state) { run_incircle(state, random_quadruples()); }

// The degenerate figures mean something only if every case is exactly degenerate.
void BM_orient2d_degenerate(benchmark::State& state) {
  const auto cases = collinear_triples();
  for (const Triple& k : cases)
    if (dynmesh::orient2d(k.a, k.b, k.c) != 0) return state.SkipWithError("a case is not collinear");
  run_orient2d(state, cases);
}
void BM_incircle_degenerate(benchmark::State& state) {
  const auto cases = cocircular_quadruples();
  for (const Quadruple& k : cases)
    if (dynmesh::incircle(k.a, k.b, k.c, k.d) != 0) return state.SkipWithError("a case is not cocircular");
  run_incircle(state, cases);
}

BENCHMARK(BM_orient2d_random);
BENCHMARK(BM_orient2d_degenerate);
BENCHMARK(BM_incircle_random);
BENCHMARK(BM_incircle_degenerate);

}  // namespace
