// Tests of the classic list and tree apps: map, filter, reverse, minimum, sum, exptrees.
//
// For every app: differential random sequences of removals, reinsertions, modifications and
// batches (after every propagate the output equals the conventional twin's, the engine's
// invariants hold, and the live trace has the size of a from-scratch run's on the current
// input), edge cases (empty and one-element inputs, removing and reinserting everything),
// the work done per update (not only the results), and memory returning to the
// from-scratch level after many update cycles.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sac/sac.hpp>

#include "app_test_support.hpp"
#include "sacapps/app.hpp"
#include "sacapps/exptrees.hpp"
#include "sacapps/filter.hpp"
#include "sacapps/list.hpp"

namespace {

using app_test::expect_consistent;
using app_test::pick;

using app_test::kDebugChecks;
using app_test::kSanitized;

// Large sizes of the work tests (kept modest under the sanitizers, which run at -O0).
constexpr std::size_t kLargeN = kSanitized ? 20000 : 100000;

/// Updates per work measurement: 100, but 10 on the large input under SAC_DEBUG_CHECKS,
/// where each propagation checks the whole trace.
constexpr std::size_t work_updates(std::size_t n) { return kDebugChecks && n > 1000 ? 10 : 100; }

const std::vector<std::string> kApps{"map", "filter", "reverse", "minimum", "sum", "exptrees"};

std::unique_ptr<sacapps::App> make(const std::string& name) {
  auto app = sacapps::make_app(name);
  if (!app) ADD_FAILURE() << "unknown app " << name;
  return app;
}

/// One random mutator change; false if none of the drawn kind was possible.
bool random_change(sacapps::App& app, std::mt19937_64& rng) {
  const std::size_t n = app.positions();
  const unsigned kind = static_cast<unsigned>(rng() % 10);
  if (kind < 4) {
    const std::size_t i = pick(app, true, rng);
    if (i == n) return false;
    app.remove(i);
  } else if (kind < 8) {
    const std::size_t i = pick(app, false, rng);
    if (i == n) return false;
    app.reinsert(i);
  } else {
    const std::size_t i = pick(app, true, rng);
    if (i == n) return false;
    app.modify(i, rng());
  }
  return true;
}

class AppsListTest : public ::testing::TestWithParam<std::string> {};

// ---------------------------------------------------------------- 1. differential sequences

TEST_P(AppsListTest, DifferentialRandomSequences) {
  const std::size_t steps = kSanitized ? 120 : 300;
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    std::mt19937_64 rng(seed * 7919 + 17);
    const std::size_t n = kSanitized ? 100 + rng() % 300 : 200 + rng() % 1800;
    SCOPED_TRACE("seed " + std::to_string(seed) + ", n " + std::to_string(n));
    auto app = make(GetParam());
    app->generate(n, seed);
    app->run_self_adjusting();
    expect_consistent(*app);
    for (std::size_t step = 0; step < steps && !HasFailure(); ++step) {
      SCOPED_TRACE("step " + std::to_string(step));
      if (rng() % 5 == 0) {  // a batch: several changes, one propagation
        const std::size_t k = 2 + rng() % 7;
        for (std::size_t j = 0; j < k; ++j) random_change(*app, rng);
      } else {
        random_change(*app, rng);
      }
      app->engine().propagate();
      expect_consistent(*app);
    }
  }
}

// ---------------------------------------------------------------- 2. edge cases

TEST_P(AppsListTest, EmptyInput) {
  auto app = make(GetParam());
  app->generate(0, 5);
  EXPECT_EQ(app->positions(), 0u);
  app->run_self_adjusting();
  expect_consistent(*app);
  app->engine().propagate();  // nothing changed
  EXPECT_EQ(app->engine().stats().last_trace_distance, 0u);
  expect_consistent(*app);
}

TEST_P(AppsListTest, OneElement) {
  auto app = make(GetParam());
  app->generate(1, 6);
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
  app->remove(0);  // a batch that changes nothing in the end
  app->reinsert(0);
  app->engine().propagate();
  expect_consistent(*app);
}

TEST_P(AppsListTest, RemoveEverythingThenReinsertEverything) {
  const std::size_t n = kSanitized ? 60 : 250;
  std::mt19937_64 rng(11);
  auto app = make(GetParam());
  app->generate(n, 8);
  app->run_self_adjusting();
  const std::size_t initial_events = app->engine().live_events();
  const std::size_t initial_bytes = app->engine().record_bytes();

  // One at a time, in random order.
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  for (std::size_t i : order) {
    app->remove(i);
    app->engine().propagate();
    ASSERT_TRUE(app->verify()) << "after removing " << i;
  }
  expect_consistent(*app);
  std::shuffle(order.begin(), order.end(), rng);
  for (std::size_t i : order) {
    app->reinsert(i);
    app->engine().propagate();
    ASSERT_TRUE(app->verify()) << "after reinserting " << i;
  }
  expect_consistent(*app);
  EXPECT_EQ(app->engine().live_events(), initial_events);
  EXPECT_EQ(app->engine().record_bytes(), initial_bytes);

  // All in one batch each way.
  for (std::size_t i = 0; i < n; ++i) app->remove(i);
  app->engine().propagate();
  expect_consistent(*app);
  for (std::size_t i = n; i-- > 0;) app->reinsert(i);
  app->engine().propagate();
  expect_consistent(*app);
  EXPECT_EQ(app->engine().live_events(), initial_events);
  EXPECT_EQ(app->engine().record_bytes(), initial_bytes);
}

// ---------------------------------------------------------------- 3. work per update

struct Work {
  double mean_distance = 0;
  std::uint64_t max_distance = 0;
  std::uint64_t max_reexecuted = 0;
};

/// Deletes and reinserts the element at `updates` positions spread over the input (the
/// suite's protocol), propagating after each change.
Work measure_updates(sacapps::App& app, std::size_t updates) {
  Work w;
  std::uint64_t total = 0, count = 0;
  const std::size_t n = app.positions();
  auto note = [&] {
    const sac::Stats& s = app.engine().stats();
    total += s.last_trace_distance;
    w.max_distance = std::max(w.max_distance, s.last_trace_distance);
    w.max_reexecuted = std::max(w.max_reexecuted, s.last_reexecuted);
    ++count;
  };
  for (std::size_t k = 0; k < updates; ++k) {
    const std::size_t i = ((2 * k + 1) * n) / (2 * updates);
    const bool check = n <= 10000 || k % 10 == 0;  // verify is O(n)
    app.remove(i);
    app.engine().propagate();
    note();
    if (check) {
      EXPECT_TRUE(app.verify()) << "after removing " << i;
    }
    app.reinsert(i);
    app.engine().propagate();
    note();
    if (check) {
      EXPECT_TRUE(app.verify()) << "after reinserting " << i;
    }
  }
  w.mean_distance = count ? static_cast<double>(total) / static_cast<double>(count) : 0.0;
  return w;
}

TEST(AppsWork, MapSingleChangeIsConstantWork) {
  for (const std::size_t n : {std::size_t{1000}, kLargeN}) {
    SCOPED_TRACE("n " + std::to_string(n));
    auto app = make("map");
    app->generate(n, 21);
    app->run_self_adjusting();
    const Work w = measure_updates(*app, work_updates(n));
    std::printf("[ map n=%zu ] mean trace distance %.2f, max %llu, max re-executed %llu\n", n,
                w.mean_distance, static_cast<unsigned long long>(w.max_distance),
                static_cast<unsigned long long>(w.max_reexecuted));
    EXPECT_LE(w.max_reexecuted, 1u);
    EXPECT_LE(w.max_distance, 6u);
  }
}

TEST(AppsWork, FilterSingleChangeIsConstantExpectedWork) {
  for (const std::size_t n : {std::size_t{1000}, kLargeN}) {
    SCOPED_TRACE("n " + std::to_string(n));
    auto app = make("filter");
    app->generate(n, 22);
    app->run_self_adjusting();
    const Work w = measure_updates(*app, work_updates(n));
    std::printf("[ filter n=%zu ] mean trace distance %.2f, max %llu, max re-executed %llu\n", n,
                w.mean_distance, static_cast<unsigned long long>(w.max_distance),
                static_cast<unsigned long long>(w.max_reexecuted));
    EXPECT_LE(w.max_reexecuted, 1u);
    EXPECT_LE(w.mean_distance, 10.0);
    EXPECT_LE(w.max_distance, 40u);  // O(1 + dropped cells after the change); see below
  }
}

// The filter's exact work bound: a change redoes the steps of the dropped cells that follow
// it up to the next kept cell (their destination changed) and nothing else.
TEST(AppsWork, FilterWorkIsBoundedByTheFollowingDroppedRun) {
  using sacapps::filter::keep;
  using V = std::int64_t;
  const std::size_t n = 2000;
  std::vector<V> values(n);
  std::mt19937_64 rng(23);
  for (V& v : values) v = static_cast<V>(rng() % 1000);
  sac::Engine rt;
  sacapps::InputList<V> in(rt, values);
  sacapps::List<V> out;
  rt.run([&](sac::Engine& rt2) { sacapps::filter::filter_list<keep>(rt2, in.head(), &out); });
  for (std::size_t i = 1; i + 1 < n && !HasFailure(); i += 7) {
    std::uint64_t run = 0;  // dropped cells right after i
    for (std::size_t j = i + 1; j < n && !keep(values[j]); ++j) ++run;
    in.remove(i);
    rt.propagate();
    EXPECT_EQ(rt.stats().last_reexecuted, 1u);
    EXPECT_LE(rt.stats().last_trace_distance, 6 + 2 * run) << "removing " << i;
    in.reinsert(i);
    rt.propagate();
    EXPECT_EQ(rt.stats().last_reexecuted, 1u);
    EXPECT_LE(rt.stats().last_trace_distance, 6 + 2 * run) << "reinserting " << i;
  }
  std::vector<V> expect;
  for (V v : values)
    if (keep(v)) expect.push_back(v);
  EXPECT_EQ(sacapps::to_vector(out), expect);
}

class AppsLogWorkTest : public ::testing::TestWithParam<std::string> {};

TEST_P(AppsLogWorkTest, UpdatesAreSublinear) {
  double mean_small = 0;
  for (const std::size_t n : {std::size_t{1000}, kLargeN}) {
    SCOPED_TRACE("n " + std::to_string(n));
    auto app = make(GetParam());
    app->generate(n, 31);
    app->run_self_adjusting();
    const std::size_t scratch_events = app->engine().live_events();
    const Work w = measure_updates(*app, work_updates(n));
    std::printf("[ %s n=%zu ] mean trace distance %.2f, max %llu, max re-executed %llu\n",
                GetParam().c_str(), n, w.mean_distance,
                static_cast<unsigned long long>(w.max_distance),
                static_cast<unsigned long long>(w.max_reexecuted));
    const double lg = std::log2(static_cast<double>(n));
    EXPECT_LT(w.mean_distance, 100 * lg);
    EXPECT_LT(w.max_distance, scratch_events / 20) << "an update redid a large part of the trace";
    if (n == 1000) {
      mean_small = w.mean_distance;
    } else {
      EXPECT_LT(w.mean_distance, 4 * mean_small + 50) << "grows much faster than log n";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Apps, AppsLogWorkTest,
                         ::testing::Values("reverse", "minimum", "sum", "exptrees"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// ---------------------------------------------------------------- 4. memory returns

TEST(AppsMemory, MapRemoveReinsertCyclesReturnToFromScratch) {
  const std::size_t n = 1000;
  auto app = make("map");
  app->generate(n, 41);
  app->run_self_adjusting();
  const std::size_t trace0 = app->engine().trace_bytes();
  std::mt19937_64 rng(42);
  const int cycles = kDebugChecks ? 1000 : 10000;  // each propagation checks the trace
  for (int cycle = 0; cycle < cycles; ++cycle) {
    const std::size_t i = rng() % n;
    app->remove(i);
    app->engine().propagate();
    app->reinsert(i);
    app->engine().propagate();
  }
  ASSERT_TRUE(app->verify());
  EXPECT_NO_THROW(app->engine().check_invariants());
  auto fresh = app->clone_current();
  fresh->run_self_adjusting();
  EXPECT_EQ(app->engine().record_bytes(), fresh->engine().record_bytes());
  EXPECT_EQ(app->engine().live_events(), fresh->engine().live_events());
  // Tables and the order list may keep some slack, but nothing grows with the cycles.
  EXPECT_LT(app->engine().trace_bytes(), 2 * trace0 + (64u << 10));
}

// ---------------------------------------------------------------- exptrees semantics

// ((a + b) * c) - d over leaves a=0, b=1, c=2, d=3, built by hand.
sacapps::exptrees::Shape small_shape() {
  using namespace sacapps::exptrees;
  Shape s;
  s.leaves = 4;
  s.op = {Op::Leaf, Op::Leaf, Op::Leaf, Op::Leaf, Op::Add, Op::Mul, Op::Sub};
  s.operands = {{0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 1}, {4, 2}, {5, 3}};
  s.value = {5, 7, 3, 10};
  s.depth = 3;
  return s;
}

TEST(AppsExpTrees, RemovedLeavesAreSplicedOut) {
  using namespace sacapps::exptrees;
  sac::Engine rt;
  ExpTree tree(rt, small_shape(), {true, true, true, true});
  sac::Mod<Value> result;
  rt.run([&](sac::Engine& rt2) { eval_tree(rt2, tree.root(), &result); });
  EXPECT_EQ(result.get(), (5 + 7) * 3 - 10);
  tree.remove(0);  // (b * c) - d: the Add node is replaced by b
  rt.propagate();
  EXPECT_EQ(result.get(), 7 * 3 - 10);
  tree.remove(2);  // b - d
  rt.propagate();
  EXPECT_EQ(result.get(), 7 - 10 + kPrime);
  tree.remove(3);  // b
  rt.propagate();
  EXPECT_EQ(result.get(), 7);
  tree.remove(1);  // the empty expression
  rt.propagate();
  EXPECT_EQ(result.get(), 0);
  tree.reinsert(2);  // c
  rt.propagate();
  EXPECT_EQ(result.get(), 3);
  tree.set_value(2, 4);
  rt.propagate();
  EXPECT_EQ(result.get(), 4);
  tree.reinsert(0);  // (a * c)
  tree.reinsert(3);  // (a * c) - d
  rt.propagate();
  EXPECT_EQ(result.get(), 5 * 4 - 10);
  tree.reinsert(1);
  rt.propagate();
  EXPECT_EQ(result.get(), (5 + 7) * 4 - 10);
  EXPECT_EQ(result.get(), evaluate_conventional(tree.shape(), tree.presence()));
  EXPECT_NO_THROW(rt.check_invariants());
}

TEST(AppsExpTrees, RandomShapesAreShallow) {
  const auto s = sacapps::exptrees::random_shape(100000, 3);
  EXPECT_EQ(s.op.size(), 2 * s.leaves - 1);
  EXPECT_LT(s.depth, 80u);  // random-BST depth: about 4.3 ln n at most, w.h.p.
}

INSTANTIATE_TEST_SUITE_P(Apps, AppsListTest, ::testing::ValuesIn(kApps),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

}  // namespace
