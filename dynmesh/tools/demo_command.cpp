// `dynmesh demo`: the README's main job, with an embedded input (no files needed). Builds the
// dynamic quadtree on N points of the `clusters` distribution (fixed seed), applies U
// single-point updates (alternating deletions and insertions, one propagation each), prints
// the figures (led by the speedup of an update over a static rebuild), verifies the final
// tree against a from-scratch static build and the checkers, and draws the final tree.
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include "commands.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/svg.hpp"
#include "progress.hpp"
#include "update_driver.hpp"
#include "verify.hpp"

namespace dynmesh::tool {
namespace {

template <class T>
double median(std::vector<T> v) {
  if (v.empty()) return 0.0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double hi = static_cast<double>(v[mid]);
  if (v.size() % 2) return hi;
  const double lo = static_cast<double>(*std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
  return (lo + hi) / 2;
}

template <class T>
double mean(const std::vector<T>& v) {
  double s = 0;
  for (const T& x : v) s += static_cast<double>(x);
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

}  // namespace

int run_demo(const DemoOptions& o) {
  constexpr Distribution kDist = Distribution::Clusters;
  if (o.n < 2) throw InputError(InputError::Kind::Count, "--n must be at least 2");

  std::vector<Point<2>> initial = generate<2>(kDist, o.n + o.updates, o.seed);
  std::vector<Point<2>> pool(initial.begin() + static_cast<std::ptrdiff_t>(o.n), initial.end());
  initial.resize(o.n);
  const Box<2> box = derive_box<2>(initial);

  const auto t0 = std::chrono::steady_clock::now();
  DynamicQuadtree<2> tree(box, std::span<const Point<2>>(initial));
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  UpdateDriver<2> driver(tree, std::move(pool), o.seed);
  const double spread = driver.log2_spread();
  std::vector<double> seconds;
  std::vector<std::uint64_t> distances;
  std::size_t deletions = 0;
  {
    Progress progress("updates", o.updates);
    for (std::size_t u = 0; u < o.updates; ++u) {
      const auto step = driver.step();
      seconds.push_back(step.stats.seconds);
      distances.push_back(step.stats.trace_distance);
      deletions += step.op == EditOp::Delete;
      progress.tick(u + 1);
    }
  }

  const Verification v = verify<2>(tree);
  const std::vector<Leaf<2>> leaves = tree.leaves();
  if (!o.svg.empty()) {
    const std::vector<Point<2>> pts = driver.coordinates();
    write_svg_file(o.svg, box, leaves, pts);
  }

  const double mean_s = mean(seconds);
  std::printf("dynmesh demo: a well-graded quadtree kept up to date by change propagation\n");
  // The headline: what an update saves over the alternative, rebuilding the tree statically
  // (the self-adjusting build, slower than the static one, would flatter the ratio).
  if (o.updates > 0 && mean_s > 0)
    std::printf("  speedup            %.0fx: an update vs a static rebuild (%.3f s static build / %.1f us mean "
                "update)\n",
                v.static_seconds / mean_s, v.static_seconds, mean_s * 1e6);
  std::printf("  points             %zu (clusters distribution, 2D, seed %llu), log2(L/s) = %.1f\n", o.n,
              static_cast<unsigned long long>(o.seed), spread);
  std::printf("  leaves             %zu\n", leaves.size());
  std::printf("  split cells        %zu\n", tree.num_split());
  std::printf("  build              %.3f s self-adjusting, %.3f s static oracle\n", build_s, v.static_seconds);
  std::printf("  updates            %zu (%zu deletions, %zu insertions), one propagation each\n", o.updates,
              deletions, o.updates - deletions);
  if (o.updates > 0) {
    std::printf("  update time        mean %.1f us, median %.1f us\n", mean_s * 1e6, median(seconds) * 1e6);
    std::printf("  trace distance     mean %.0f, median %.0f per update\n", mean(distances), median(distances));
    if (mean_s > 0)
      std::printf("  vs own build       %.0fx (self-adjusting build / mean update)\n", build_s / mean_s);
  }
  std::printf("  live trace         %.0f bytes per point\n",
              static_cast<double>(tree.trace_bytes()) / static_cast<double>(std::max<std::size_t>(1, tree.size())));
  if (v.ok)
    std::printf("verified: yes (tree invariants hold; equal to a from-scratch build on the final %zu points)\n",
                tree.size());
  else
    std::printf("verified: no\n");
  if (!o.svg.empty()) std::printf("picture: %s\n", o.svg.c_str());
  std::fflush(stdout);
  if (!v.ok) throw InvariantError("verification failed: " + v.problem);
  return 0;
}

}  // namespace dynmesh::tool
