// dynmesh_bench — from-scratch overhead, update time, speedup and memory of the
// self-adjusting quadtree (DynamicQuadtree) against the plain static oracle
// (StaticQuadtree), for the figures of bench/RESULTS.md.
//
// Method (as sac_suite): for each n, the static build is the median of three; the
// self-adjusting build follows one untimed warm-up build (so that both sides run on memory
// the process has already touched: first-touch page zeroing on these VMs costs more than
// the computation) and is the median of `--reps` timed builds. Then U updates alternate a
// deletion of a random present point and an insertion of a fresh point of the same
// distribution; each update's propagate() time and trace distance are recorded, and the
// mean and median of each kind are reported. After the updates the tree is compared with a
// static build on the final point set (verified = 1 when equal). All ratios come from one
// process run. Output: a table, or CSV with --csv:
//   dim,dist,n,static_s,scratch_s,overhead,insert_us,delete_us,update_us,median_update_us,
//   max_update_us,speedup,mean_distance,trace_bytes,bytes_per_point,verified
// speedup = scratch_s / mean update time (against the runtime's own from-scratch run, the
// alternative an update replaces); overhead = scratch_s / static_s.
// --breakdown: after each build, where trace_bytes() goes (DynamicQuadtree::
// memory_breakdown()): count, bytes, bytes per point and share of the total for each record
// kind, side structure and directory part, then what trace_bytes() leaves out. Lines start
// with '#', so CSV readers can skip them; the block follows its size's row.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <sac/chunk_cache.hpp>

#include "bench_stats.hpp"

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace {

using namespace dynmesh;

using bench::mean;
using bench::median;
using bench::seconds;

struct Row {
  int dim = 2;
  std::string dist;
  std::size_t n = 0;
  double static_s = 0, scratch_s = 0, insert_us = 0, delete_us = 0, update_us = 0,
         median_update_us = 0, max_update_us = 0, mean_distance = 0;
  std::size_t trace_bytes = 0;
  bool verified = false;
  std::string breakdown;  // --breakdown: the block printed after the row
};

/// The breakdown block of --breakdown (see the header comment).
std::string breakdown_text(const QuadtreeMemory& m, std::size_t trace_bytes, std::size_t n, int dim) {
  std::string out;
  char line[1024];
  const double total = static_cast<double>(m.total());
  auto row = [&](const char* name, std::uint64_t count, std::size_t bytes) {
    std::snprintf(line, sizeof line, "# %-26s %12llu %14zu %10.1f %7.2f%%\n", name,
                  static_cast<unsigned long long>(count), bytes,
                  static_cast<double>(bytes) / static_cast<double>(n), 100.0 * static_cast<double>(bytes) / total);
    out += line;
  };
  std::snprintf(line, sizeof line, "# breakdown dim=%d n=%zu\n# %-26s %12s %14s %10s %8s\n", dim, n, "part",
                "count", "bytes", "B/point", "share");
  out += line;
  m.engine.for_each_part(row);
  row("base version records", m.engine.inputs.count, m.engine.inputs.header);
  row("base version values", m.engine.inputs.count, m.engine.inputs.payload);
  row("directory slots", m.slots, m.slot_bytes);
  row("directory table", m.slots, m.table_bytes);
  row("per-level list nodes", m.level_nodes, m.level_node_bytes);
  row("input list nodes", m.input_nodes, m.input_node_bytes);
  std::snprintf(line, sizeof line,
                "# total %zu B = trace_bytes() %zu B: %s (unaccounted records %lld B)\n"
                "# base versions: %llu (1 per input node + the list head = %zu; a default (Engine::init_default)"
                " makes one only when it is both read and written)\n"
                "# outside trace_bytes(): engine vectors %zu B, pool reserved %zu B (unused %zu B, %.1f B/point),"
                " large blocks %zu B, size-class rounding %zu B\n",
                m.total(), trace_bytes, m.total() == trace_bytes ? "equal" : "DIFFERENT",
                static_cast<long long>(m.engine.unaccounted), static_cast<unsigned long long>(m.engine.inputs.count),
                m.input_nodes + 1, m.engine.engine_vectors, m.engine.pool_reserved, m.engine.pool_unused(),
                static_cast<double>(m.engine.pool_unused()) / static_cast<double>(n), m.engine.pool_large,
                m.engine.size_class_rounding);
  out += line;
  out += "# the reads (records and closures) by record size, i.e. by closure type:\n";
  for (const auto& [bytes, count] : m.engine.read_sizes) {
    char name[64];
    std::snprintf(name, sizeof name, "reads of %zu B", bytes);
    row(name, count, bytes * count);
  }
  return out;
}

template <std::size_t d>
Row measure(Distribution dist, std::size_t n, std::size_t updates, int reps, std::uint64_t seed,
            bool breakdown) {
  Row row;
  row.dim = static_cast<int>(d);
  row.dist = std::string(distribution_name(dist));
  row.n = n;
  const auto pool = generate<d>(dist, n + updates, seed);
  const std::vector<Point<d>> initial(pool.begin(), pool.begin() + static_cast<std::ptrdiff_t>(n));
  const Box<d> box = derive_box<d>(pool);

  std::vector<double> st;
  for (int i = 0; i < 3; ++i)
    st.push_back(seconds([&] { auto t = StaticQuadtree<d>::from_points(box, initial); (void)t; }));
  row.static_s = median(st);

  { DynamicQuadtree<d> warm(box, initial); }
  std::vector<double> sc;
  std::optional<DynamicQuadtree<d>> tree;
  for (int i = 0; i < reps; ++i) {
    tree.reset();
    sc.push_back(seconds([&] { tree.emplace(box, initial); }));
  }
  row.scratch_s = median(sc);
  row.trace_bytes = tree->trace_bytes();
  if (breakdown) row.breakdown = breakdown_text(tree->memory_breakdown(), row.trace_bytes, n, row.dim);

  Rng rng(seed ^ 0x5eed);
  std::vector<PointId> ids;
  for (const auto& [id, p] : tree->points()) ids.push_back(id);
  std::vector<double> ins, del, all, dist_all;
  std::size_t next = n;
  for (std::size_t u = 0; u < updates; ++u) {
    if (u % 2 == 0 && !ids.empty()) {
      const std::size_t k = static_cast<std::size_t>(rng.below(ids.size()));
      tree->erase(ids[k]);
      ids[k] = ids.back();
      ids.pop_back();
      del.push_back(tree->last_update().seconds);
    } else {
      bool done = false;
      while (!done && next < pool.size()) {
        try {
          ids.push_back(tree->insert(pool[next++]));
          done = true;
        } catch (const InputError&) {  // a duplicate or a too-close point: take the next one
        }
      }
      if (!done) continue;
      ins.push_back(tree->last_update().seconds);
    }
    all.push_back(tree->last_update().seconds);
    dist_all.push_back(static_cast<double>(tree->last_update().trace_distance));
  }
  row.insert_us = mean(ins) * 1e6;
  row.delete_us = mean(del) * 1e6;
  row.update_us = mean(all) * 1e6;
  row.median_update_us = median(all) * 1e6;
  row.max_update_us = all.empty() ? 0 : *std::max_element(all.begin(), all.end()) * 1e6;
  row.mean_distance = mean(dist_all);

  const auto oracle = StaticQuadtree<d>::from_points(box, [&] {
    std::vector<Point<d>> cur;
    for (const auto& [id, p] : tree->points()) cur.push_back(p);
    return cur;
  }());
  const auto leaves = tree->leaves();
  row.verified = std::equal(leaves.begin(), leaves.end(), oracle.leaves().begin(), oracle.leaves().end());
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  // Engines are built one after another: keep their freed chunks warm, so that every
  // measurement starts alike (sac/chunk_cache.hpp; a user's default is 64 MiB).
  sac::set_chunk_cache_limit(std::size_t{1} << 30);
  CLI::App app{"dynmesh_bench: self-adjusting quadtree vs the static oracle"};
  int dim = 2;
  std::string dist_name = "uniform";
  std::vector<std::size_t> sizes{1000, 10000, 100000};
  std::size_t updates = 1000;
  int reps = 3;
  std::uint64_t seed = 1;
  bool csv = false;
  bool breakdown = false;
  app.add_option("--dim", dim, "2 or 3")->check(CLI::IsMember({2, 3}));
  app.add_option("--dist", dist_name, "point distribution");
  app.add_option("--n", sizes, "sizes (several allowed)")->delimiter(',');
  app.add_option("--updates", updates, "updates measured per size");
  app.add_option("--reps", reps, "timed from-scratch builds (median)")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed");
  app.add_flag("--csv", csv, "CSV output");
  app.add_flag("--breakdown", breakdown, "after each build, print trace_bytes() by part ('#' lines)");
  CLI11_PARSE(app, argc, argv);
  const auto dist = parse_distribution(dist_name);
  if (!dist) {
    std::fprintf(stderr, "dynmesh_bench: unknown distribution '%s'\n", dist_name.c_str());
    return 1;
  }
  if (csv)
    std::printf("dim,dist,n,static_s,scratch_s,overhead,insert_us,delete_us,update_us,"
                "median_update_us,max_update_us,speedup,mean_distance,trace_bytes,bytes_per_point,verified\n");
  else
    std::printf("%3s %-9s %8s %9s %9s %8s %9s %9s %9s %9s %9s %9s %8s %11s %8s\n", "dim", "dist",
                "n", "static_s", "scratch_s", "overhead", "insert_us", "delete_us", "update_us",
                "median_us", "max_us", "speedup", "distance", "bytes/point", "verified");
  for (std::size_t n : sizes) {
    const Row r = dim == 2 ? measure<2>(*dist, n, updates, reps, seed, breakdown)
                           : measure<3>(*dist, n, updates, reps, seed, breakdown);
    const double overhead = r.scratch_s / r.static_s;
    const double speedup = r.scratch_s / (r.update_us * 1e-6);
    const double bpp = static_cast<double>(r.trace_bytes) / static_cast<double>(r.n);
    if (csv)
      std::printf("%d,%s,%zu,%.6f,%.6f,%.3f,%.2f,%.2f,%.2f,%.2f,%.2f,%.1f,%.1f,%zu,%.1f,%d\n",
                  r.dim, r.dist.c_str(), r.n, r.static_s, r.scratch_s, overhead, r.insert_us,
                  r.delete_us, r.update_us, r.median_update_us, r.max_update_us, speedup,
                  r.mean_distance, r.trace_bytes, bpp, r.verified ? 1 : 0);
    else
      std::printf("%3d %-9s %8zu %9.4f %9.4f %8.2f %9.1f %9.1f %9.1f %9.1f %9.0f %9.0f %8.1f %11.0f %8d\n",
                  r.dim, r.dist.c_str(), r.n, r.static_s, r.scratch_s, overhead, r.insert_us,
                  r.delete_us, r.update_us, r.median_update_us, r.max_update_us, speedup,
                  r.mean_distance, bpp, r.verified ? 1 : 0);
    std::fputs(r.breakdown.c_str(), stdout);
    std::fflush(stdout);
    if (!r.verified) return 1;
  }
  return 0;
}
