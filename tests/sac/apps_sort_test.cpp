// Tests of the sorting and geometric apps: quicksort, mergesort, quickhull, diameter.
//
// For every app (and input variants: many equal sort keys, points in a square or a disk):
// differential random sequences of removals, reinsertions, modifications and batches (after
// every propagate the output equals the conventional twin's, the engine's invariants hold,
// and the live trace equals a from-scratch run's on the current input, event for event and
// byte for byte); edge cases (empty input, one element, all keys equal, collinear and
// duplicate points, removing everything and reinserting it); independent oracles (std::sort,
// all-pairs distances, hand-made hulls); and the work per update, which must be
// logarithmic, not linear.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sac/sac.hpp>

#include "app_test_support.hpp"
#include "sacapps/app.hpp"
#include "sacapps/diameter.hpp"
#include "sacapps/mergesort.hpp"
#include "sacapps/quickhull.hpp"
#include "sacapps/quicksort.hpp"

namespace {

using app_test::expect_consistent;
using app_test::pick;

using sacapps::Point;
using sacapps::Site;
using sacapps::diameter::DiameterApp;
using sacapps::mergesort::MergesortApp;
using sacapps::quickhull::Distribution;
using sacapps::quickhull::QuickhullApp;
using sacapps::quicksort::QuicksortApp;

using app_test::kDebugChecks;
using app_test::kSanitized;

// ------------------------------------------------------------------ the apps under test

struct Variant {
  std::string name;
  std::function<std::unique_ptr<sacapps::App>()> make;
};

void PrintTo(const Variant& v, std::ostream* os) { *os << v.name; }
std::string variant_name(const ::testing::TestParamInfo<Variant>& info) { return info.param.name; }

const std::vector<Variant> kSortVariants{
    {"quicksort", [] { return std::make_unique<QuicksortApp>(); }},
    {"quicksort_few_keys", [] { return std::make_unique<QuicksortApp>(8); }},
    {"mergesort", [] { return std::make_unique<MergesortApp>(); }},
    {"mergesort_few_keys", [] { return std::make_unique<MergesortApp>(8); }},
};
const std::vector<Variant> kHullVariants{
    {"quickhull_square", [] { return std::make_unique<QuickhullApp>(Distribution::Square); }},
    {"quickhull_disk", [] { return std::make_unique<QuickhullApp>(Distribution::Disk); }},
};
const std::vector<Variant> kDiameterVariants{
    {"diameter_square", [] { return std::make_unique<DiameterApp>(Distribution::Square); }},
    {"diameter_disk", [] { return std::make_unique<DiameterApp>(Distribution::Disk); }},
};

// ------------------------------------------------------------------ helpers

/// One random mutator change (remove, reinsert or modify); false if none was possible.
bool random_change(sacapps::App& app, std::mt19937_64& rng) {
  const unsigned kind = static_cast<unsigned>(rng() % 3);
  const std::size_t i = pick(app, kind != 1, rng);
  if (i == app.positions()) return false;
  if (kind == 0) app.remove(i);
  else if (kind == 1) app.reinsert(i);
  else app.modify(i, rng());
  return true;
}

std::vector<std::int64_t> sorted_values(const sacapps::SortApp& app) {
  std::vector<std::int64_t> out;
  for (const auto& t : app.current_input()) out.push_back(t.value);
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::int64_t> output_values(const sacapps::SortApp& app) {
  return sacapps::to_vector(app.output());
}

std::vector<Site> hull_of(const QuickhullApp& app) {
  std::vector<Site> out;
  for (const auto* c = app.output().get(); c; c = c->next.get())
    out.push_back(Site{c->value, c->id});
  return out;
}

double all_pairs_diameter(const std::vector<sacapps::Tagged<Point>>& pts) {
  double best = 0;
  for (const auto& a : pts)
    for (const auto& b : pts) best = std::max(best, sacapps::geom::dist2(a.value, b.value));
  return best;
}

/// Removes every element (propagating after each), then reinserts them all in a random
/// order, checking the output along the way and the trace at the end of each phase.
void remove_all_then_reinsert_all(sacapps::App& app, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::size_t> order(app.positions());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  for (std::size_t i : order) {
    app.remove(i);
    app.engine().propagate();
    ASSERT_TRUE(app.verify()) << "after removing position " << i;
  }
  expect_consistent(app);
  std::shuffle(order.begin(), order.end(), rng);
  for (std::size_t i : order) {
    app.reinsert(i);
    app.engine().propagate();
    ASSERT_TRUE(app.verify()) << "after reinserting position " << i;
  }
  expect_consistent(app);
}

// ------------------------------------------------------------------ differential sequences

class SacAppDifferential : public ::testing::TestWithParam<Variant> {};

TEST_P(SacAppDifferential, RandomSequencesMatchTheTwinAndAFromScratchTrace) {
  const std::vector<std::uint64_t> seeds{1, 2, 3};
  const int steps = kSanitized ? 40 : 200;
  for (std::uint64_t seed : seeds) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    const std::size_t n = kSanitized ? 40 + rng() % 80 : 100 + rng() % 400;
    auto app = GetParam().make();
    app->generate(n, seed);
    app->run_self_adjusting();
    expect_consistent(*app);
    for (int step = 0; step < steps && !HasFailure(); ++step) {
      SCOPED_TRACE("step " + std::to_string(step));
      if (rng() % 5 == 0) {  // a batch: several changes, one propagate
        const int k = 2 + static_cast<int>(rng() % 7);
        for (int j = 0; j < k; ++j) random_change(*app, rng);
      } else if (!random_change(*app, rng)) {
        continue;
      }
      app->engine().propagate();
      expect_consistent(*app);
    }
  }
}

TEST_P(SacAppDifferential, EmptyInput) {
  auto app = GetParam().make();
  app->generate(0, 1);
  app->run_self_adjusting();
  expect_consistent(*app);
}

TEST_P(SacAppDifferential, OneElement) {
  auto app = GetParam().make();
  app->generate(1, 5);
  app->run_self_adjusting();
  expect_consistent(*app);
  app->remove(0);
  app->engine().propagate();
  expect_consistent(*app);
  app->reinsert(0);
  app->engine().propagate();
  expect_consistent(*app);
  app->modify(0, 99);
  app->engine().propagate();
  expect_consistent(*app);
}

TEST_P(SacAppDifferential, RemoveEverythingThenReinsertEverything) {
  auto app = GetParam().make();
  app->generate(kSanitized ? 40 : 150, 11);
  app->run_self_adjusting();
  remove_all_then_reinsert_all(*app, 11);
}

INSTANTIATE_TEST_SUITE_P(Sort, SacAppDifferential, ::testing::ValuesIn(kSortVariants),
                         variant_name);
INSTANTIATE_TEST_SUITE_P(Hull, SacAppDifferential, ::testing::ValuesIn(kHullVariants),
                         variant_name);
INSTANTIATE_TEST_SUITE_P(Diameter, SacAppDifferential, ::testing::ValuesIn(kDiameterVariants),
                         variant_name);

// ------------------------------------------------------------------ sorts: edge cases, oracle

template <class SortAppT>
void check_sort_edge_cases() {
  {  // all keys equal: the order is by id alone (a sorted input, quicksort's worst case)
    SortAppT app;
    app.set_input(std::vector<std::int64_t>(kSanitized ? 60 : 200, 42));
    app.run_self_adjusting();
    expect_consistent(app);
    std::mt19937_64 rng(3);
    for (int step = 0; step < 30 && !::testing::Test::HasFailure(); ++step) {
      const std::size_t i = pick(app, step % 2 == 0, rng);
      if (i == app.positions()) continue;
      if (step % 2 == 0) app.remove(i);
      else app.reinsert(i);
      app.engine().propagate();
      expect_consistent(app);
    }
  }
  {  // the output is std::sort of the values, and equal keys come in id order
    SortAppT app(16);
    app.generate(300, 8);
    app.run_self_adjusting();
    EXPECT_EQ(output_values(app), sorted_values(app));
    std::mt19937_64 rng(4);
    for (int step = 0; step < 20; ++step) {
      random_change(app, rng);
      app.engine().propagate();
      EXPECT_EQ(output_values(app), sorted_values(app));
    }
    std::uint64_t prev_id = 0;
    std::int64_t prev_value = -1;
    for (const auto* c = app.output().get(); c; c = c->next.get()) {
      if (c->value == prev_value) {
        EXPECT_LT(prev_id, c->id);
      }
      prev_value = c->value;
      prev_id = c->id;
    }
  }
}

TEST(SortEdgeCases, QuicksortEqualKeysAndStdSortOracle) { check_sort_edge_cases<QuicksortApp>(); }
TEST(SortEdgeCases, MergesortEqualKeysAndStdSortOracle) { check_sort_edge_cases<MergesortApp>(); }

// ------------------------------------------------------------------ hulls: edge cases, oracle

TEST(HullEdgeCases, CollinearPointsGiveTheTwoEnds) {
  std::vector<Point> pts;
  for (int k = 0; k < 50; ++k) {  // the diagonal points (j, j), j < 50, in a scrambled order
    const double j = static_cast<double>((k * 17) % 50);
    pts.push_back(Point{j, j});
  }
  QuickhullApp app;
  app.set_input(pts);
  app.run_self_adjusting();
  expect_consistent(app);
  const auto hull = hull_of(app);
  ASSERT_EQ(hull.size(), 2u);
  EXPECT_EQ(hull[0].p, (Point{0, 0}));
  EXPECT_EQ(hull[1].p, (Point{49, 49}));
  // Remove the ends one after the other: the next ones along the line take over.
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (pts[i] == Point{0, 0} || pts[i] == Point{49, 49}) app.remove(i);
  app.engine().propagate();
  expect_consistent(app);
  ASSERT_EQ(hull_of(app).size(), 2u);
  EXPECT_EQ(hull_of(app)[0].p, (Point{1, 1}));
  EXPECT_EQ(hull_of(app)[1].p, (Point{48, 48}));
}

TEST(HullEdgeCases, DuplicatePointsCountOnceWithTheSmallestId) {
  // The corners of a square, each four times, points on its edges and inside.
  std::vector<Point> pts;
  for (int copy = 0; copy < 4; ++copy)
    for (Point p : {Point{0, 0}, Point{4, 0}, Point{4, 4}, Point{0, 4}}) pts.push_back(p);
  for (int k = 1; k < 4; ++k) {
    pts.push_back(Point{static_cast<double>(k), 0});
    pts.push_back(Point{4, static_cast<double>(k)});
    pts.push_back(Point{static_cast<double>(k), static_cast<double>(k)});
  }
  QuickhullApp app;
  app.set_input(pts);
  app.run_self_adjusting();
  expect_consistent(app);
  const std::vector<Site> want{{{0, 0}, 0}, {{4, 0}, 1}, {{4, 4}, 2}, {{0, 4}, 3}};
  EXPECT_EQ(hull_of(app), want);
  // Removing a corner's first copy hands the vertex to the next copy.
  app.remove(2);
  app.engine().propagate();
  expect_consistent(app);
  const std::vector<Site> want2{{{0, 0}, 0}, {{4, 0}, 1}, {{4, 4}, 6}, {{0, 4}, 3}};
  EXPECT_EQ(hull_of(app), want2);
}

TEST(HullEdgeCases, AllPointsEqualGiveAOnePointHull) {
  QuickhullApp app;
  app.set_input(std::vector<Point>(20, Point{0.5, 0.25}));
  app.run_self_adjusting();
  expect_consistent(app);
  const std::vector<Site> want{{{0.5, 0.25}, 0}};
  EXPECT_EQ(hull_of(app), want);
  remove_all_then_reinsert_all(app, 5);
  EXPECT_EQ(hull_of(app), want);
}

TEST(HullEdgeCases, RandomHullsAreConvexAndContainEveryPoint) {
  QuickhullApp app(Distribution::Disk);
  app.generate(kSanitized ? 200 : 2000, 21);
  app.run_self_adjusting();
  std::mt19937_64 rng(21);
  for (int step = 0; step < 20; ++step) {
    const auto hull = hull_of(app);
    ASSERT_GE(hull.size(), 3u);
    for (std::size_t k = 0; k < hull.size(); ++k) {
      const Point& a = hull[k].p;
      const Point& b = hull[(k + 1) % hull.size()].p;
      EXPECT_GT(sacapps::geom::cross(a, b, hull[(k + 2) % hull.size()].p), 0);  // a left turn
      for (const auto& t : app.current_input()) EXPECT_GE(sacapps::geom::cross(a, b, t.value), 0);
    }
    random_change(app, rng);
    app.engine().propagate();
  }
}

TEST(DiameterEdgeCases, MatchesAllPairsOfInputPoints) {
  DiameterApp app(Distribution::Disk);
  app.generate(kSanitized ? 100 : 400, 31);
  app.run_self_adjusting();
  std::mt19937_64 rng(31);
  for (int step = 0; step < 30; ++step) {
    EXPECT_EQ(app.output().get(), all_pairs_diameter(app.current_input()));
    random_change(app, rng);
    app.engine().propagate();
  }
}

TEST(DiameterEdgeCases, DegenerateSets) {
  DiameterApp app;
  app.set_input({Point{1, 1}, Point{1, 1}, Point{1, 1}});
  app.run_self_adjusting();
  expect_consistent(app);
  EXPECT_EQ(app.output().get(), 0.0);
  app.modify(1, 7);
  app.engine().propagate();
  expect_consistent(app);
  EXPECT_EQ(app.output().get(), all_pairs_diameter(app.current_input()));

  DiameterApp line;
  std::vector<Point> pts;
  for (int k = 0; k < 30; ++k) pts.push_back(Point{static_cast<double>(k), 0});
  line.set_input(pts);
  line.run_self_adjusting();
  expect_consistent(line);
  EXPECT_EQ(line.output().get(), 29.0 * 29.0);
  remove_all_then_reinsert_all(line, 9);
  EXPECT_EQ(line.output().get(), 29.0 * 29.0);
}

// ------------------------------------------------------------------ work per update

/// Mean trace distance of one update (a removal or a reinsertion at positions spread over
/// the input, propagated alone).
double mean_update_distance(sacapps::App& app, std::size_t updates) {
  const std::size_t n = app.positions();
  std::uint64_t total = 0;
  std::size_t count = 0;
  for (std::size_t k = 0; k < updates; ++k) {
    const std::size_t i = ((2 * k + 1) * n) / (2 * updates);
    app.remove(i);
    app.engine().propagate();
    total += app.engine().stats().last_trace_distance;
    app.reinsert(i);
    app.engine().propagate();
    total += app.engine().stats().last_trace_distance;
    count += 2;
  }
  return static_cast<double>(total) / static_cast<double>(count);
}

class SacAppWork : public ::testing::TestWithParam<Variant> {};

TEST_P(SacAppWork, UpdatesCostLogarithmicTraceDistance) {
  // The distance per update grows as log n: the bound below is a constant times log2 n
  // (changes of the hull itself weigh more at small n).
  const std::size_t small = kSanitized ? 500 : 2000;
  const std::size_t large = kSanitized ? 4000 : 20000;
  // Under SAC_DEBUG_CHECKS each propagation checks the whole trace.
  const std::size_t updates = kDebugChecks ? 8 : kSanitized ? 20 : 50;
  double mean[2];
  for (int k = 0; k < 2; ++k) {
    const std::size_t n = k == 0 ? small : large;
    auto app = GetParam().make();
    app->generate(n, 1);
    app->run_self_adjusting();
    mean[k] = mean_update_distance(*app, updates);
    EXPECT_TRUE(app->verify());
    std::printf("[ work     ] %s n=%zu: %.1f trace events per update (%.1f x log2 n)\n",
                GetParam().name.c_str(), n, mean[k], mean[k] / std::log2(static_cast<double>(n)));
    EXPECT_LT(mean[k], 40 * std::log2(static_cast<double>(n))) << "n=" << n;
  }
  // Ten times the input, far less than ten times the work.
  EXPECT_LT(mean[1], 2.5 * mean[0]);
}

const std::vector<Variant> kWorkSort{kSortVariants[0], kSortVariants[2]};
INSTANTIATE_TEST_SUITE_P(Sort, SacAppWork, ::testing::ValuesIn(kWorkSort), variant_name);
INSTANTIATE_TEST_SUITE_P(Hull, SacAppWork, ::testing::ValuesIn(kHullVariants), variant_name);
INSTANTIATE_TEST_SUITE_P(Diameter, SacAppWork, ::testing::ValuesIn(kDiameterVariants),
                         variant_name);

}  // namespace
