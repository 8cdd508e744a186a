// dynmesh_soak — a long run of single-point updates on DynamicQuadtree<2> or <3>: does the
// tree stay equal to a from-scratch build, and does its memory stay flat, after 10^6
// updates? Figures in bench/RESULTS.md.
//
// Method: n initial points of the first distribution in a fixed box [-0.5, 1.5)^d (every
// generator below draws inside [0, 1]^d or close to it). Then --updates single-point updates
// alternate, as dynmesh_bench and dynmesh/tools/update_driver.hpp do, the deletion of a
// present point chosen uniformly and the insertion of the next point of an insertion pool;
// a pool point the tree rejects (outside the box, a duplicate, too close: InputError) is
// skipped, the tree being unchanged. The pool's distribution cycles through --dists, one
// --segment of updates each, so the point set turns over from one distribution to the next
// (with the defaults a segment replaces nearly all the points, and the cycle runs twice, so
// the middle and the end of the run are on the same distribution and clusters).
// Every distribution's pool is generated before the run, so the samples measure the tree.
//
// Every --check-every updates and at the end: RSS is sampled (VmRSS, VmHWM), then the tree
// is compared with the static oracle built from scratch on the present points (leaves()
// exactly) and check_invariants() runs; each failure counts as a mismatch. After the last
// check the tree is destroyed and a fresh DynamicQuadtree is built on the final points:
// its live events and record bytes must equal the soaked tree's (docs/DESIGN.md, "The correctness
// contract": the live trace is the size of a from-scratch run's). Any mismatch makes the exit status 1.
//
// compact() is not called: the tree compacts its cell directory itself whenever the
// directory has doubled since the last compaction, and a user would not call it. With
// --compact it is called before every sample, to show the slack between two automatic
// compactions (dir_slots and RSS with and without).
//
// Output: one CSV line per check (after a '#' header line), then a summary. Times: `update`
// is the mean wall time of propagate() (last_update().seconds, as dynmesh_bench reports);
// `call` the wall time of the whole insert/erase call (validation, linking, propagate,
// release, automatic compaction); the median comes from a 1-µs histogram of propagate().
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench_stats.hpp"

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace {

using namespace dynmesh;
using Clock = std::chrono::steady_clock;

struct Memory {
  double rss_mb = 0, hwm_mb = 0;
};

/// VmRSS and VmHWM of this process, in MiB (0 if /proc is unavailable).
Memory read_memory() {
  Memory m;
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    std::istringstream fields(line);
    std::string key;
    double kb = 0;
    fields >> key >> kb;
    if (key == "VmRSS:") m.rss_mb = kb / 1024;
    if (key == "VmHWM:") m.hwm_mb = kb / 1024;
  }
  return m;
}

/// Counts of update times in 1-µs bins (the last bin takes everything slower), for an exact
/// median to 1 µs without storing 10^6 samples (which would itself grow RSS).
class Histogram {
 public:
  void add(double seconds) {
    const auto us = static_cast<std::size_t>(seconds * 1e6);
    ++bins_[std::min(us, bins_.size() - 1)];
    ++count_;
  }
  double median_us() const {
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < bins_.size(); ++i)
      if ((seen += bins_[i]) * 2 >= count_ && count_ > 0) return static_cast<double>(i) + 0.5;
    return 0;
  }

 private:
  std::vector<std::uint64_t> bins_ = std::vector<std::uint64_t>(100001, 0);
  std::uint64_t count_ = 0;
};

/// The insertion points of one distribution, generated before the run; refilled with a new
/// seed in the unlikely case that rejections exhaust it.
template <std::size_t d>
class Pool {
 public:
  Pool(Distribution dist, std::size_t size, std::uint64_t seed)
      : dist_(dist), size_(size), seed_(seed), points_(generate<d>(dist, size, seed)) {}
  Point<d> next() {
    if (next_ == points_.size()) {
      points_ = generate<d>(dist_, size_, seed_ + 0x9e37'79b9'7f4a'7c15ULL * ++refills_);
      next_ = 0;
    }
    return points_[next_++];
  }

 private:
  Distribution dist_;
  std::size_t size_;
  std::uint64_t seed_;
  std::vector<Point<d>> points_;
  std::size_t next_ = 0;
  std::uint64_t refills_ = 0;
};

struct Options {
  std::size_t n = 10000;
  std::size_t updates = 1000000;
  std::size_t check_every = 10000;
  std::size_t segment = 125000;
  std::vector<Distribution> dists;
  std::uint64_t seed = 1;
  bool compact = false;
};

struct Sample {
  std::size_t updates = 0;
  double rss_mb = 0;
};

template <std::size_t d>
int soak(const Options& opt) {
  Box<d> box;
  box.origin.fill(-0.5);
  box.side = 2.0;

  // Pools first (their memory is in the baseline sample): each distribution gets the
  // insertions of its segments, plus a margin for rejected points.
  std::vector<Pool<d>> pools;
  for (std::size_t k = 0; k < opt.dists.size(); ++k) {
    std::size_t inserts = 0;
    for (std::size_t start = k * opt.segment; start < opt.updates; start += opt.dists.size() * opt.segment)
      inserts += (std::min(opt.segment, opt.updates - start) + 1) / 2;
    pools.emplace_back(opt.dists[k], inserts + inserts / 100 + 64, opt.seed + 1 + k);
  }
  std::vector<Point<d>> initial;
  for (const Point<d>& p : generate<d>(opt.dists[0], opt.n, opt.seed))
    if (try_locate(box, p)) initial.push_back(p);

  std::optional<DynamicQuadtree<d>> tree;
  const double build_s = bench::seconds([&] { tree.emplace(box, initial); });
  std::vector<PointId> ids;
  for (const auto& [id, p] : tree->points()) ids.push_back(id);
  Rng rng(opt.seed ^ 0x50a6'0000'0000'0000ULL);

  std::printf("# dynmesh_soak dim=%zu n=%zu updates=%zu check_every=%zu segment=%zu seed=%llu "
              "box=[-0.5,1.5)^%zu compact=%s dists=",
              d, initial.size(), opt.updates, opt.check_every, opt.segment,
              static_cast<unsigned long long>(opt.seed), d, opt.compact ? "yes" : "no");
  for (std::size_t k = 0; k < opt.dists.size(); ++k)
    std::printf("%s%s", k ? "," : "", std::string(distribution_name(opt.dists[k])).c_str());
  std::printf("\n# build_s=%.3f\n", build_s);
  std::printf("updates,elapsed_s,update_phase_s,check_s,rss_mb,hwm_mb,trace_mb,live_events,dir_slots,"
              "present,dist,window_update_us,mismatches\n");

  std::size_t mismatches = 0, rejected = 0;
  double update_s = 0, call_s = 0, check_s = 0, window_s = 0, max_s = 0;
  std::size_t window_n = 0;
  Histogram histogram;
  std::vector<Sample> samples;
  const auto t0 = Clock::now();

  const auto check = [&](std::size_t done, Distribution dist) {
    const auto c0 = Clock::now();
    if (opt.compact) tree->compact();
    const Memory mem = read_memory();  // before the oracle's build allocates
    samples.push_back({done, mem.rss_mb});
    std::vector<Point<d>> present;
    present.reserve(tree->size());
    for (const auto& [id, p] : tree->points()) present.push_back(p);
    try {
      const auto oracle = StaticQuadtree<d>::from_points(box, present);
      const auto leaves = tree->leaves();
      if (!std::equal(leaves.begin(), leaves.end(), oracle.leaves().begin(), oracle.leaves().end())) {
        ++mismatches;
        std::fprintf(stderr, "dynmesh_soak: after %zu updates the leaves differ from the oracle's\n", done);
      }
      tree->check_invariants();
    } catch (const std::exception& e) {
      ++mismatches;
      std::fprintf(stderr, "dynmesh_soak: after %zu updates: %s\n", done, e.what());
    }
    check_s += std::chrono::duration<double>(Clock::now() - c0).count();
    const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
    std::printf("%zu,%.1f,%.1f,%.1f,%.1f,%.1f,%.1f,%llu,%zu,%zu,%s,%.1f,%zu\n", done, elapsed, call_s,
                check_s, mem.rss_mb, mem.hwm_mb, static_cast<double>(tree->trace_bytes()) / (1 << 20),
                static_cast<unsigned long long>(tree->live_events()), tree->directory_size(), tree->size(),
                std::string(distribution_name(dist)).c_str(), window_n ? window_s / static_cast<double>(window_n) * 1e6 : 0.0,
                mismatches);
    std::fflush(stdout);
    window_s = 0;
    window_n = 0;
  };

  check(0, opt.dists[0]);
  std::size_t done = 0;
  for (std::size_t u = 0; u < opt.updates; ++u) {
    const std::size_t k = (u / opt.segment) % opt.dists.size();
    const auto c0 = Clock::now();
    if (u % 2 == 0 && ids.size() > 2) {
      const auto j = static_cast<std::size_t>(rng.below(ids.size()));
      tree->erase(ids[j]);
      ids[j] = ids.back();
      ids.pop_back();
    } else {
      for (;;) {
        try {
          ids.push_back(tree->insert(pools[k].next()));
          break;
        } catch (const InputError&) {  // outside the box, a duplicate, too close: the next one
          ++rejected;
        }
      }
    }
    call_s += std::chrono::duration<double>(Clock::now() - c0).count();
    const double s = tree->last_update().seconds;
    update_s += s;
    window_s += s;
    ++window_n;
    max_s = std::max(max_s, s);
    histogram.add(s);
    done = u + 1;
    if (done % opt.check_every == 0 || done == opt.updates) check(done, opt.dists[k]);
  }
  const double total_s = std::chrono::duration<double>(Clock::now() - t0).count();

  // Trace size against a fresh build on the final points (the soaked tree is destroyed
  // first, so the peak RSS stays that of one tree).
  std::vector<Point<d>> final_points;
  for (const auto& [id, p] : tree->points()) final_points.push_back(p);
  const auto soaked_events = tree->live_events();
  const auto soaked_records = tree->record_bytes();
  const auto soaked_bytes = tree->trace_bytes();
  tree.reset();
  const DynamicQuadtree<d> fresh(box, final_points);
  const bool same_trace = fresh.live_events() == soaked_events && fresh.record_bytes() == soaked_records;
  if (!same_trace) ++mismatches;

  // The memory plateau: the first samples at or after 10% and 50% of the run, and the last.
  const auto rss_at = [&](double fraction) {
    for (const Sample& s : samples)
      if (static_cast<double>(s.updates) >= fraction * static_cast<double>(opt.updates)) return s;
    return samples.back();
  };
  const Sample s10 = rss_at(0.1), s50 = rss_at(0.5), s100 = samples.back();
  const Memory end = read_memory();
  std::printf("# total_s=%.1f update_phase_s=%.1f check_s=%.1f rejected=%zu\n", total_s, call_s, check_s, rejected);
  std::printf("# update_us mean=%.1f median=%.1f max=%.0f call_us mean=%.1f\n",
              update_s / static_cast<double>(done) * 1e6, histogram.median_us(), max_s * 1e6,
              call_s / static_cast<double>(done) * 1e6);
  std::printf("# rss_mb at_%zu=%.1f at_%zu=%.1f at_%zu=%.1f end_over_50pct=%.3f peak_hwm_mb=%.1f\n",
              s10.updates, s10.rss_mb, s50.updates, s50.rss_mb, s100.updates, s100.rss_mb,
              s50.rss_mb > 0 ? s100.rss_mb / s50.rss_mb : 0.0, end.hwm_mb);
  std::printf("# trace vs fresh build: live_events %llu / %llu, record_bytes %zu / %zu, trace_bytes %zu / %zu: %s\n",
              static_cast<unsigned long long>(soaked_events), static_cast<unsigned long long>(fresh.live_events()),
              soaked_records, fresh.record_bytes(), soaked_bytes, fresh.trace_bytes(),
              same_trace ? "same" : "DIFFERENT");
  std::printf("# mismatches=%zu\n", mismatches);
  return mismatches == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynmesh_soak: 10^6 single-point updates against the static oracle, with memory samples"};
  int dim = 2;
  Options opt;
  std::vector<std::string> dist_names{"uniform", "clusters", "spiral", "shrinking"};
  app.add_option("--dim", dim, "2 or 3")->check(CLI::IsMember({2, 3}));
  app.add_option("--n", opt.n, "initial points (of the first distribution)")->check(CLI::PositiveNumber);
  app.add_option("--updates", opt.updates, "single-point updates")->check(CLI::PositiveNumber);
  app.add_option("--check-every", opt.check_every, "updates between oracle checks and RSS samples")
      ->check(CLI::PositiveNumber);
  app.add_option("--segment", opt.segment, "updates before the pool moves to the next distribution")
      ->check(CLI::PositiveNumber);
  app.add_option("--dists", dist_names, "insertion distributions, cycled")->delimiter(',');
  app.add_option("--seed", opt.seed, "seed");
  app.add_flag("--compact", opt.compact, "call compact() before every sample (a user would not)");
  CLI11_PARSE(app, argc, argv);
  for (const std::string& name : dist_names) {
    const auto dist = parse_distribution(name);
    if (!dist) {
      std::fprintf(stderr, "dynmesh_soak: unknown distribution '%s'\n", name.c_str());
      return 2;
    }
    opt.dists.push_back(*dist);
  }
  if (opt.dists.empty()) {
    std::fprintf(stderr, "dynmesh_soak: --dists is empty\n");
    return 2;
  }
  try {
    return dim == 2 ? soak<2>(opt) : soak<3>(opt);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dynmesh_soak: %s\n", e.what());
    return 1;
  }
}
