// dynmesh_hpu_steps — where the self-adjusting hpu mesh's work goes, step by step
// (src/hpu/hpu_cells_program.hpp on its own engine, without the quadtree).
//
// Method: for each (distribution, n), build the program on generate(dist, n, seed) in its
// derived box; then U times delete a point drawn with the seed and insert it back, one
// propagation each. Prints, from scratch: events, record bytes per input point, completed
// steps per input point by kind (first class, collect, try, insert, final), rounds of reads
// per step and cells per round; per update: the mean and median trace distance, the mean
// update time, and the mean steps re-run by kind and rounds. With --verify the final mesh is
// compared with HpuMesh's. Flat in n is the goal for every per-update column. With --tail K,
// the K costliest propagations of each row follow it: the operation, the trace distance, the
// events created, the reads re-executed, and the steps re-run by kind. An update that creates
// far more events than its steps explain has re-run a list pass. --breakdown prints where
// the trace's bytes go after each build; --engine-stats the engine's counters (sac::Stats)
// after each series; --search-stats what the steps' searches asked and read, per input point
// from scratch and per update: left searches and leaves read (counters the program keeps
// anyway: counting more inside the view's leaf loop would slow every search). --points FILE
// measures a point file instead (its one row is named after the file, n is its size; --box
// sets the box, else it is derived from the points), with the same delete-insert updates.
//
//   dynmesh_hpu_steps [--dist spiral,curves,uniform] [--n 1000,4000,16000] [--updates 20]
//                     [--seed 1] [--angle 20.7] [--verify] [--tail K] [--breakdown] [--engine-stats]
//                     [--search-stats] [--points FILE [--box o1 o2 L]]
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench_stats.hpp"

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/io.hpp"
#include "hpu/hpu_cells_program.hpp"
#include "hpu/hpu_cells_state.hpp"

namespace {

using namespace dynmesh;
using detail::HcStepCounts;

struct Run {
  Run(const Box<2>& box, const std::vector<Point<2>>& pts, double angle)
      : state(box), program(engine, state, angle) {
    state.start(engine);
    apply(pts, {});
    engine.set_context(&program);
    state.feed.set_logging(false);  // as DynamicMesh: a build logs no change
    engine.run([](sac::Engine& rt) { detail::HpuCellsProgram::main(rt); });
    state.feed.set_logging(true);
  }
  ~Run() { state.feed.close(); }
  void apply(const std::vector<Point<2>>& ins, const std::vector<Point<2>>& del) {
    std::vector<Edit<2>> edits;
    for (const auto& p : del) edits.push_back({EditOp::Delete, p});
    for (const auto& p : ins) edits.push_back({EditOp::Insert, p});
    state.commit(engine, state.plan(edits));
  }
  void update(const std::vector<Point<2>>& ins, const std::vector<Point<2>>& del) {
    apply(ins, del);
    engine.propagate();
    state.release(engine);
    (void)state.feed.take_change();
  }

  detail::HpuCellsState state;  // before the engine: outlives it
  sac::Engine engine;
  detail::HpuCellsProgram program;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Where the self-adjusting hpu mesh's work goes, step by step"};
  std::vector<std::string> dists{"spiral", "curves", "uniform"};
  std::vector<std::size_t> sizes{1000, 4000, 16000};
  int updates = 20;
  std::uint64_t seed = 1;
  double angle = kHpuDefaultMinAngle;
  bool verify = false;
  bool breakdown = false;
  bool engine_stats = false;
  bool search_stats = false;
  std::size_t tail = 0;
  std::string points_file;
  std::vector<double> box_args;
  auto* points_opt = app.add_option("--points", points_file, "measure this point file instead of the distributions");
  app.add_option("--box", box_args, "with --points: the box, origin and side (default: derived)")
      ->expected(3)
      ->needs(points_opt);
  app.add_option("--dist", dists, "distributions, comma-separated")->delimiter(',');
  app.add_option("--n", sizes, "sizes, comma-separated")->delimiter(',');
  app.add_option("--updates", updates, "delete-insert pairs measured");
  app.add_option("--seed", seed, "random seed");
  app.add_option("--angle", angle, "angle bound");
  app.add_flag("--verify", verify, "compare the final mesh with HpuMesh's");
  app.add_option("--tail", tail, "after each row, print its K costliest propagations (by trace distance)");
  app.add_flag("--engine-stats", engine_stats, "after each series, print the engine's counters (sac::Stats)");
  app.add_flag("--search-stats", search_stats,
               "after each series, print the left searches and leaves read, per point from scratch and per update");
  app.add_flag("--breakdown", breakdown, "after each build, print where the trace's bytes go (sac::MemoryBreakdown)");
  CLI11_PARSE(app, argc, argv);

  std::printf("%-8s %7s | %9s %8s %31s %6s %6s | %8s %8s %8s %31s %7s\n", "dist", "n", "events", "B/pt",
              "steps/pt (fc co try ins fin)", "rnd/st", "cl/rnd", "dist", "median", "us", "re-run (fc co try ins fin)",
              "rounds");
  std::vector<Point<2>> file_points;
  if (!points_file.empty()) {
    try {
      file_points = read_points_file<2>(points_file).points;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "dynmesh_hpu_steps: %s\n", e.what());
      return 2;
    }
    const std::size_t slash = points_file.find_last_of('/');
    dists = {points_file.substr(slash == std::string::npos ? 0 : slash + 1)};
    sizes = {file_points.size()};
  }
  for (const std::string& dname : dists) {
    const auto parsed = points_file.empty() ? parse_distribution(dname) : std::optional<Distribution>{};
    if (points_file.empty() && !parsed) {
      std::fprintf(stderr, "dynmesh_hpu_steps: unknown distribution %s\n", dname.c_str());
      return 2;
    }
    for (const std::size_t n : sizes) {
      std::vector<Point<2>> pts = points_file.empty() ? generate<2>(*parsed, n, seed) : file_points;
      const Box<2> box = box_args.empty() ? derive_box<2>(pts) : Box<2>{{box_args[0], box_args[1]}, box_args[2]};
      Run run(box, pts, angle);
      const sac::Stats& st = run.engine.stats();
      const double scratch_events = static_cast<double>(st.events_created);
      const double bytes = static_cast<double>(run.engine.record_bytes()) / static_cast<double>(n);
      const HcStepCounts s0 = run.program.steps;
      if (breakdown) std::cout << run.engine.memory_breakdown() << std::flush;
      const auto c0 = run.program.view.counts();
      const std::size_t asks0 = run.program.stats.neighbour_asks;
      const std::size_t leaves0 = run.program.view.leaves_read();
      const double steps0 = static_cast<double>(s0.total());
      std::mt19937_64 rng(seed * 7919 + n);
      std::vector<double> dist_v, us_v;
      std::array<double, HcStepCounts::kKinds> rerun{};
      double rounds = 0;
      struct Costly {
        std::uint64_t distance, created, reexecuted;
        int update;
        bool insert;
        std::array<std::uint64_t, HcStepCounts::kKinds> steps;
      };
      std::vector<Costly> costly;
      for (int u = 0; u < updates; ++u) {
        const std::size_t i = rng() % pts.size();
        const Point<2> x = pts[i];
        for (int op = 0; op < 2; ++op) {
          const HcStepCounts before = run.program.steps;
          const auto rb = run.program.view.counts().rounds;
          const std::uint64_t created0 = st.events_created;
          const double sec = bench::seconds([&] {
            if (op == 0) run.update({}, {x});
            else run.update({x}, {});
          });
          us_v.push_back(sec * 1e6);
          dist_v.push_back(static_cast<double>(st.last_trace_distance));
          for (int k = 0; k < HcStepCounts::kKinds; ++k)
            rerun[k] += static_cast<double>(run.program.steps.done[k] - before.done[k]);
          rounds += static_cast<double>(run.program.view.counts().rounds - rb);
          if (tail > 0) {
            Costly c{st.last_trace_distance, st.events_created - created0, st.last_reexecuted, u, op == 1, {}};
            for (int k = 0; k < HcStepCounts::kKinds; ++k) c.steps[k] = run.program.steps.done[k] - before.done[k];
            costly.push_back(c);
          }
        }
      }
      const double m = std::max<double>(1, static_cast<double>(dist_v.size()));
      char steps_pt[64], rr[64];
      std::snprintf(steps_pt, sizeof steps_pt, "%.2f %.2f %.2f %.2f %.2f", s0.done[0] / double(n), s0.done[1] / double(n),
                    s0.done[2] / double(n), s0.done[3] / double(n), s0.done[4] / double(n));
      std::snprintf(rr, sizeof rr, "%.1f %.1f %.1f %.1f %.1f", rerun[0] / m, rerun[1] / m, rerun[2] / m, rerun[3] / m,
                    rerun[4] / m);
      std::printf("%-8s %7zu | %9.0f %8.0f %31s %6.2f %6.2f | %8.0f %8.0f %8.0f %31s %7.1f\n", dname.c_str(), n,
                  scratch_events, bytes, steps_pt, static_cast<double>(c0.rounds) / steps0,
                  static_cast<double>(c0.cells) / static_cast<double>(c0.rounds), bench::mean(dist_v),
                  bench::median(dist_v), bench::mean(us_v), rr, rounds / m);
      std::stable_sort(costly.begin(), costly.end(),
                       [](const Costly& a, const Costly& b) { return a.distance > b.distance; });
      if (costly.size() > tail) costly.resize(tail);
      for (const Costly& c : costly)
        std::printf("  costly: update %d %s: distance %llu, %llu events created, %llu reads re-executed, steps "
                    "re-run (fc co try ins fin) %llu %llu %llu %llu %llu\n",
                    c.update, c.insert ? "insert" : "delete", static_cast<unsigned long long>(c.distance),
                    static_cast<unsigned long long>(c.created), static_cast<unsigned long long>(c.reexecuted),
                    static_cast<unsigned long long>(c.steps[0]), static_cast<unsigned long long>(c.steps[1]),
                    static_cast<unsigned long long>(c.steps[2]), static_cast<unsigned long long>(c.steps[3]),
                    static_cast<unsigned long long>(c.steps[4]));
      std::fflush(stdout);
      if (engine_stats) std::cout << "  engine: " << st << "\n" << std::flush;
      if (search_stats) {
        const double asks1 = static_cast<double>(run.program.stats.neighbour_asks - asks0);
        const std::uint64_t leaves1 = run.program.view.leaves_read() - leaves0;
        const double pn = static_cast<double>(n);
        std::printf("  searches, per point from scratch: left searches %.1f, leaves read %.1f\n",
                    static_cast<double>(asks0) / pn, static_cast<double>(leaves0) / pn);
        std::printf("  searches, per update: left searches %.0f, leaves read %.0f\n", asks1 / m,
                    static_cast<double>(leaves1) / m);
        std::fflush(stdout);
      }
      if (verify) {
        const bool same = run.state.feed.triangles() == HpuMesh(box, pts, angle).triangles();
        std::printf("  verified against HpuMesh: %s\n", same ? "yes" : "NO");
        if (!same) return 1;
      }
    }
  }
  return 0;
}
