// Tests of Engine::memo_near: a memoized call reused only when its old call lies at most k
// stamps ahead of now.
//
// What is checked: on a list whose per-element call is keyed by the element alone, moving
// the last element to the front re-runs that element's call only with memo_near, where
// memo() reuses the far call and re-runs every call it discarded on the way; a call just
// ahead is reused, and one further than k is counted in Stats::memo_far; and a random
// differential (moves, removals, re-insertions, seed printed) against the expected output
// and a from-scratch run's trace size, with check_invariants() after every propagate().
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "../sanitized.hpp"
#include "sac/sac.hpp"

namespace {

using sac::Engine;
using sac::Mod;

struct Item {
  Item(long v, std::uint64_t i) : value(v), id(i) {}
  long value;
  std::uint64_t id;
  Mod<Item*> next;
};

/// An element's output, keyed by its id.
struct Res {
  explicit Res(std::uint64_t i) : id(i) {}
  std::uint64_t id;
  Mod<long> v;
  Mod<Res*> next;
};

int g_work = 0;

void count_call(Engine&, int* calls, int /*key*/) { ++*calls; }

void work(Engine& rt, Item* it, Res* r) {
  ++g_work;
  rt.write(r->v, it->value * 3 + 1);
}

/// The list's outputs in order; each element's work is memoized on (element, output) only,
/// so its key does not say where the element stands. reach 0: memo(), else memo_near(reach).
/// The link reads' keys do say it: (element, its predecessor), as a list step in dynmesh's
/// hpu program, so a moved element's old link read far ahead is not reused either.
void walk(Engine& rt, Item* it, Mod<Res*>* dest, std::uint32_t reach, Item* pred, Item* grand) {
  (void)grand;
  if (!it) return rt.write(*dest, nullptr);
  Res* r = rt.alloc<Res>(it->id, it->id);
  rt.write(*dest, r);
  if (reach) rt.memo_near(reach, sac::fn<&work>(it, r));
  else rt.memo(sac::fn<&work>(it, r));
  rt.memo_read(it->next, sac::fn<&walk>(&r->next, reach, it, pred));
}

/// The mutator's list: items in `order`, linked through their next modifiables.
struct List {
  Engine& rt;
  std::vector<std::unique_ptr<Item>> items;
  std::vector<Item*> order;
  Mod<Item*> head;
  Mod<Res*> out;

  List(Engine& rt2, int n) : rt(rt2) {
    for (int i = 0; i < n; ++i) {
      items.push_back(std::make_unique<Item>(1000 + 7 * i, static_cast<std::uint64_t>(i)));
      order.push_back(items.back().get());
    }
    relink();
  }
  /// Sets every next (and head) to the order; unchanged links cost nothing.
  void relink() {
    rt.set(head, order.empty() ? nullptr : order.front());
    for (std::size_t i = 0; i < order.size(); ++i) rt.set(order[i]->next, i + 1 < order.size() ? order[i + 1] : nullptr);
  }
  void start(std::uint32_t reach) {
    rt.run([this, reach](Engine& rt2) {
      rt2.memo_read(head, sac::fn<&walk>(&out, reach, static_cast<Item*>(nullptr), static_cast<Item*>(nullptr)));
    });
  }
  std::vector<long> result() const {
    std::vector<long> r;
    for (Res* x = out.get(); x; x = x->next.get()) r.push_back(x->v.get());
    return r;
  }
  std::vector<long> expected() const {
    std::vector<long> r;
    for (const Item* it : order) r.push_back(it->value * 3 + 1);
    return r;
  }
};

void expect_healthy(const Engine& rt) {
  EXPECT_FALSE(rt.poisoned());
  EXPECT_NO_THROW(rt.check_invariants());
  EXPECT_EQ(rt.stats().live_events, rt.stats().events_created - rt.stats().events_undone);
}

/// Moves the last element to the front; returns the work calls the propagation ran.
int move_last_to_front(std::uint32_t reach, int n, sac::Stats* delta) {
  Engine rt;
  List l(rt, n);
  l.start(reach);
  EXPECT_EQ(l.result(), l.expected());
  const sac::Stats s0 = rt.stats();
  const int w0 = g_work;
  std::rotate(l.order.begin(), l.order.end() - 1, l.order.end());
  l.relink();
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(l.result(), l.expected());
  delta->memo_hits = rt.stats().memo_hits - s0.memo_hits;
  delta->memo_far = rt.stats().memo_far - s0.memo_far;
  delta->last_trace_distance = rt.stats().last_trace_distance;
  return g_work - w0;
}

TEST(MemoNear, AnElementMovedFarReRunsOnlyItsOwnCall) {
  const int n = 200;
  sac::Stats near, far;
  const int near_calls = move_last_to_front(8, n, &near);
  const int plain_calls = move_last_to_front(0, n, &far);
  EXPECT_EQ(near_calls, 1) << "only the moved element's call runs anew";
  EXPECT_EQ(near.memo_far, 1u) << "its old call, at the list's end, is refused";
  EXPECT_GE(near.memo_hits, 1u) << "the next element's call, just ahead, is reused";
  EXPECT_LE(near.last_trace_distance, 30u);
  // memo() reuses the moved element's call at the end and discards all between.
  EXPECT_GE(plain_calls, n - 2);
  EXPECT_EQ(far.memo_far, 0u);
  EXPECT_GT(far.last_trace_distance, 10u * near.last_trace_distance);
}

TEST(MemoNear, ACallJustAheadIsReusedAndOneBeyondTheReachIsNot) {
  // A read re-runs and issues, before the memoized call, `extra` new events: the old call
  // then lies `extra`-ish stamps after now only if nothing of the old body precedes it. Here
  // the old body writes `pad` modifiables before the call, so its start lies pad stamps
  // ahead of the re-execution's first events.
  for (const std::uint32_t pad : {0u, 3u, 40u}) {
    Engine rt;
    Mod<int> in;
    std::vector<Mod<int>> pads(pad);
    int calls = 0;
    rt.set(in, 0);
    rt.run([&](Engine& rt2) {
      rt2.read(in, [&pads, pc = &calls](Engine& rt3, int v) {
        if (v == 0)
          for (auto& m : pads) rt3.write(m, 1);
        rt3.memo_near(8, sac::fn<&count_call>(pc, 1));
      });
    });
    ASSERT_EQ(calls, 1);
    const sac::Stats s0 = rt.stats();
    rt.set(in, 1);  // the new body skips the pads: the old call lies pad stamps ahead
    rt.propagate();
    expect_healthy(rt);
    if (pad <= 8) {
      EXPECT_EQ(calls, 1) << "pad " << pad;
      EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 1u);
    } else {
      EXPECT_EQ(calls, 2) << "pad " << pad;
      EXPECT_EQ(rt.stats().memo_far - s0.memo_far, 1u);
    }
  }
}

TEST(MemoNear, RandomMovesMatchTheExpectedListAndAFromScratchTrace) {
  const unsigned seed = 20261129;
  std::printf("MemoNear random differential: seed %u\n", seed);
  std::mt19937 rng(seed);
  const int n = test_support::kSanitized ? 60 : 300;
  Engine rt;
  List l(rt, n);
  l.start(16);
  std::vector<Item*> absent;
  int calls = 0, changes = 0;
  for (int step = 0; step < 300; ++step) {
    const int op = static_cast<int>(rng() % 3);
    ++changes;
    if (op == 0 && l.order.size() > 1) {  // move one element
      const std::size_t from = rng() % l.order.size();
      Item* it = l.order[from];
      l.order.erase(l.order.begin() + static_cast<long>(from));
      l.order.insert(l.order.begin() + static_cast<long>(rng() % (l.order.size() + 1)), it);
    } else if (op == 1 && l.order.size() > 1) {  // remove one
      const std::size_t from = rng() % l.order.size();
      absent.push_back(l.order[from]);
      l.order.erase(l.order.begin() + static_cast<long>(from));
    } else if (!absent.empty()) {  // put one back
      Item* it = absent.back();
      absent.pop_back();
      l.order.insert(l.order.begin() + static_cast<long>(rng() % (l.order.size() + 1)), it);
    } else {
      --changes;
    }
    const int w0 = g_work;
    l.relink();
    rt.propagate();
    expect_healthy(rt);
    ASSERT_EQ(l.result(), l.expected()) << "seed " << seed << " step " << step;
    // The element that moved or came back runs its call anew; a reuse within the reach may
    // also undo the calls of the elements whose trace lies before it (an element moved two
    // places earlier: two elements of about 7 stamps each), which then run anew.
    EXPECT_LE(g_work - w0, 3) << "seed " << seed << " step " << step;
    calls += g_work - w0;
    if (step % 50 == 49) {
      // The same ids in the same order, on items of its own.
      Engine rt2;
      List f(rt2, n);
      std::vector<Item*> order;
      for (const Item* it : l.order) order.push_back(f.items[it->id].get());
      f.order = order;
      f.relink();
      f.start(16);
      EXPECT_EQ(f.result(), l.result());
      EXPECT_EQ(rt2.live_events(), rt.live_events()) << "step " << step;
    }
  }
  std::printf("MemoNear random differential: %d calls for %d changes\n", calls, changes);
  EXPECT_LE(calls, changes + changes / 10) << "about one call a change";
}

}  // namespace
