// dynmesh_mpi_bench — the figures of docs/DISTRIBUTED.md and bench/RESULTS.md for the
// quadtree on MPI ranks (run it under mpiexec; every figure is measured in one run):
//   mpiexec -np P dynmesh_mpi_bench [--dim 2|3] [--n N] [--per-rank] [--batches B] [--batch K]
//                                   [--seed X] [--plain]
// Builds T* of N uniform points (N per rank with --per-rank: weak scaling) with MpiQuadtree,
// then applies B batches of K scattered single-point edits (alternately the deletion of a
// random present point and the insertion of a new uniform point), and prints one CSV line
// from rank 0:
//   ranks,dim,n,l0,build_s,batch_s,prop_s,prop_cpu_s,edits_per_s,max_owned,ghost_fraction,max_rss_mib,rss_per_rank_mib
// batch_s is the mean wall time of a batch (apply() between barriers); prop_s the largest
// over the ranks of the mean local propagation alone (DynamicQuadtree::apply), prop_cpu_s the
// same in CPU time (what it costs on a core of its own: the ranks here share 2 cores with
// other work); ghost_fraction is the
// ghost points of all ranks over n; rss_per_rank_mib lists each rank's peak RSS.
// --plain (one process only) builds a DynamicQuadtree instead: the one-process baseline.
// Setup (drawing points and edits) is excluded from the times.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <mpi.h>

#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/mpi_quadtree.hpp"

namespace {

using namespace dynmesh;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // KiB on Linux
}

template <std::size_t d>
int run(int dim, std::size_t n, bool per_rank, std::size_t batches, std::size_t k, std::uint64_t seed, bool plain) {
  int rank = 0, nranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &nranks);
  const std::size_t total = per_rank ? n * static_cast<std::size_t>(nranks) : n;
  // Every rank draws the same points and edits; rank r passes its contiguous share.
  std::vector<Point<d>> all = generate<d>(Distribution::Uniform, total + batches * k, seed);
  std::vector<Point<d>> points(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(total));
  std::vector<Point<d>> fresh(all.begin() + static_cast<std::ptrdiff_t>(total), all.end());
  all.clear();
  all.shrink_to_fit();
  const Box<d> box{{}, 1.0};  // uniform points lie in [0, 1)^d
  std::vector<std::vector<Edit<d>>> script(batches);
  {
    Rng rng(seed + 99);
    std::vector<Point<d>> present = points;
    std::size_t next = 0;
    for (auto& batch : script)
      for (std::size_t i = 0; i < k; ++i) {
        if (i % 2 == 0) {
          const std::size_t j = static_cast<std::size_t>(rng.below(present.size()));
          batch.push_back(Edit<d>{EditOp::Delete, present[j]});
          present[j] = present.back();
          present.pop_back();
        } else {
          batch.push_back(Edit<d>{EditOp::Insert, fresh[next]});
          present.push_back(fresh[next++]);
        }
      }
  }
  fresh.clear();
  fresh.shrink_to_fit();
  auto share = [&](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    const std::size_t lo = v.size() * static_cast<std::size_t>(rank) / static_cast<std::size_t>(nranks);
    const std::size_t hi = v.size() * static_cast<std::size_t>(rank + 1) / static_cast<std::size_t>(nranks);
    return std::span<const T>(v).subspan(lo, hi - lo);
  };

  double build_s = 0, batch_s = 0, prop_s = 0, prop_cpu_s = 0;
  int l0 = -1;
  std::size_t owned = total, ghosts = 0;
  MPI_Barrier(MPI_COMM_WORLD);
  if (plain) {
    auto t0 = Clock::now();
    DynamicQuadtree<d> tree(box, points);
    build_s = seconds_since(t0);
    points.clear();
    points.shrink_to_fit();
    t0 = Clock::now();
    for (const auto& batch : script) tree.apply(batch);
    batch_s = seconds_since(t0) / static_cast<double>(std::max<std::size_t>(1, batches));
    prop_s = batch_s;
    prop_cpu_s = -1;  // not measured
  } else {
    std::optional<MpiQuadtree<d>> tree;
    auto t0 = Clock::now();
    tree.emplace(MPI_COMM_WORLD, box, share(points));
    MPI_Barrier(MPI_COMM_WORLD);
    build_s = seconds_since(t0);
    points.clear();
    points.shrink_to_fit();
    MPI_Barrier(MPI_COMM_WORLD);
    t0 = Clock::now();
    for (const auto& batch : script) tree->apply(share(batch));
    MPI_Barrier(MPI_COMM_WORLD);
    batch_s = seconds_since(t0) / static_cast<double>(std::max<std::size_t>(1, batches));
    const MpiRankStats st = tree->rank_stats();
    owned = st.owned_points;
    const double mine_prop = st.propagations ? st.propagate_seconds / static_cast<double>(st.propagations) : 0.0;
    MPI_Allreduce(&mine_prop, &prop_s, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    const double mine_cpu = st.propagations ? st.propagate_cpu_seconds / static_cast<double>(st.propagations) : 0.0;
    MPI_Allreduce(&mine_cpu, &prop_cpu_s, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    ghosts = st.ghost_points;
    l0 = tree->partition_level();
  }
  unsigned long mine[2] = {owned, ghosts}, most = 0, ghost_sum = 0;
  MPI_Reduce(&mine[0], &most, 1, MPI_UNSIGNED_LONG, MPI_MAX, 0, MPI_COMM_WORLD);
  MPI_Reduce(&mine[1], &ghost_sum, 1, MPI_UNSIGNED_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
  const double rss = peak_rss_mib();
  std::vector<double> rss_all(static_cast<std::size_t>(nranks));
  MPI_Gather(&rss, 1, MPI_DOUBLE, rss_all.data(), 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (rank == 0) {
    std::string per;
    for (const double r : rss_all) per += (per.empty() ? "" : " ") + std::to_string(static_cast<long>(r));
    std::printf("ranks,dim,n,l0,build_s,batch_s,prop_s,prop_cpu_s,edits_per_s,max_owned,ghost_fraction,max_rss_mib,rss_per_rank_mib\n");
    std::printf("%d,%d,%zu,%d,%.3f,%.4f,%.4f,%.4f,%.0f,%lu,%.4f,%.0f,%s\n", plain ? 0 : nranks, dim, total, l0, build_s,
                batch_s, prop_s, prop_cpu_s,
                static_cast<double>(k) / batch_s, most, static_cast<double>(ghost_sum) / static_cast<double>(total),
                *std::max_element(rss_all.begin(), rss_all.end()), per.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  CLI::App app{"dynmesh_mpi_bench: the quadtree on MPI ranks, memory and throughput"};
  int dim = 2;
  std::size_t n = 100000, batches = 20, k = 1000;
  std::uint64_t seed = 1;
  bool per_rank = false, plain = false;
  app.add_option("--dim", dim)->check(CLI::IsMember({2, 3}));
  app.add_option("--n", n, "points (per rank with --per-rank)");
  app.add_flag("--per-rank", per_rank, "N points per rank (weak scaling)");
  app.add_option("--batches", batches);
  app.add_option("--batch", k, "edits per batch");
  app.add_option("--seed", seed);
  app.add_flag("--plain", plain, "one process: a DynamicQuadtree, the baseline");
  int status = 0;
  try {
    app.parse(argc, argv);
    status = dim == 3 ? run<3>(dim, n, per_rank, batches, k, seed, plain) : run<2>(dim, n, per_rank, batches, k, seed, plain);
  } catch (const CLI::ParseError& e) {
    status = app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dynmesh_mpi_bench: %s\n", e.what());
    status = 1;
  }
  MPI_Finalize();
  return status;
}
