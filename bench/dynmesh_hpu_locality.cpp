// dynmesh_hpu_locality — how much of the hpu refinement one point update changes when every
// question is answered from the cells (src/hpu/cell_refiner.hpp): the reach of the rules
// alone, without the runtime, beside which the self-adjusting program's updates are judged.
//
// Method: refine P with the step log on; then, for U points x of P drawn with a fixed seed,
// refine P \ {x} in the same box and count the steps (CellStep: a step's key, what the cells
// handed it, its answer) that one run has and the other has not: the steps an ideal change
// propagation of "delete x" (or, read backwards, "insert x") must re-run or undo. Each such
// step is weighted by the leaves it read, the reads its re-execution would record. Deletion
// and insertion give the same figure (the difference is symmetric). Prints one row per
// (distribution, n): the steps of a run, then the mean, median and largest number of
// changed steps and the mean changed leaf reads per update. Flat in n is the goal.
// --reach says where the changed collects and processings lie: their distance from the
// updated point in units of 2^j, j their size class. The O(lg L/s) bound holds if that
// distance is bounded, whatever n, so that each class changes O(1) steps of its own size.
// --time also times the twin and the cell refiner on P and prints what the changed steps'
// geometry costs: the new steps (half the changed, over deletions and insertions) at each
// one's mean cost per step of a from-scratch run. Changed steps count from above (a step
// whose cells handed it another vertex re-runs in the program only if it used that
// vertex), so beside the program's measured update it says how much of that update the
// rules' own change could explain (bench/RESULTS.md).
// --held-stars prints instead what stars held from one walk to the next would save: the
// collects whose walk repeats the vertex's previous one, and the final walks of a star the
// vertex's last collect walked whole, with their left searches.
// --maintained-stars prints instead what stars kept up to date by the walks would answer
// (src/hpu/star_ledger.hpp): the collects a held star replays and their share of the
// collects' left searches; the share of the new vertices' first collects' searches
// replayed; the collects' searches the oracle answers (every triangle within the cap held)
// and the share of the triangles within the caps that no walk had met; the final walks'
// searches whose emitted triangles, and whose whole star, were held; and the share of all
// left searches that the replayed collects and the answered final walks make (and with the
// oracle's collects).
//
//   dynmesh_hpu_locality [--dist spiral,curves,uniform] [--n 1000,4000,16000] [--updates 20]
//                        [--seed 1] [--angle 20.7] [--csv] [--by-class] [--reach] [--time] [--profile]
//                        [--held-stars] [--maintained-stars]
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <sac/splitmix64.hpp>

#include "bench_stats.hpp"

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "hpu/cell_refiner.hpp"

namespace {

using namespace dynmesh;

struct Diff {
  std::size_t steps = 0;
  std::size_t leaves = 0;
  std::size_t by_kind[4] = {0, 0, 0, 0};  // changed steps: first classes, collects, processes, final
  std::size_t leaves_by_kind[4] = {0, 0, 0, 0};
  std::map<int, std::size_t> by_class;  // changed collects and processings by size class
  Point<2> update{};                    // the point inserted or deleted
  std::map<int, std::size_t> reach;     // the same by bin b: |at - update| / 2^cls in [2^(b-1), 2^b), 0: < 1
  double farthest = 0;                  // the largest |at - update| / 2^cls
  void add(const detail::CellStep& s) {
    ++steps, leaves += s.leaves;
    ++by_kind[s.kind], leaves_by_kind[s.kind] += s.leaves;
    if (s.kind == detail::CellStep::Collect || s.kind == detail::CellStep::Process) {
      ++by_class[s.cls];
      const double r = std::hypot(s.at[0] - update[0], s.at[1] - update[1]) / std::ldexp(1.0, s.cls);
      ++reach[r < 1 ? 0 : std::ilogb(r) + 1];
      farthest = std::max(farthest, r);
    }
  }
};

/// The multiset difference of two digest-sorted step logs.
Diff difference(const std::vector<detail::CellStep>& a, const std::vector<detail::CellStep>& b, const Point<2>& update) {
  Diff d;
  d.update = update;
  std::size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    if (j == b.size() || (i < a.size() && a[i].digest < b[j].digest)) {
      d.add(a[i++]);
    } else if (i == a.size() || b[j].digest < a[i].digest) {
      d.add(b[j++]);
    } else {
      ++i, ++j;
    }
  }
  return d;
}

std::vector<detail::CellStep> run(const Box<2>& box, const std::vector<Point<2>>& pts, double angle) {
  auto r = detail::cell_refine(box, pts, angle, detail::CellRefineOptions{.log_steps = true});
  std::sort(r.steps.begin(), r.steps.end());
  return std::move(r.steps);
}

/// One --held-stars row: what stars held from one walk to the next would answer.
void print_held_stars(const std::string& name, std::size_t n, const detail::CellQuestionStats& q) {
  const auto pct = [](std::size_t a, std::size_t b) { return b ? 100.0 * static_cast<double>(a) / static_cast<double>(b) : 0.0; };
  const auto per = [](std::size_t a, std::size_t b) { return b ? static_cast<double>(a) / static_cast<double>(b) : 0.0; };
  std::printf("%-8s %7zu %9zu %10.2f %8.1f%% %8.1f%% %9zu %9.2f %8.1f%% %8.1f%%\n", name.c_str(), n, q.collects,
              per(q.collect_asks, q.collects), pct(q.held_collects, q.collects), pct(q.held_asks, q.collect_asks),
              q.final_stars, per(q.final_asks, q.final_stars), pct(q.held_final, q.final_stars),
              pct(q.held_final_asks, q.final_asks));
  std::printf("%-8s %7zu   left searches: %zu in all, %zu (%.1f%%) in collects and final walks a held star "
              "answers; %.1f%% of the collects (%.1f%% of their searches) follow a whole walk of their vertex; "
              "%.1f%% of the collects' triangles were found by their vertex's previous walk\n",
              name.c_str(), n, q.neighbour_asks, q.held_asks + q.held_final_asks,
              pct(q.held_asks + q.held_final_asks, q.neighbour_asks), pct(q.kept_collects, q.collects),
              pct(q.kept_asks, q.collect_asks), pct(q.repeated_triangles, q.walk_triangles));
}

/// One --maintained-stars row: what stars kept up to date by the walks would answer.
void print_maintained(const std::string& name, std::size_t n, const detail::CellRefinement& r) {
  const auto pct = [](std::size_t a, std::size_t b) { return b ? 100.0 * static_cast<double>(a) / static_cast<double>(b) : 0.0; };
  const auto per = [](std::size_t a, std::size_t b) { return b ? static_cast<double>(a) / static_cast<double>(b) : 0.0; };
  const detail::MaintainedStarStats& m = r.maintained;
  const std::size_t all = r.questions.neighbour_asks;
  std::printf("%-8s %7zu %9zu %8.2f %8.1f%% %8.1f%% %8.1f%% %8.1f%% %8.1f%% %8.1f%% %8.1f%% %8.1f%% %10zu %8.1f%% %8.1f%%\n",
              name.c_str(), n, m.collects, per(m.collect_asks, m.collects), pct(m.answered_design, m.collects),
              pct(m.answered_design_asks, m.collect_asks), pct(m.births_design_asks, m.birth_asks),
              pct(m.answered_asks, m.collect_asks), pct(m.unheld_triangles, m.needed_triangles),
              pct(m.answered_final_asks, m.final_asks), pct(m.whole_final_asks, m.final_asks),
              pct(m.collect_asks + m.final_asks, all), all, pct(m.answered_design_asks + m.answered_final_asks, all),
              pct(m.answered_asks + m.answered_final_asks, all));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Steps of the cell-based hpu refinement that one point update changes"};
  std::vector<std::string> dists{"spiral", "curves", "uniform"};
  std::vector<std::size_t> sizes{1000, 4000, 16000};
  std::size_t updates = 20;
  std::uint64_t seed = 1;
  double angle = 20.7;
  bool csv = false, profile = false, by_class = false, reach = false, time = false;
  app.add_option("--dist", dists, "distributions")->delimiter(',');
  app.add_option("--n", sizes, "sizes")->delimiter(',');
  app.add_option("--updates", updates, "updates measured per size");
  app.add_option("--seed", seed, "seed of the points and of the updates");
  app.add_option("--angle", angle, "angle bound (degrees)");
  app.add_flag("--csv", csv, "CSV output");
  app.add_flag("--time", time, "also time HpuMesh (the twin) and the cell refiner on the same points (one run each)");
  app.add_flag("--by-class", by_class, "also print the changed collects and processings per update by size class");
  app.add_flag("--reach", reach,
               "also print the changed collects and processings per update by their distance from the updated point, "
               "in units of 2^(their size class)");
  app.add_flag("--profile", profile, "also print, per step kind, the leaves one step reads (mean, median, p99, max)");
  bool held = false;
  app.add_flag("--held-stars", held,
               "only print, per (distribution, n), the left searches that stars held from one walk to the next would "
               "save: collects whose walk repeats the vertex's previous one, final walks of a star its last collect "
               "walked whole");
  bool maintained = false;
  app.add_flag("--maintained-stars", maintained,
               "only print, per (distribution, n), what stars kept up to date by the walks would answer: collects "
               "a held star replays, final walks whose triangles some walk had met");
  CLI11_PARSE(app, argc, argv);


  if (maintained)
    std::printf("%-8s %7s %9s %8s %9s %9s %9s %9s %9s %9s %9s %9s %10s %9s %9s\n", "dist", "n", "collects",
                "asks/col", "replayed", "rep asks", "birth rep", "orc asks", "unheld", "fin asks", "fin whole",
                "walk asks", "all asks", "saved", "saved orc");
  else if (held)
    std::printf("%-8s %7s %9s %10s %9s %9s %9s %9s %9s %9s\n", "dist", "n", "collects", "asks/coll", "held col",
                "held ask", "final", "asks/fin", "held fin", "held ask");
  else if (csv)
    std::printf("dist,n,steps,mean_changed,median_changed,max_changed,mean_changed_leaves,"
                "first,collect,process,final,first_leaves,collect_leaves,process_leaves,final_leaves\n");
  else
    std::printf("%-8s %7s %8s %9s %9s %8s %11s   %s\n", "dist", "n", "steps", "mean chg", "median", "max",
                "chg reads", "changed steps (reads) by kind: first / collect / process / final");
  for (const std::string& name : dists) {
    const auto dist = parse_distribution(name);
    if (!dist) {
      std::fprintf(stderr, "dynmesh_hpu_locality: unknown distribution %s\n", name.c_str());
      return 2;
    }
    for (const std::size_t n : sizes) {
      const auto pts = generate<2>(*dist, n, seed);
      const Box<2> box = derive_box<2>(pts);
      if (maintained) {
        print_maintained(name, n, detail::cell_refine(box, pts, angle, detail::CellRefineOptions{.maintained_stars = true}));
        continue;
      }
      if (held) {
        print_held_stars(name, n, detail::cell_refine(box, pts, angle, detail::CellRefineOptions{.held_stars = true}).questions);
        continue;
      }
      const auto base = run(box, pts, angle);
      double twin_s = 0, cell_s = 0;
      if (time) {
        std::vector<Triangle> twin_mesh, cell_mesh;
        twin_s = bench::seconds([&] { twin_mesh = HpuMesh(box, pts, angle).triangles(); });
        cell_s = bench::seconds([&] { cell_mesh = detail::cell_refine(box, pts, angle).triangles; });
        std::printf("# %s n=%zu time: twin %.3f s, cell refiner %.3f s (%.1fx), same mesh %d\n", name.c_str(), n, twin_s,
                    cell_s, cell_s / twin_s, static_cast<int>(twin_mesh == cell_mesh));
      }
      if (profile) {
        static const char* const kKind[] = {"first class", "collect", "process", "final"};
        for (int k = 0; k < 4; ++k) {
          std::vector<double> l;
          for (const auto& st : base)
            if (st.kind == k) l.push_back(st.leaves);
          std::sort(l.begin(), l.end());
          double sum = 0;
          for (const double x : l) sum += x;
          if (!l.empty())
            std::printf("# %s n=%zu %-12s steps %8zu  leaves/step mean %6.1f median %5.0f p99 %6.0f max %6.0f\n",
                        name.c_str(), n, kKind[k], l.size(), sum / static_cast<double>(l.size()), l[l.size() / 2],
                        l[l.size() * 99 / 100], l.back());
        }
      }
      std::mt19937_64 rng(seed ^ sac::kGoldenGamma);
      std::vector<double> changed, reads;
      double kind[4] = {0, 0, 0, 0}, kind_leaves[4] = {0, 0, 0, 0};
      std::map<int, double> classes, reaches;
      double farthest = 0;
      for (std::size_t u = 0; u < updates; ++u) {
        std::vector<Point<2>> less = pts;
        const auto gone = static_cast<std::ptrdiff_t>(rng() % less.size());
        const Point<2> x = less[static_cast<std::size_t>(gone)];
        less.erase(less.begin() + gone);
        const Diff d = difference(base, run(box, less, angle), x);
        for (const auto& [b, count] : d.reach) reaches[b] += static_cast<double>(count) / static_cast<double>(updates);
        farthest = std::max(farthest, d.farthest);
        changed.push_back(static_cast<double>(d.steps));
        reads.push_back(static_cast<double>(d.leaves));
        for (const auto& [c, count] : d.by_class) classes[c] += static_cast<double>(count) / static_cast<double>(updates);
        for (int k = 0; k < 4; ++k) {
          kind[k] += static_cast<double>(d.by_kind[k]) / static_cast<double>(updates);
          kind_leaves[k] += static_cast<double>(d.leaves_by_kind[k]) / static_cast<double>(updates);
        }
      }
      const auto mean = [](const std::vector<double>& v) {
        double s = 0;
        for (const double x : v) s += x;
        return v.empty() ? 0.0 : s / static_cast<double>(v.size());
      };
      const double med = bench::median(changed);
      const double mx = changed.empty() ? 0.0 : *std::max_element(changed.begin(), changed.end());
      if (csv)
        std::printf("%s,%zu,%zu,%.1f,%.1f,%.0f,%.1f,%.1f,%.1f,%.1f,%.1f,%.1f,%.1f,%.1f,%.1f\n", name.c_str(), n,
                    base.size(), mean(changed), med, mx, mean(reads), kind[0], kind[1], kind[2], kind[3], kind_leaves[0],
                    kind_leaves[1], kind_leaves[2], kind_leaves[3]);
      else
        std::printf("%-8s %7zu %8zu %9.1f %9.1f %8.0f %11.1f   %.0f (%.0f) / %.0f (%.0f) / %.0f (%.0f) / %.0f (%.0f)\n",
                    name.c_str(), n, base.size(), mean(changed), med, mx, mean(reads), kind[0], kind_leaves[0], kind[1],
                    kind_leaves[1], kind[2], kind_leaves[2], kind[3], kind_leaves[3]);
      if (by_class) {
        std::printf("# %s n=%zu changed collects+processings by class:", name.c_str(), n);
        for (const auto& [c, x] : classes) std::printf(" %d:%.0f", c, x);
        std::printf("\n");
      }
      if (time && !base.empty()) {
        // The new run's steps that the old one lacks (half the changed steps, over deletions
        // and insertions) at a from-scratch run's cost per step (by steps for the twin; by
        // leaves read too for the refiner).
        double base_leaves = 0;
        for (const auto& st : base) base_leaves += st.leaves;
        const double steps = static_cast<double>(base.size());
        const double new_steps = mean(changed) / 2, twin_us = 1e6 * twin_s / steps, cell_us = 1e6 * cell_s / steps;
        std::printf("# %s n=%zu new steps per update: %.1f; at the twin's %.3f us a step %.0f us; at the cell "
                    "refiner's %.3f us a step %.0f us, by leaves read %.0f us\n",
                    name.c_str(), n, new_steps, twin_us, twin_us * new_steps, cell_us, cell_us * new_steps,
                    1e6 * cell_s / base_leaves * mean(reads) / 2);
      }
      if (reach) {
        std::printf("# %s n=%zu changed collects+processings by distance / 2^class:", name.c_str(), n);
        for (const auto& [b, x] : reaches) std::printf(" <%g:%.1f", std::ldexp(1.0, b), x);
        std::printf("; farthest %.1f\n", farthest);
      }
      std::fflush(stdout);
    }
  }
  return 0;
}
