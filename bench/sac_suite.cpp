// sac_suite — the classic self-adjusting benchmark suite (docs/FORMATS.md, "sac_suite").
//
// For each app: time the conventional twin and the self-adjusting from-scratch run on the
// same input, each the median of three runs (the latter after one untimed warm-up run on a
// clone of the input,
// so that both sides run on memory the process has already touched: on these VMs the
// kernel's first-touch zeroing costs more than the computation itself), then at U positions
// spread over the input delete the element and propagate, reinsert it and propagate;
// update_s is the mean over the 2U propagations. Every output is verified against the
// conventional result after the from-scratch run and after every propagation (in a second,
// identical, untimed pass). Ratios come from one process run.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <sac/chunk_cache.hpp>

#include "sacapps/app.hpp"

namespace {

using Clock = std::chrono::steady_clock;

template <class F>
double seconds(F&& f) {
  auto t0 = Clock::now();
  f();
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct Row {
  std::string app;
  std::size_t n = 0;
  double conv_s = 0, scratch_s = 0, overhead = 0, update_s = 0, speedup = 0;
  std::size_t trace_bytes = 0;
  double bytes_per_elem = 0;
  bool verified = true;
  double mean_distance = 0;
};

Row run_app(const std::string& name, std::size_t n, std::size_t updates, std::uint64_t seed) {
  Row row;
  row.app = name;
  row.n = n;
  auto app = sacapps::make_app(name);
  app->generate(n, seed);

  // The conventional run as the self-adjusting one below: one untimed warm-up, and every
  // run starts with the previous result freed, so that neither side pays fresh pages and
  // the figures do not depend on the order of the apps.
  app->run_conventional();
  std::vector<double> conv;
  for (int i = 0; i < 3; ++i) {
    app->release_conventional();
    conv.push_back(seconds([&] { app->run_conventional(); }));
  }
  std::sort(conv.begin(), conv.end());
  row.conv_s = conv[1];

  // From scratch: two untimed warm-ups on clones, two timed runs on clones, and the timed run
  // of the app itself whose trace the updates then use; the median of the three is reported.
  // The first app of a process needs both warm-ups: after one, its first timed run still
  // met cold pages (map at 10^6: 0.088 s against 0.056 s), and so does the app's own run,
  // whose engine was made before any chunk was cached.
  for (int i = 0; i < 2; ++i) {
    auto warm = app->clone_current();
    warm->run_self_adjusting();
  }
  std::vector<double> scratch;
  for (int i = 0; i < 2; ++i) {
    auto clone = app->clone_current();
    scratch.push_back(seconds([&] { clone->run_self_adjusting(); }));
  }
  scratch.push_back(seconds([&] { app->run_self_adjusting(); }));
  std::sort(scratch.begin(), scratch.end());
  row.scratch_s = scratch[1];
  row.trace_bytes = app->engine().trace_bytes();
  row.bytes_per_elem = n ? static_cast<double>(row.trace_bytes) / static_cast<double>(n) : 0.0;
  row.verified = app->verify();

  // The 2U propagations are run twice: once timed, back to back as in the usual protocol,
  // then once more, untimed, verifying the output after every propagation. Each
  // delete+reinsert pair restores the input, so both passes perform the same propagations;
  // verifying inside the timed pass would instead time how fast a propagation recovers from
  // the O(n) verification flushing the caches.
  const std::size_t positions = app->positions();
  const std::size_t u = std::min(updates, positions);
  double total = 0;
  std::uint64_t distance = 0;
  std::size_t count = 0;
  for (int pass = 0; pass < 2; ++pass) {
    const bool timed = pass == 0;
    for (std::size_t k = 0; k < u; ++k) {
      const std::size_t i = ((2 * k + 1) * positions) / (2 * u);
      if (!app->present(i)) continue;
      for (int step = 0; step < 2; ++step) {
        if (step == 0) app->remove(i);
        else app->reinsert(i);
        const double t = seconds([&] { app->engine().propagate(); });
        if (timed) {
          total += t;
          distance += app->engine().stats().last_trace_distance;
          ++count;
        } else {
          row.verified = row.verified && app->verify();
        }
      }
    }
  }
  row.update_s = count ? total / static_cast<double>(count) : 0.0;
  row.mean_distance = count ? static_cast<double>(distance) / static_cast<double>(count) : 0.0;
  row.overhead = row.conv_s > 0 ? row.scratch_s / row.conv_s : 0.0;
  row.speedup = row.update_s > 0 ? row.conv_s / row.update_s : 0.0;
  return row;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  // Engines are built one after another: keep their freed chunks warm (sac/chunk_cache.hpp),
  // so that an engine's run does not pay for fresh pages of memory its predecessor freed.
  sac::set_chunk_cache_limit(std::size_t{1} << 30);
  CLI::App cli{"sac_suite: the classic self-adjusting computation benchmarks"};
  std::string apps_arg;
  std::size_t n = 100000;
  std::size_t updates = 100;
  std::uint64_t seed = 1;
  bool csv = false;
  cli.add_option("--apps", apps_arg, "comma-separated apps (default: all)");
  cli.add_option("--n", n, "input size")->check(CLI::NonNegativeNumber);
  cli.add_option("--updates", updates, "positions updated (delete+reinsert each)");
  cli.add_option("--seed", seed, "input seed");
  cli.add_flag("--csv", csv, "print CSV instead of a table");
  CLI11_PARSE(cli, argc, argv);

  std::vector<std::string> apps = apps_arg.empty() ? sacapps::app_names() : split(apps_arg);
  for (const auto& a : apps)
    if (!sacapps::make_app(a)) {
      std::cerr << "sac_suite: unknown app '" << a << "'\n";
      return 2;
    }

  if (csv)
    std::printf("app,n,conv_s,scratch_s,overhead,update_s,speedup,trace_bytes,bytes_per_elem,verified\n");
  else
    std::printf("%-10s %9s %10s %10s %9s %11s %10s %12s %9s %9s %4s\n", "app", "n", "conv_s",
                "scratch_s", "overhead", "update_s", "speedup", "trace_bytes", "B/elem",
                "distance", "ok");
  bool all_ok = true;
  for (const auto& a : apps) {
    Row r = run_app(a, n, updates, seed);
    all_ok = all_ok && r.verified;
    if (csv)
      std::printf("%s,%zu,%.6g,%.6g,%.4g,%.6g,%.6g,%zu,%.4g,%d\n", r.app.c_str(), r.n, r.conv_s,
                  r.scratch_s, r.overhead, r.update_s, r.speedup, r.trace_bytes,
                  r.bytes_per_elem, r.verified ? 1 : 0);
    else
      std::printf("%-10s %9zu %10.4g %10.4g %9.3g %11.4g %10.4g %12zu %9.1f %9.1f %4s\n",
                  r.app.c_str(), r.n, r.conv_s, r.scratch_s, r.overhead, r.update_s, r.speedup,
                  r.trace_bytes, r.bytes_per_elem, r.mean_distance, r.verified ? "yes" : "NO");
    std::fflush(stdout);
  }
  return all_ok ? 0 : 1;
}
