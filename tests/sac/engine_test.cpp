// Tests of sac/engine.hpp: the semantics of each primitive alone, then random differential
// tests of small self-adjusting programs against plain recomputation.
//
// What is checked, besides outputs: which reads re-ran (stats), memo hits and misses, keyed
// allocation identity and object lifetimes (constructor/destructor counts), that the live
// trace after an update has exactly the size of a from-scratch run on the same input
// (live_events, record_bytes), that misuse gives clear errors, and that check_invariants()
// passes after every run() and propagate() and fails when one part of the trace is corrupted
// (through the test-only EngineTestAccess). Sizes shrink under AddressSanitizer.
//
// Bodies only capture values and pointers to objects that outlive the engine (the test's
// locals), as the engine's documentation requires; nothing relies on a read's body having run
// when read() returns.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "../sanitized.hpp"
#include "sac/detail/order_list.hpp"
#include "sac/detail/trace_nodes.hpp"
#include "sac/sac.hpp"

namespace sac {

/// The bytes of one int input (a base version), as Engine::input_bytes counts them.
constexpr std::size_t kIntInput = (sizeof(detail::Version<int>) + 7) & ~std::size_t{7};

/// The test-only hook declared in Engine: the private trace, so that the checker tests below
/// can corrupt one part of it and see check_invariants() fail.
struct EngineTestAccess {
  static detail::OrderList& order(Engine& rt) { return rt.order_; }
  static Stats& stats(Engine& rt) { return rt.stats_; }
  static auto& queue(Engine& rt) { return rt.queue_; }
  static auto& allocs(Engine& rt) { return rt.allocs_; }
  static auto& memos(Engine& rt) { return rt.memos_; }
  static void attach(detail::ReadNode* r, detail::VersionBase* v) { detail::attach(&r->link, v); }
  static void detach(detail::ReadNode* r) { detail::detach(&r->link); }
  static void attach_default(detail::ReadNode* r, const ModBase& m) { Engine::attach_default(&r->link, m); }
  static void attach(detail::ReaderLink* l, detail::VersionBase* v) { detail::attach(l, v); }
  static void detach(detail::ReaderLink* l) { detail::detach(l); }
};

}  // namespace sac

#if defined(__SANITIZE_ADDRESS__)
#define SAC_ENGINE_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SAC_ENGINE_TEST_SANITIZED 1
#endif
#endif
#ifndef SAC_ENGINE_TEST_SANITIZED
#define SAC_ENGINE_TEST_SANITIZED 0
#endif

namespace {

using sac::Engine;
using sac::Mod;
using sac::Stats;

constexpr int kScale = SAC_ENGINE_TEST_SANITIZED ? 5 : 1;

// ------------------------------------------------------------------ read bodies
//
// Read bodies are plain lambdas, the documented way to write them; body() is the identity,
// a marker that reads as "this lambda is a read body".
template <class F>
std::decay_t<F> body(F&& f) {
  return std::forward<F>(f);
}

// ----------------------------------------------------------------------------- helpers

/// Invariants hold and the counters agree with each other.
void expect_healthy(const Engine& rt) {
  EXPECT_FALSE(rt.poisoned());
  EXPECT_FALSE(rt.in_computation());
  EXPECT_NO_THROW(rt.check_invariants());
  const Stats& s = rt.stats();
  EXPECT_EQ(s.live_events, s.events_created - s.events_undone) << s;
  EXPECT_EQ(rt.live_events(), s.live_events);
}

struct Figures {
  std::uint64_t live_events = 0;
  std::size_t record_bytes = 0;
  bool operator==(const Figures&) const = default;
};
Figures figures(const Engine& rt) { return {rt.live_events(), rt.record_bytes()}; }
std::ostream& operator<<(std::ostream& os, const Figures& f) {
  return os << "{live_events=" << f.live_events << ", record_bytes=" << f.record_bytes << "}";
}

/// Counts constructions and destructions (keyed allocation, undo, leak checks).
struct Counted {
  static inline int ctor = 0;
  static inline int dtor = 0;
  static void reset() { ctor = dtor = 0; }
  int v;
  Mod<int> m;
  explicit Counted(int x) : v(x) { ++ctor; }
  Counted(const Counted&) = delete;
  Counted& operator=(const Counted&) = delete;
  ~Counted() { ++dtor; }
};

/// A memoized function that only counts how often it really runs.
void bump(Engine&, int* calls, int /*key*/) { ++*calls; }

// ------------------------------------------------------------- input lists (mutator side)

struct Cell {
  long value;
  std::uint64_t id;
  Mod<Cell*> next;
  Cell(long v, std::uint64_t i) : value(v), id(i) {}
};

/// A mutator-owned list over values[0..n) where element i is present or absent; remove and
/// reinsert relink element i at its original position.
class Input {
 public:
  Input(Engine& rt, const std::vector<long>& values, std::vector<bool> present)
      : rt_(&rt), present_(std::move(present)) {
    for (std::size_t i = 0; i < values.size(); ++i)
      cells_.push_back(std::make_unique<Cell>(values[i], i));
    Cell* nx = nullptr;
    for (std::size_t i = values.size(); i-- > 0;) {
      if (present_[i]) {
        rt.set(cells_[i]->next, nx);
        nx = cells_[i].get();
      } else {
        rt.set(cells_[i]->next, static_cast<Cell*>(nullptr));
      }
    }
    rt.set(head, nx);
  }
  Input(Engine& rt, const std::vector<long>& values)
      : Input(rt, values, std::vector<bool>(values.size(), true)) {}

  Mod<Cell*> head;

  std::size_t size() const { return cells_.size(); }
  bool present(std::size_t i) const { return present_[i]; }
  const std::vector<bool>& presence() const { return present_; }
  Cell* cell(std::size_t i) { return cells_[i].get(); }

  void remove(std::size_t i) {
    Cell* c = cells_.at(i).get();
    rt_->set(link_before(i), c->next.get());
    present_[i] = false;
  }
  void reinsert(std::size_t i) {
    Cell* c = cells_.at(i).get();
    Mod<Cell*>& before = link_before(i);
    rt_->set(c->next, before.get());
    rt_->set(before, c);
    present_[i] = true;
  }
  void toggle(std::size_t i) {
    if (present_[i]) remove(i);
    else reinsert(i);
  }

  /// The current sequence, read from the modifiables (checks the mutator bookkeeping too).
  std::vector<long> sequence() const {
    std::vector<long> out;
    for (Cell* c = head.get(); c; c = c->next.get()) out.push_back(c->value);
    return out;
  }

 private:
  Mod<Cell*>& link_before(std::size_t i) {
    for (std::size_t j = i; j-- > 0;)
      if (present_[j]) return cells_[j]->next;
    return head;
  }

  Engine* rt_;
  std::vector<std::unique_ptr<Cell>> cells_;
  std::vector<bool> present_;
};

// ---------------------------------------------------------------- the programs under test

// Map: out[i] = 2 * in[i], output cells allocated under the input cell's id, the recursion
// memoized with memo_read on (tail modifiable, destination).
struct MapOut {
  long v;
  Mod<MapOut*> next;
  explicit MapOut(long x) : v(x) {}
};

int g_map_steps = 0;  // how many times map_step really ran

void map_step(Engine& rt, Cell* c, Mod<MapOut*>* dst) {
  ++g_map_steps;
  if (!c) {
    rt.write(*dst, static_cast<MapOut*>(nullptr));
    return;
  }
  MapOut* o = rt.alloc<MapOut>(c->id, 2 * c->value);
  rt.write(*dst, o);
  rt.memo_read(c->next, sac::fn<map_step>(&o->next));
}

struct MapProgram {
  Mod<MapOut*> out;
  void start(Engine& rt, Input& in) {
    rt.run([&](Engine& rt2) { rt2.memo_read(in.head, sac::fn<map_step>(&out)); });
  }
  std::vector<long> result() const {
    std::vector<long> r;
    for (MapOut* o = out.get(); o; o = o->next.get()) r.push_back(o->v);
    return r;
  }
  static std::vector<long> expected(const std::vector<long>& seq) {
    std::vector<long> r;
    for (long x : seq) r.push_back(2 * x);
    return r;
  }
};

// Prefix sums: out[i] = in[0] + ... + in[i]. Each output cell holds its sum in a modifiable
// written by a read of the previous sum; the recursion is memoized with memo_read.
struct SumOut {
  Mod<long> sum;
  Mod<SumOut*> next;
};

void psum_step(Engine& rt, Cell* c, Mod<long>* prev, Mod<SumOut*>* dst) {
  if (!c) {
    rt.write(*dst, static_cast<SumOut*>(nullptr));
    return;
  }
  SumOut* o = rt.alloc<SumOut>(c->id);
  rt.write(*dst, o);
  rt.read(*prev, body([o, v = c->value](Engine& rt2, long s) { rt2.write(o->sum, s + v); }));
  rt.memo_read(c->next, sac::fn<psum_step>(&o->sum, &o->next));
}

// The same prefix sums with the events of a step in another program order: the read of the
// previous sum is issued before the write of the destination and the allocation of the next
// cell, so the engine must run the read (and close its interval) before that write.
void psum_late_step(Engine& rt, Cell* c, Mod<long>* prev, Mod<SumOut*>* dst) {
  if (!c) {
    rt.write(*dst, static_cast<SumOut*>(nullptr));
    return;
  }
  SumOut* o = rt.alloc<SumOut>(c->id);
  rt.read(*prev, body([o, v = c->value](Engine& rt2, long s) { rt2.write(o->sum, s + v); }));
  rt.write(*dst, o);
  rt.memo_read(c->next, sac::fn<psum_late_step>(&o->sum, &o->next));
}

struct PsumProgram {
  Mod<long> zero;
  Mod<SumOut*> out;
  void start(Engine& rt, Input& in) {
    rt.set(zero, 0L);
    rt.run([&](Engine& rt2) { rt2.memo_read(in.head, sac::fn<psum_step>(&zero, &out)); });
  }
  std::vector<long> result() const {
    std::vector<long> r;
    for (SumOut* o = out.get(); o; o = o->next.get()) r.push_back(o->sum.get());
    return r;
  }
  static std::vector<long> expected(const std::vector<long>& seq) {
    std::vector<long> r;
    long s = 0;
    for (long x : seq) r.push_back(s += x);
    return r;
  }
};

struct PsumLateProgram : PsumProgram {
  void start(Engine& rt, Input& in) {
    rt.set(zero, 0L);
    rt.run([&](Engine& rt2) { rt2.memo_read(in.head, sac::fn<psum_late_step>(&zero, &out)); });
  }
};

// Imperative accumulation: one modifiable `acc` is written once per element (skipping
// multiples of 3) and `mx` whenever a larger element shows up; each step reads the version
// its predecessors left. Outputs: the final acc and the final mx.
constexpr long kMinStart = -1000;

void acc_step(Engine& rt, Cell* c, Mod<long>* acc, Mod<long>* mx, Mod<long>* out) {
  if (!c) {
    rt.read(*acc, body([out](Engine& rt2, long a) { rt2.write(*out, a); }));
    return;
  }
  rt.read(*acc, body([acc, v = c->value](Engine& rt2, long a) {
    if (v % 3 != 0) rt2.write(*acc, a + v);
  }));
  rt.read(*mx, body([mx, v = c->value](Engine& rt2, long m) {
    if (v > m) rt2.write(*mx, v);
  }));
  rt.memo_read(c->next, sac::fn<acc_step>(acc, mx, out));
}

struct AccProgram {
  Mod<long> acc, mx, out, out_max;
  void start(Engine& rt, Input& in) {
    rt.run([&](Engine& rt2) {
      rt2.write(acc, 0L);
      rt2.write(mx, kMinStart);
      rt2.memo_read(in.head, sac::fn<acc_step>(&acc, &mx, &out));
      rt2.read(mx, body([p = &out_max](Engine& rt3, long m) { rt3.write(*p, m); }));
    });
  }
  std::vector<long> result() const { return {out.get(), out_max.get()}; }
  static std::vector<long> expected(const std::vector<long>& seq) {
    long a = 0, m = kMinStart;
    for (long x : seq) {
      if (x % 3 != 0) a += x;
      m = std::max(m, x);
    }
    return {a, m};
  }
};

/// Runs Program from scratch on a fresh engine over the given input; returns its figures.
template <class Program>
Figures fresh_figures(const std::vector<long>& values, const std::vector<bool>& present,
                      std::vector<long>* result = nullptr) {
  Engine rt;
  Input in(rt, values, present);
  Program p;
  p.start(rt, in);
  EXPECT_NO_THROW(rt.check_invariants());
  if (result) *result = p.result();
  return figures(rt);
}

std::vector<long> random_values(std::mt19937_64& rng, int n) {
  std::uniform_int_distribution<long> d(-50, 50);
  std::vector<long> v(static_cast<std::size_t>(n));
  for (long& x : v) x = d(rng);
  return v;
}

// ================================================================ versioned reads

TEST(EngineVersions, EachReadSeesTheLatestVersionBeforeIt) {
  Engine rt;
  Mod<int> in, m, o1, o2, o3;
  int c1 = 0, c2 = 0, c3 = 0;
  rt.set(in, 1);
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([pm = &m](Engine& rt3, int v) { rt3.write(*pm, v * 10); }));
    rt2.read(m, body([po = &o1, pc = &c1](Engine& rt3, int v) { ++*pc; rt3.write(*po, v); }));
    rt2.write(m, 100);
    rt2.read(m, body([po = &o2, pc = &c2](Engine& rt3, int v) { ++*pc; rt3.write(*po, v); }));
    rt2.write(m, 200);
    rt2.read(m, body([po = &o3, pc = &c3](Engine& rt3, int v) { ++*pc; rt3.write(*po, v); }));
  });
  expect_healthy(rt);
  EXPECT_EQ(o1.get(), 10);
  EXPECT_EQ(o2.get(), 100);
  EXPECT_EQ(o3.get(), 200);
  EXPECT_EQ(m.get(), 200);  // the newest version
  EXPECT_EQ(c1 + c2 + c3, 3);

  // The early write depends on `in`: only it and the read between it and the next write
  // re-run; the reads after the later (unchanged) writes do not.
  rt.set(in, 2);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(o1.get(), 20);
  EXPECT_EQ(o2.get(), 100);
  EXPECT_EQ(o3.get(), 200);
  EXPECT_EQ(m.get(), 200);
  EXPECT_EQ(c1, 2);
  EXPECT_EQ(c2, 1);
  EXPECT_EQ(c3, 1);
  EXPECT_EQ(rt.stats().last_reexecuted, 2u);
  EXPECT_EQ(rt.stats().propagations, 1u);

  // Nothing changed: nothing re-runs.
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(rt.stats().last_reexecuted, 0u);
  EXPECT_EQ(rt.stats().last_trace_distance, 0u);
}

TEST(EngineVersions, WritesAndReadsInsideAReexecutedBody) {
  Engine rt;
  Mod<int> in, m, a, b, c;
  rt.set(in, 3);
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([pm = &m, pa = &a, pb = &b](Engine& rt3, int v) {
      rt3.write(*pm, v);
      rt3.read(*pm, body([pa](Engine& rt4, int w) { rt4.write(*pa, w + 1); }));
      rt3.write(*pm, v * 2);
      rt3.read(*pm, body([pb](Engine& rt4, int w) { rt4.write(*pb, w + 1); }));
    }));
    rt2.read(m, body([pc = &c](Engine& rt3, int w) { rt3.write(*pc, w); }));
  });
  expect_healthy(rt);
  EXPECT_EQ(a.get(), 4);
  EXPECT_EQ(b.get(), 7);
  EXPECT_EQ(c.get(), 6);
  for (int v : {5, -2, 0, 5, 5, 100}) {
    rt.set(in, v);
    rt.propagate();
    expect_healthy(rt);
    EXPECT_EQ(a.get(), v + 1);
    EXPECT_EQ(b.get(), 2 * v + 1);
    EXPECT_EQ(c.get(), 2 * v);
    EXPECT_EQ(m.get(), 2 * v);
  }
}

TEST(EngineVersions, ANewWriteTakesOverTheReadersAfterIt) {
  // A write inserted by re-execution between an old version and its readers: the readers
  // after it now see it; removing it again gives them back the older version.
  Engine rt;
  Mod<int> in, m, before, after;
  int runs_after = 0;
  rt.set(in, 0);
  rt.run([&](Engine& rt2) {
    rt2.write(m, 1);
    rt2.read(m, body([p = &before](Engine& rt3, int w) { rt3.write(*p, w); }));
    rt2.read(in, body([pm = &m](Engine& rt3, int v) {
      if (v > 0) rt3.write(*pm, v);
    }));
    rt2.read(m, body([p = &after, r = &runs_after](Engine& rt3, int w) { ++*r; rt3.write(*p, w); }));
  });
  expect_healthy(rt);
  EXPECT_EQ(after.get(), 1);
  rt.set(in, 7);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(before.get(), 1);
  EXPECT_EQ(after.get(), 7);
  EXPECT_EQ(runs_after, 2);
  EXPECT_EQ(m.get(), 7);
  rt.set(in, 9);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(after.get(), 9);
  rt.set(in, 0);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(after.get(), 1);
  EXPECT_EQ(before.get(), 1);
  EXPECT_EQ(m.get(), 1);
  EXPECT_EQ(runs_after, 4);
}

// ================================================================ cut-off

TEST(EngineCutOff, EqualWriteDoesNotReexecuteReaders) {
  Engine rt;
  Mod<int> in, half, out;
  int downstream = 0;
  rt.set(in, 4);
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([ph = &half](Engine& rt3, int v) { rt3.write(*ph, v / 2); }));
    rt2.read(half, body([po = &out, pd = &downstream](Engine& rt3, int h) { ++*pd; rt3.write(*po, h + 1); }));
  });
  expect_healthy(rt);
  EXPECT_EQ(out.get(), 3);
  EXPECT_EQ(downstream, 1);

  rt.set(in, 5);  // half stays 2
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);
  EXPECT_EQ(downstream, 1);
  EXPECT_EQ(out.get(), 3);

  rt.set(in, 6);  // half becomes 3
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(rt.stats().last_reexecuted, 2u);
  EXPECT_EQ(downstream, 2);
  EXPECT_EQ(out.get(), 4);
}

TEST(EngineCutOff, SettingAnEqualInputChangesNothing) {
  Engine rt;
  Mod<int> in, out;
  Mod<std::string> s, sout;
  rt.set(in, 4);
  rt.set(s, std::string("same"));
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([po = &out](Engine& rt3, int v) { rt3.write(*po, v); }));
    rt2.read(s, body([po = &sout](Engine& rt3, const std::string& v) { rt3.write(*po, v + "!"); }));
  });
  const std::uint64_t pushes = rt.stats().queue_pushes;
  rt.set(in, 4);
  rt.set(s, std::string("same"));
  EXPECT_EQ(rt.stats().queue_pushes, pushes);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(rt.stats().last_reexecuted, 0u);
  EXPECT_EQ(rt.stats().last_trace_distance, 0u);
  rt.set(s, std::string("other"));
  rt.propagate();
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);
  EXPECT_EQ(sout.get(), "other!");
  expect_healthy(rt);
}

TEST(EngineCutOff, InsertedOrRemovedVersionEqualToTheOlderOne) {
  // A write that appears (or disappears) with the same value as the version before it does
  // not affect the readers after it.
  Engine rt;
  Mod<int> in, m, out;
  int runs = 0;
  rt.set(in, 0);
  rt.run([&](Engine& rt2) {
    rt2.write(m, 1);
    rt2.read(in, body([pm = &m](Engine& rt3, int v) {
      if (v) rt3.write(*pm, 1);
    }));
    rt2.read(m, body([po = &out, r = &runs](Engine& rt3, int w) { ++*r; rt3.write(*po, w); }));
  });
  expect_healthy(rt);
  rt.set(in, 1);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);
  EXPECT_EQ(runs, 1);
  rt.set(in, 0);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);
  EXPECT_EQ(runs, 1);
  EXPECT_EQ(out.get(), 1);
}

// ================================================================ memo window rules

TEST(EngineMemo, MemoReadHitReusesTheRestOfAList) {
  const int n = 1000 / kScale;
  std::mt19937_64 rng(5);
  std::vector<long> values = random_values(rng, n);
  Engine rt;
  Input in(rt, values);
  MapProgram p;
  p.start(rt, in);
  expect_healthy(rt);
  ASSERT_EQ(p.result(), MapProgram::expected(in.sequence()));
  const Figures scratch = figures(rt);

  // Output cell of element k (its address must survive updates: keyed allocation).
  auto out_cell = [&](std::size_t k) {
    MapOut* o = p.out.get();
    for (std::size_t j = 0; j < k; ++j) o = o->next.get();
    return o;
  };
  const std::size_t i = static_cast<std::size_t>(n / 2);
  MapOut* const after = out_cell(i + 1);
  MapOut* const far = out_cell(static_cast<std::size_t>(n - 1));

  Stats s0 = rt.stats();
  const int steps0 = g_map_steps;
  in.remove(i);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(p.result(), MapProgram::expected(in.sequence()));
  EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 1u) << rt.stats();
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);
  EXPECT_EQ(g_map_steps - steps0, 1) << "only the step of the predecessor re-runs";
  EXPECT_LE(rt.stats().last_trace_distance, 10u) << "O(1) work expected";
  EXPECT_EQ(out_cell(i), after) << "the successor's output cell is reused";
  EXPECT_EQ(out_cell(static_cast<std::size_t>(n - 2)), far);
  EXPECT_EQ(figures(rt), fresh_figures<MapProgram>(values, in.presence()));

  s0 = rt.stats();
  in.reinsert(i);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(p.result(), MapProgram::expected(in.sequence()));
  EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 1u) << rt.stats();
  EXPECT_EQ(rt.stats().memo_misses - s0.memo_misses, 1u) << rt.stats();
  EXPECT_LE(rt.stats().last_reexecuted, 2u);
  EXPECT_LE(rt.stats().last_trace_distance, 12u);
  EXPECT_EQ(out_cell(i + 1), after);
  EXPECT_EQ(figures(rt), scratch);
}

TEST(EngineMemo, MemoHitInsideTheWindowSkipsTheCall) {
  Engine rt;
  Mod<int> in, o;
  int calls = 0;
  rt.set(in, 1);
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([po = &o, pc = &calls](Engine& rt3, int v) {
      rt3.write(*po, v);
      rt3.memo(sac::fn<bump>(pc, 7));
      rt3.memo(sac::fn<bump>(pc, 7));  // equal key twice: each call matches its own entry
    }));
  });
  expect_healthy(rt);
  EXPECT_EQ(calls, 2);
  const Figures scratch = figures(rt);
  for (int v = 2; v < 6; ++v) {
    const Stats s0 = rt.stats();
    rt.set(in, v);
    rt.propagate();
    expect_healthy(rt);
    EXPECT_EQ(o.get(), v);
    EXPECT_EQ(calls, 2) << "memoized calls must not re-run";
    EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 2u);
    EXPECT_EQ(rt.stats().memo_misses - s0.memo_misses, 0u);
    EXPECT_EQ(figures(rt), scratch);
  }
}

TEST(EngineMemo, EntryBeforeTheWindowIsNotReused) {
  Engine rt;
  Mod<int> in;
  int calls = 0;
  rt.set(in, 0);
  rt.run([&](Engine& rt2) {
    rt2.memo(sac::fn<bump>(&calls, 1));
    rt2.read(in, body([pc = &calls](Engine& rt3, int v) {
      if (v) rt3.memo(sac::fn<bump>(pc, 1));
    }));
  });
  EXPECT_EQ(calls, 1);
  const Stats s0 = rt.stats();
  rt.set(in, 1);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 0u);
  EXPECT_EQ(rt.stats().memo_misses - s0.memo_misses, 1u);
}

TEST(EngineMemo, EntryAfterTheWindowIsNotReused) {
  Engine rt;
  Mod<int> in;
  int calls = 0;
  rt.set(in, 0);
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([pc = &calls](Engine& rt3, int v) {
      if (v) rt3.memo(sac::fn<bump>(pc, 1));
    }));
    rt2.memo(sac::fn<bump>(&calls, 1));
  });
  EXPECT_EQ(calls, 1);
  const Stats s0 = rt.stats();
  rt.set(in, 1);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 0u);
  EXPECT_EQ(rt.stats().memo_misses - s0.memo_misses, 1u);
}

TEST(EngineMemo, EntryInAnEnclosingReadButOutsideTheInnerWindowIsNotReused) {
  // The entry lies inside the outer read's interval, before the inner read that re-runs.
  Engine rt;
  Mod<int> a, b;
  int calls = 0;
  rt.set(a, 0);
  rt.set(b, 0);
  rt.run([&](Engine& rt2) {
    rt2.read(a, body([pc = &calls, pb = &b](Engine& rt3, int) {
      rt3.memo(sac::fn<bump>(pc, 3));
      rt3.read(*pb, body([pc](Engine& rt4, int v) {
        if (v) rt4.memo(sac::fn<bump>(pc, 3));
      }));
    }));
  });
  EXPECT_EQ(calls, 1);
  Stats s0 = rt.stats();
  rt.set(b, 1);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);
  EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 0u);
  // Re-running the outer read: both entries are inside its window and are reused.
  s0 = rt.stats();
  rt.set(a, 1);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(calls, 2);
  // Both entries lie in the outer read's window: the first call matches the first entry and
  // the call made by the (new) inner read matches the old inner read's entry.
  EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 2u);
}

void reader_of(Engine& rt, const int& v, int* runs, Mod<int>* dst) {
  ++*runs;
  rt.write(*dst, v);
}

TEST(EngineMemo, MemoReadOutsideTheWindowIsNotReused) {
  Engine rt;
  Mod<int> in, m, d1;
  int runs = 0;
  rt.set(in, 0);
  rt.set(m, 5);
  rt.run([&](Engine& rt2) {
    rt2.memo_read(m, sac::fn<reader_of>(&runs, &d1));
    rt2.read(in, body([pm = &m, pr = &runs, pd = &d1](Engine& rt3, int v) {
      if (v) rt3.memo_read(*pm, sac::fn<reader_of>(pr, pd));
    }));
  });
  EXPECT_EQ(runs, 1);
  const Stats s0 = rt.stats();
  rt.set(in, 1);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(runs, 2);
  EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 0u);
  EXPECT_EQ(rt.stats().memo_misses - s0.memo_misses, 1u);
  EXPECT_EQ(d1.get(), 5);
}

void triple(Engine& rt, Mod<int>* src, Mod<int>* dst, int* runs) {
  rt.read(*src, body([dst, runs](Engine& rt2, int x) {
    ++*runs;
    rt2.write(*dst, 3 * x);
  }));
}

TEST(EngineMemo, AffectedReadsInsideAReusedEntryArePropagated) {
  Engine rt;
  Mod<int> in, mid, out, in2, out2;
  int runs = 0, runs2 = 0;
  rt.set(in, 1);
  rt.set(in2, 10);
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([pmid = &mid, pout = &out, pr = &runs, pin2 = &in2, pout2 = &out2,
                 pr2 = &runs2](Engine& rt3, int v) {
      rt3.write(*pmid, v);
      // Reused on re-execution, but the read inside depends on the new `mid`...
      rt3.memo(sac::fn<triple>(pmid, pout, pr));
      // ... and this one on an input changed in the same batch.
      rt3.memo(sac::fn<triple>(pin2, pout2, pr2));
    }));
  });
  expect_healthy(rt);
  EXPECT_EQ(out.get(), 3);
  EXPECT_EQ(out2.get(), 30);
  const Figures scratch = figures(rt);

  Stats s0 = rt.stats();
  rt.set(in, 5);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(out.get(), 15);
  EXPECT_EQ(out2.get(), 30);
  EXPECT_EQ(runs, 2);
  EXPECT_EQ(runs2, 1);
  EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 2u);
  EXPECT_EQ(rt.stats().last_reexecuted, 2u);
  EXPECT_EQ(figures(rt), scratch);

  s0 = rt.stats();
  rt.set(in, 6);
  rt.set(in2, 11);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(out.get(), 18);
  EXPECT_EQ(out2.get(), 33);
  EXPECT_EQ(runs, 3);
  EXPECT_EQ(runs2, 2);
  EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 2u);
  EXPECT_EQ(rt.stats().last_reexecuted, 3u);
  EXPECT_EQ(figures(rt), scratch);
}

// ================================================================ keyed allocation

TEST(EngineAlloc, SameKeyInTheWindowReturnsTheSameObject) {
  Counted::reset();
  {
    Engine rt;
    Mod<int> in;
    Mod<Counted*> out;
    rt.set(in, 1);
    rt.run([&](Engine& rt2) {
      rt2.read(in, body([po = &out](Engine& rt3, int v) {
        Counted* c = rt3.alloc<Counted>(42, v);
        rt3.write(c->m, v);
        rt3.write(*po, c);
      }));
    });
    expect_healthy(rt);
    Counted* const first = out.get();
    ASSERT_NE(first, nullptr);
    EXPECT_EQ(Counted::ctor, 1);
    const Figures scratch = figures(rt);
    for (int v = 2; v <= 5; ++v) {
      const Stats s0 = rt.stats();
      rt.set(in, v);
      rt.propagate();
      expect_healthy(rt);
      EXPECT_EQ(out.get(), first) << "same key, same object";
      EXPECT_EQ(Counted::ctor, 1) << "the constructor must not run again";
      EXPECT_EQ(Counted::dtor, 0);
      EXPECT_EQ(first->v, 1) << "a reused object keeps its state";
      EXPECT_EQ(first->m.get(), v);
      EXPECT_EQ(rt.stats().alloc_reuses - s0.alloc_reuses, 1u);
      EXPECT_EQ(figures(rt), scratch);
    }
  }
  EXPECT_EQ(Counted::dtor, Counted::ctor);
}

TEST(EngineAlloc, EqualKeysInOneRunAreDistinctAndReusedInOrder) {
  Counted::reset();
  {
    Engine rt;
    Mod<int> in;
    Mod<Counted*> o1, o2;
    rt.set(in, 1);
    rt.run([&](Engine& rt2) {
      rt2.read(in, body([p1 = &o1, p2 = &o2](Engine& rt3, int v) {
        Counted* a = rt3.alloc<Counted>(7, v);
        Counted* b = rt3.alloc<Counted>(7, v + 100);
        rt3.write(*p1, a);
        rt3.write(*p2, b);
      }));
    });
    expect_healthy(rt);
    Counted* const a = o1.get();
    Counted* const b = o2.get();
    EXPECT_NE(a, b) << "a from-scratch run never shares keyed objects";
    EXPECT_EQ(a->v, 1);
    EXPECT_EQ(b->v, 101);
    rt.set(in, 2);
    rt.propagate();
    expect_healthy(rt);
    EXPECT_EQ(o1.get(), a);
    EXPECT_EQ(o2.get(), b);
    EXPECT_EQ(Counted::ctor, 2);
    EXPECT_EQ(Counted::dtor, 0);
  }
  EXPECT_EQ(Counted::dtor, Counted::ctor);
}

/// read(in, v -> out = alloc<Counted>(key v)); one closure type for every engine.
void run_keyed_by_value(Engine& rt, Mod<int>& in, Mod<Counted*>& out) {
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([po = &out](Engine& rt3, int v) {
      Counted* c = rt3.alloc<Counted>(v, v);  // the key follows the input
      rt3.write(*po, c);
    }));
  });
}

TEST(EngineAlloc, DifferentKeyGivesANewObjectAndTheOldOneIsDestroyed) {
  Counted::reset();
  {
    Engine rt;
    Mod<int> in;
    Mod<Counted*> out;
    rt.set(in, 1);
    run_keyed_by_value(rt, in, out);
    expect_healthy(rt);
    for (int v = 2; v <= 6; ++v) {
      Counted* const old = out.get();
      const int c0 = Counted::ctor, d0 = Counted::dtor;
      rt.set(in, v);
      rt.propagate();
      expect_healthy(rt);
      EXPECT_NE(out.get(), old);
      EXPECT_EQ(out.get()->v, v);
      EXPECT_EQ(Counted::ctor - c0, 1);
      EXPECT_EQ(Counted::dtor - d0, 1) << "undone allocations are destroyed by propagate()";
      // Same live trace as a fresh engine running the same program on the same input.
      Engine rt2;
      Mod<int> fin;
      Mod<Counted*> fout;
      rt2.set(fin, v);
      run_keyed_by_value(rt2, fin, fout);
      EXPECT_EQ(figures(rt), figures(rt2));
    }
  }
  EXPECT_EQ(Counted::dtor, Counted::ctor);
}

TEST(EngineAlloc, UnkeyedMakeIsFreedWhenUndone) {
  Counted::reset();
  {
    Engine rt;
    Mod<int> in;
    Mod<Counted*> out;
    rt.set(in, 0);
    rt.run([&](Engine& rt2) {
      rt2.read(in, body([po = &out](Engine& rt3, int v) {
        Counted* c = rt3.make<Counted>(v);
        rt3.make<std::vector<int>>(100, v);  // an object owning heap memory (leak check)
        rt3.write(*po, c);
      }));
    });
    const Figures scratch = figures(rt);
    for (int v = 1; v <= 20; ++v) {
      rt.set(in, v);
      rt.propagate();
      expect_healthy(rt);
      EXPECT_EQ(out.get()->v, v);
      EXPECT_EQ(Counted::ctor, v + 1);
      EXPECT_EQ(Counted::dtor, v);
      EXPECT_EQ(figures(rt), scratch);
    }
  }
  EXPECT_EQ(Counted::dtor, Counted::ctor);
}

// ================================================================ undo

TEST(EngineUndo, RemovedWriteRestoresTheOlderVersionAndDropsItsTrace) {
  Counted::reset();
  int calls = 0;
  auto program = [&calls](Engine& rt, Mod<int>& in, Mod<int>& m, Mod<int>& out) {
    rt.run([&](Engine& rt2) {
      rt2.write(m, 1);
      rt2.read(in, body([pm = &m, pc = &calls](Engine& rt3, int v) {
        if (v) {
          rt3.write(*pm, 2);
          rt3.memo(sac::fn<bump>(pc, v));
          rt3.make<Counted>(v);
          rt3.read(*pm, body([](Engine&, int) {}));
        }
      }));
      rt2.read(m, body([po = &out](Engine& rt3, int w) { rt3.write(*po, w); }));
    });
  };
  auto fresh = [&](int v) {
    Engine rt;
    Mod<int> in, m, out;
    rt.set(in, v);
    program(rt, in, m, out);
    EXPECT_EQ(out.get(), v ? 2 : 1);
    return figures(rt);
  };
  {
    Engine rt;
    Mod<int> in, m, out;
    rt.set(in, 1);
    program(rt, in, m, out);
    expect_healthy(rt);
    EXPECT_EQ(out.get(), 2);
    const Figures with_write = figures(rt);
    EXPECT_EQ(with_write, fresh(1));

    rt.set(in, 0);
    rt.propagate();
    expect_healthy(rt);
    EXPECT_EQ(out.get(), 1) << "the later reader sees the older version again";
    EXPECT_EQ(m.get(), 1);
    EXPECT_EQ(figures(rt), fresh(0)) << "write, memo entry, allocation and read all undone";
    EXPECT_LT(figures(rt).record_bytes, with_write.record_bytes);

    rt.set(in, 1);
    rt.propagate();
    expect_healthy(rt);
    EXPECT_EQ(out.get(), 2);
    EXPECT_EQ(figures(rt), with_write);
    rt.set(in, 0);
    rt.propagate();
    expect_healthy(rt);
    EXPECT_EQ(figures(rt), fresh(0));
  }
  EXPECT_EQ(Counted::dtor, Counted::ctor);
}

// ================================================================ batches

TEST(EngineBatch, SeveralSetsThenOnePropagateEqualsFromScratch) {
  const int n = 50;
  Engine rt;
  std::vector<Mod<int>> xs(n);
  std::vector<Mod<int>> ys(n);
  for (int i = 0; i < n; ++i) rt.set(xs[static_cast<std::size_t>(i)], i);
  rt.run([&](Engine& rt2) {
    for (int i = 0; i < n; ++i)
      rt2.read(xs[static_cast<std::size_t>(i)],
              body([py = &ys[static_cast<std::size_t>(i)]](Engine& rt3, int v) { rt3.write(*py, v * v); }));
  });
  const Figures scratch = figures(rt);
  rt.set(xs[3], 30);
  rt.set(xs[40], 400);
  rt.set(xs[17], 170);
  rt.set(xs[17], 17);  // back to the original value inside the batch
  rt.set(xs[3], 31);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(rt.stats().last_reexecuted, 3u);  // 3, 40 and 17 (17 was enqueued, then restored)
  for (int i = 0; i < n; ++i) {
    const int x = i == 3 ? 31 : i == 40 ? 400 : i;
    EXPECT_EQ(ys[static_cast<std::size_t>(i)].get(), x * x);
  }
  EXPECT_EQ(figures(rt), scratch);
}

TEST(EngineBatch, ListBatchesMatchAFreshRun) {
  std::mt19937_64 rng(77);
  const int n = 200 / kScale;
  std::vector<long> values = random_values(rng, n);
  Engine rt;
  Input in(rt, values);
  PsumProgram p;
  p.start(rt, in);
  for (int round = 0; round < 20; ++round) {
    const int k = 2 + static_cast<int>(rng() % 12);
    for (int j = 0; j < k; ++j) in.toggle(rng() % static_cast<std::size_t>(n));
    rt.propagate();
    expect_healthy(rt);
    std::vector<long> scratch_result;
    const Figures scratch = fresh_figures<PsumProgram>(values, in.presence(), &scratch_result);
    ASSERT_EQ(p.result(), PsumProgram::expected(in.sequence())) << "round " << round;
    ASSERT_EQ(p.result(), scratch_result);
    ASSERT_EQ(figures(rt), scratch) << "round " << round;
  }
}

// ================================================================ misuse

TEST(EngineMisuse, ReadingANeverWrittenModifiablePoisons) {
  Engine rt;
  Mod<int> never, in;
  rt.set(in, 1);
  EXPECT_THROW(rt.run([&](Engine& rt2) { rt2.read(never, body([](int) {})); }), sac::UsageError);
  EXPECT_TRUE(rt.poisoned());
  EXPECT_FALSE(rt.in_computation());
  EXPECT_THROW(rt.run([](Engine&) {}), sac::PoisonedError);
  EXPECT_THROW(rt.propagate(), sac::PoisonedError);
  EXPECT_THROW(rt.set(in, 2), sac::PoisonedError);
  EXPECT_THROW(rt.read(in, body([](int) {})), sac::PoisonedError);
  EXPECT_THROW(rt.write(in, 3), sac::PoisonedError);
  EXPECT_THROW(never.get(), sac::UsageError);
}

TEST(EngineMisuse, ReadingANeverWrittenModifiableNestedInsideAReadPoisons) {
  Engine rt;
  Mod<int> never, in;
  Mod<std::string> keep;
  rt.set(in, 1);
  EXPECT_THROW(rt.run([&](Engine& rt2) {
    rt2.write(keep, std::string(200, 'k'));
    rt2.read(in, body([pn = &never, s = std::string(300, 's')](Engine& rt3, int) {
      rt3.make<std::string>(s);
      rt3.read(*pn, body([s](int) {}));
    }));
  }),
               sac::UsageError);
  EXPECT_TRUE(rt.poisoned());
}  // destroying the poisoned engine must not leak (LeakSanitizer)

TEST(EngineMisuse, AReadLosingItsOnlyVersionFailsInPropagate) {
  Engine rt;
  Mod<int> in, m, out;
  rt.set(in, 1);
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([pm = &m](Engine& rt3, int v) {
      if (v) rt3.write(*pm, v);
    }));
    rt2.read(m, body([po = &out](Engine& rt3, int w) { rt3.write(*po, w); }));
  });
  expect_healthy(rt);
  rt.set(in, 0);  // m is no longer written before its reader
  EXPECT_THROW(rt.propagate(), sac::UsageError);
  EXPECT_TRUE(rt.poisoned());
  EXPECT_THROW(rt.propagate(), sac::PoisonedError);
}

TEST(EngineMisuse, MutatorCallsFromInsideABodyAreRejected) {
  Engine rt;
  Mod<int> in, x, out;
  int rejected = 0;
  rt.set(in, 1);
  rt.set(x, 1);
  auto probe = [&](Engine& rt2) {
    EXPECT_THROW(rt2.propagate(), sac::UsageError);
    EXPECT_THROW(rt2.run([](Engine&) {}), sac::UsageError);
    EXPECT_THROW(rt2.set(x, 5), sac::UsageError);
    EXPECT_THROW(rt2.check_invariants(), sac::UsageError);
    EXPECT_TRUE(rt2.in_computation());
    ++rejected;
  };
  rt.run([&](Engine& rt2) {
    probe(rt2);
    rt2.read(in, body([&probe, po = &out](Engine& rt3, int v) {
      // (The probe lambda lives in this test's frame, which outlives the engine's use.)
      probe(rt3);
      rt3.write(*po, v);
    }));
  });
  EXPECT_EQ(rejected, 2);
  EXPECT_FALSE(rt.poisoned()) << "errors caught inside a body leave the engine usable";
  expect_healthy(rt);
  rt.set(in, 2);
  rt.propagate();
  EXPECT_EQ(rejected, 3);
  EXPECT_EQ(out.get(), 2);
  EXPECT_EQ(x.get(), 1);
  expect_healthy(rt);

  // Uncaught, the error leaves run() and poisons the engine.
  EXPECT_THROW(rt.run([&](Engine& rt2) {
    rt2.read(in, body([px = &x](Engine& rt3, int) { rt3.set(*px, 9); }));
  }),
               sac::UsageError);
  EXPECT_TRUE(rt.poisoned());
}

TEST(EngineMisuse, ComputationCallsOutsideTheComputationAreRejected) {
  Engine rt;
  Mod<int> m, out;
  rt.set(m, 1);
  EXPECT_THROW(rt.read(m, body([](int) {})), sac::UsageError);
  EXPECT_THROW(rt.write(m, 2), sac::UsageError);
  EXPECT_THROW(rt.alloc<int>(1, 2), sac::UsageError);
  EXPECT_THROW(rt.make<int>(2), sac::UsageError);
  int calls = 0;
  EXPECT_THROW(rt.memo(sac::fn<bump>(&calls, 1)), sac::UsageError);
  EXPECT_THROW(rt.memo_read(m, sac::fn<reader_of>(&calls, &out)), sac::UsageError);
  EXPECT_EQ(calls, 0);
  EXPECT_FALSE(rt.poisoned()) << "a rejected call changes nothing";
  EXPECT_EQ(m.get(), 1);
  EXPECT_EQ(rt.live_events(), 0u);
  rt.run([&](Engine& rt2) { rt2.read(m, body([po = &out](Engine& rt3, int v) { rt3.write(*po, v); })); });
  EXPECT_EQ(out.get(), 1);
  expect_healthy(rt);
}

TEST(EngineMisuse, RetireRules) {
  Engine rt;
  Mod<int> m, n, out;
  rt.set(m, 1);
  rt.set(n, 2);
  rt.run([&](Engine& rt2) { rt2.read(m, body([po = &out](Engine& rt3, int v) { rt3.write(*po, v); })); });
  EXPECT_THROW(rt.retire(m), sac::UsageError);  // still read
  EXPECT_THROW(rt.retire(out), sac::UsageError);  // written by the computation
  const std::size_t input = rt.input_bytes();
  const std::size_t records = rt.record_bytes();
  rt.retire(n);
  EXPECT_FALSE(n.written());
  EXPECT_LT(rt.input_bytes(), input);
  EXPECT_EQ(rt.record_bytes(), records) << "base versions are not trace records";
  rt.set(n, 3);
  EXPECT_EQ(n.get(), 3);
  expect_healthy(rt);
}

// init() names a modifiable lazily, inside the computation, with a default that every run
// would see; a later write before an earlier reader re-runs that reader.
TEST(EngineInit, LazilyNamedDefaultsBehaveLikeInputs) {
  Engine rt;
  Mod<int> flag, lazy, out, src;
  rt.set(src, 0);
  rt.set(flag, 0);
  rt.run([&](Engine& rt2) {
    // The reader of `lazy` comes first; the write (when src is 1) comes after it.
    rt2.read(flag, body([pl = &lazy, po = &out](Engine& rt3, int) {
      if (!pl->written()) rt3.init(*pl, 7);
      rt3.read(*pl, body([po](Engine& rt4, int v) { rt4.write(*po, v); }));
    }));
    rt2.read(src, body([pl = &lazy](Engine& rt3, int v) {
      if (!pl->written()) rt3.init(*pl, 7);
      if (v) rt3.write(*pl, 9);
    }));
  });
  EXPECT_EQ(out.get(), 7);
  EXPECT_FALSE(rt.unused(lazy)) << "it is read";
  EXPECT_THROW(rt.init(lazy, 1), sac::UsageError) << "already written";
  rt.set(src, 1);
  rt.propagate();
  EXPECT_EQ(out.get(), 7) << "the write comes after the read";
  EXPECT_EQ(lazy.get(), 9);
  expect_healthy(rt);
}

TEST(EngineInit, UnusedOnceNothingInTheTraceRefersToIt) {
  Engine rt;
  Mod<int> sel, a, b, out;
  rt.set(sel, 0);
  rt.run([&](Engine& rt2) {
    rt2.read(sel, body([pa = &a, pb = &b, po = &out](Engine& rt3, int v) {
      Mod<int>* m = v ? pb : pa;
      if (!m->written()) rt3.init(*m, v ? 20 : 10);
      rt3.read(*m, body([po](Engine& rt4, int w) { rt4.write(*po, w); }));
    }));
  });
  EXPECT_EQ(out.get(), 10);
  EXPECT_FALSE(rt.unused(a));
  EXPECT_TRUE(rt.unused(b)) << "never named";
  rt.set(sel, 1);
  rt.propagate();
  EXPECT_EQ(out.get(), 20);
  EXPECT_TRUE(rt.unused(a)) << "its only reader was undone";
  EXPECT_FALSE(rt.unused(b));
  EXPECT_FALSE(rt.unused(out)) << "written by the computation";
  rt.retire(a);
  EXPECT_FALSE(a.written());
  expect_healthy(rt);
}

// ---- init_default(): a default that costs nothing until a read sees it

TEST(EngineInitDefault, ReadsTheDefaultAndBehavesAsAWrittenModifiable) {
  Engine rt;
  Mod<int> d, out;
  Mod<const int*> p;
  rt.init_default(d);
  rt.init_default(p);
  EXPECT_TRUE(d.written()) << "a default is a value";
  EXPECT_EQ(d.get(), 0);
  EXPECT_EQ(p.get(), nullptr);
  EXPECT_TRUE(rt.unused(d));
  EXPECT_EQ(rt.input_bytes(), 0u) << "nothing is made before a read";
  EXPECT_THROW(rt.init_default(d), sac::UsageError) << "already has a value";
  EXPECT_THROW(rt.init(d, 1), sac::UsageError) << "already has a value";
  rt.run([&](Engine& rt2) { rt2.read(d, body([po = &out](Engine& rt3, int v) { rt3.write(*po, v + 1); })); });
  EXPECT_EQ(out.get(), 1);
  EXPECT_EQ(rt.input_bytes(), 0u) << "the read hangs on the modifiable: no version is made";
  EXPECT_FALSE(rt.unused(d));
  EXPECT_THROW(rt.retire(d), sac::UsageError) << "still read";
  EXPECT_TRUE(rt.unused(p));
  rt.retire(p);
  EXPECT_FALSE(p.written());
  expect_healthy(rt);
  // set() on a default that a read saw: the default becomes a base version, then changes.
  rt.set(d, 4);
  EXPECT_EQ(rt.input_bytes(), sac::kIntInput);
  rt.propagate();
  EXPECT_EQ(out.get(), 5);
  expect_healthy(rt);
}

// Reads of a default with no version hang on the modifiable (no version is made); a write
// earlier in time makes the default a base version and moves them onto it; undoing it gives
// them the default back, cut off when the value is the same; a memo_read of such a default
// is found and reused by a re-execution.
TEST(EngineInitDefault, ReadsOfADefaultHangOnTheModifiableUntilItHasAVersion) {
  Engine rt;
  Mod<int> sel, d, out1, out2, out3;
  int runs = 0;
  rt.init_default(d);
  rt.set(sel, 0);
  rt.run([&](Engine& rt2) {
    rt2.read(sel, body([pd = &d, po = &out3, pr = &runs](Engine& rt3, int s) {
      if (s == 1) rt3.write(*pd, 7);
      if (s == 2) rt3.write(*pd, 0);  // the default's value: its readers are cut off
      rt3.write(*po, s);
      if (s != 3) rt3.memo_read(*pd, sac::fn<reader_of>(pr, po));
    }));
    rt2.read(d, body([po = &out1](Engine& rt3, int v) { rt3.write(*po, v + 1); }));
    rt2.read(d, body([po = &out2](Engine& rt3, int v) { rt3.write(*po, v + 2); }));
  });
  EXPECT_EQ(out1.get(), 1);
  EXPECT_EQ(out2.get(), 2);
  EXPECT_EQ(out3.get(), 0);
  EXPECT_EQ(runs, 1);
  EXPECT_EQ(rt.input_bytes(), sac::kIntInput) << "sel's base version only: the three reads of d hang on d";
  EXPECT_FALSE(rt.unused(d));
  expect_healthy(rt);

  rt.set(sel, 3);  // the memo_read goes: one default reader fewer
  rt.propagate();
  expect_healthy(rt);
  rt.set(sel, 0);  // and comes back, run again
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(runs, 2);
  EXPECT_EQ(rt.input_bytes(), sac::kIntInput);

  rt.set(sel, 1);  // a version before the reads: the default becomes a base version
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(out1.get(), 8);
  EXPECT_EQ(out2.get(), 9);
  EXPECT_EQ(out3.get(), 7) << "the memo_read saw the write";
  EXPECT_EQ(rt.input_bytes(), 2 * sac::kIntInput);

  rt.set(sel, 0);  // undone: the readers see the default again
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(out1.get(), 1);
  EXPECT_EQ(out2.get(), 2);
  EXPECT_EQ(out3.get(), 0);

  rt.set(sel, 2);  // a write equal to the default: only sel's reader runs again
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);
  EXPECT_EQ(out3.get(), 0);
}

TEST(EngineInitDefault, MemoReadOfADefaultWithoutVersionIsReused) {
  Engine rt;
  Mod<int> in, d, out, dst;
  int runs = 0;
  rt.init_default(d);
  rt.set(in, 1);
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([pd = &d, po = &out, pr = &runs, pt = &dst](Engine& rt3, int v) {
      rt3.write(*po, v);
      rt3.memo_read(*pd, sac::fn<reader_of>(pr, pt));
    }));
  });
  EXPECT_EQ(runs, 1);
  const Stats s0 = rt.stats();
  rt.set(in, 2);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(out.get(), 2);
  EXPECT_EQ(runs, 1) << "the old read of the default was found on d and reused";
  EXPECT_EQ(rt.stats().memo_hits - s0.memo_hits, 1u);
  EXPECT_EQ(rt.input_bytes(), sac::kIntInput);
}

/// The program of the differential test below: for each input a[i] (in order), a value
/// v < k writes i + 1 to cell v, and k + c reads cell c into out[i] (0 where none). Cells
/// are named lazily with init_default(), so a cell read before any write sees its default.
struct DefaultCells {
  explicit DefaultCells(std::size_t n, std::size_t k) : a(n), out(n), cells(k) {}
  std::vector<Mod<int>> a, out, cells;

  void run(Engine& rt) {
    rt.run([this](Engine& rt2) {
      for (std::size_t i = 0; i < a.size(); ++i)
        rt2.read(a[i], body([this, i](Engine& rt3, int v) {
          const std::size_t k = cells.size();
          Mod<int>& c = cells[static_cast<std::size_t>(v) % k];
          if (!c.written()) rt3.init_default(c);
          if (static_cast<std::size_t>(v) < k) return rt3.write(c, static_cast<int>(i) + 1);
          rt3.read(c, body([po = &out[i]](Engine& rt4, int w) { rt4.write(*po, w); }));
          return;
        }));
    });
  }
};

// Every output equals a from-scratch run's after every update, on random inputs with a
// fixed, printed seed; and a from-scratch run makes base versions exactly for the cells
// whose first event is a read and that are written later (a default only read hangs its
// reads on the modifiable).
TEST(EngineInitDefault, DifferentialAgainstFromScratch) {
  constexpr std::size_t n = 60, k = 12;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    std::vector<int> in(n);
    for (int& v : in) v = static_cast<int>(rng() % (2 * k));
    Engine rt;
    DefaultCells dyn(n, k);
    for (std::size_t i = 0; i < n; ++i) rt.set(dyn.a[i], in[i]);
    dyn.run(rt);
    for (int step = 0; step < 150; ++step) {
      const std::size_t i = rng() % n;
      in[i] = static_cast<int>(rng() % (2 * k));
      rt.set(dyn.a[i], in[i]);
      rt.propagate();
      ASSERT_NO_THROW(rt.check_invariants()) << "step " << step;

      Engine rt2;
      DefaultCells fresh(n, k);
      for (std::size_t j = 0; j < n; ++j) rt2.set(fresh.a[j], in[j]);
      fresh.run(rt2);
      std::vector<bool> written(k), named(k), read_first(k);
      for (std::size_t j = 0; j < n; ++j) {
        const std::size_t v = static_cast<std::size_t>(in[j]), c = v % k;
        if (v < k) written[c] = true;
        else if (!written[c] && !named[c]) read_first[c] = true;
        named[c] = true;
        if (v >= k) {
          ASSERT_EQ(dyn.out[j].get(), fresh.out[j].get()) << "step " << step << ", out " << j;
        }
      }
      std::size_t read_then_written = 0;
      for (std::size_t c = 0; c < k; ++c) read_then_written += read_first[c] && written[c];
      ASSERT_EQ(rt2.input_bytes(), (n + read_then_written) * sac::kIntInput)
          << "base versions: the inputs and the defaults read first and written later";
    }
    expect_healthy(rt);
  }
}

// ---- set_context(): what the bodies reach through the Engine instead of their closures

struct Scale {
  int factor;
};

TEST(EngineContext, BodiesReachTheContextAndTheTypeIsChecked) {
  Engine rt;
  EXPECT_THROW(rt.context<Scale>(), sac::UsageError) << "none set";
  Scale ctx{3};
  rt.set_context(&ctx);
  EXPECT_EQ(rt.context<Scale>(), &ctx);
  EXPECT_THROW(rt.context<int>(), sac::UsageError) << "another type";
  Mod<int> in, out;
  rt.set(in, 2);
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([po = &out](Engine& rt3, int v) { rt3.write(*po, v * rt3.context<Scale>()->factor); }));
  });
  EXPECT_EQ(out.get(), 6);
  rt.set(in, 5);
  rt.propagate();
  EXPECT_EQ(out.get(), 15) << "a re-executed body reaches it too";
  expect_healthy(rt);
}

void maybe_throw(Engine& rt, Mod<int>* src, int bad) {
  rt.make<std::string>(std::string(100, 'm'));
  rt.read(*src, body([bad, s = std::string(64, 'q')](Engine& rt2, int v) {
    rt2.make<Counted>(v);
    if (v == bad) throw std::runtime_error("body failed: " + s.substr(0, 4));
  }));
}

TEST(EngineMisuse, BodyThrowingInRunPropagatesAndPoisons) {
  Counted::reset();
  {
    Engine rt;
    Mod<int> in;
    rt.set(in, 13);
    EXPECT_THROW(rt.run([&](Engine& rt2) {
      rt2.read(in, body([pin = &in, s = std::string(80, 'a')](Engine& rt3, int v) {
        rt3.alloc<Counted>(1, v);
        rt3.make<std::vector<std::string>>(3, s);
        rt3.read(*pin, body([s](Engine& rt4, int w) {
          rt4.make<Counted>(w);
          if (w == 13) throw std::runtime_error("boom " + s.substr(0, 1));
        }));
        rt3.read(*pin, body([s](Engine&, int) {}));  // issued, never run
      }));
    }),
                 std::runtime_error);
    EXPECT_TRUE(rt.poisoned());
    EXPECT_FALSE(rt.in_computation());
    EXPECT_THROW(rt.run([](Engine&) {}), sac::PoisonedError);
    EXPECT_THROW(rt.propagate(), sac::PoisonedError);
  }
  EXPECT_EQ(Counted::dtor, Counted::ctor) << "destroying a poisoned engine frees everything";
}

TEST(EngineMisuse, MemoBodyThrowingInRunPoisons) {
  Counted::reset();
  {
    Engine rt;
    Mod<int> in;
    rt.set(in, 4);
    EXPECT_THROW(rt.run([&](Engine& rt2) { rt2.memo(sac::fn<maybe_throw>(&in, 4)); }),
                 std::runtime_error);
    EXPECT_TRUE(rt.poisoned());
  }
  EXPECT_EQ(Counted::dtor, Counted::ctor);
}

TEST(EngineMisuse, BodyThrowingInPropagatePropagatesAndPoisons) {
  Counted::reset();
  {
    Engine rt;
    Mod<int> in, other;
    Mod<Counted*> out;
    rt.set(in, 1);
    rt.set(other, 1);
    rt.run([&](Engine& rt2) {
      // Re-runs first and undoes its allocation (a deferred free) before the throw below.
      rt2.read(in, body([po = &out](Engine& rt3, int v) { rt3.write(*po, rt3.alloc<Counted>(v, v)); }));
      rt2.memo(sac::fn<maybe_throw>(&in, 13));
      rt2.read(other, body([](Engine& rt3, int v) { rt3.make<std::string>(std::string(50, 'o') + std::to_string(v)); }));
    });
    expect_healthy(rt);
    rt.set(in, 13);
    rt.set(other, 2);
    EXPECT_THROW(rt.propagate(), std::runtime_error);
    EXPECT_TRUE(rt.poisoned());
    EXPECT_FALSE(rt.in_computation());
    EXPECT_THROW(rt.propagate(), sac::PoisonedError);
    EXPECT_THROW(rt.set(in, 1), sac::PoisonedError);
  }
  EXPECT_EQ(Counted::dtor, Counted::ctor);
}

// ================================================================ program order
//
// Calls (read, memo_read, memo) may be deferred by the engine, but a write/alloc/make that a
// body performs after a call must land after that call's whole interval (engine.hpp: "the
// events happen in program order, exactly as if every call ran on the spot").

// A body that issues a read and then writes: flush() runs the read, and its close must not
// be chained onto the *running* parent's pending close, or the parent's later write would be
// recorded inside the nested read's interval and re-running the nested read would undo it
// (out2 below would lose its only version). Same for alloc/make after a call, and for memo().
TEST(EngineOrder, WriteAfterANestedReadStaysOutsideIt) {
  Engine rt;
  Mod<int> a, b, out1, out2;
  rt.set(a, 1);
  rt.set(b, 10);
  rt.run([&](Engine& rt2) {
    rt2.read(a, body([pb = &b, p1 = &out1, p2 = &out2](Engine& rt3, int va) {
      rt3.read(*pb, body([p1](Engine& rt4, int vb) { rt4.write(*p1, vb); }));
      rt3.write(*p2, va);  // after the nested read, in the outer read's own interval
    }));
  });
  expect_healthy(rt);
  ASSERT_EQ(out1.get(), 10);
  ASSERT_EQ(out2.get(), 1);
  rt.set(b, 20);  // re-runs only the nested read
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);
  EXPECT_EQ(out1.get(), 20);
  ASSERT_TRUE(out2.written()) << "the outer read's write was undone by the nested read";
  EXPECT_EQ(out2.get(), 1);
  EXPECT_EQ(rt.live_events(), 4u);
}

TEST(EngineOrder, AllocAndMakeAfterNestedCallsStayOutsideThem) {
  // Failing with the bug above (the allocations land inside the memo entry / the read).
  Counted::reset();
  {
    Engine rt;
    Mod<int> a, b;
    Mod<Counted*> keyed, plain;
    int calls = 0;
    rt.set(a, 1);
    rt.set(b, 1);
    rt.run([&](Engine& rt2) {
      rt2.read(a, body([pb = &b, pk = &keyed, pp = &plain, pc = &calls](Engine& rt3, int va) {
        rt3.memo(sac::fn<bump>(pc, 1));
        rt3.write(*pk, rt3.alloc<Counted>(9, va));
        rt3.read(*pb, body([](Engine&, int) {}));
        rt3.write(*pp, rt3.make<Counted>(va));
      }));
    });
    expect_healthy(rt);
    const Figures scratch = figures(rt);
    EXPECT_EQ(scratch.live_events, 7u);  // read, memo, alloc, write, read, make, write
    Counted* const k0 = keyed.get();
    for (int v = 2; v < 5; ++v) {
      rt.set(a, v);
      rt.propagate();
      expect_healthy(rt);
      EXPECT_EQ(keyed.get(), k0) << "the keyed object after the memo call is reused";
      EXPECT_EQ(plain.get()->v, v);
      EXPECT_EQ(calls, 1);
      EXPECT_EQ(figures(rt), scratch) << "the trace must not grow with updates";
      rt.set(b, v);  // re-runs the nested read alone: must not undo the make after it
      rt.propagate();
      expect_healthy(rt);
      ASSERT_TRUE(plain.written());
      EXPECT_EQ(plain.get()->v, v);
      EXPECT_EQ(figures(rt), scratch);
    }
  }
  EXPECT_EQ(Counted::dtor, Counted::ctor);
}

// ================================================================ regressions

TEST(EngineClosures, PlainLambdaReadBodies) {
  // read() accepts lambdas (no operator==): the documented pattern, verbatim, a lambda
  // capturing by value as a read body.
  Engine rt;
  Mod<int> in, out;
  rt.set(in, 1);
  rt.run([&](Engine& rt2) {
    rt2.read(in, [po = &out, s = std::string(40, 'x')](Engine& rt3, int v) {
      rt3.write(*po, v + static_cast<int>(s.size()));
    });
    rt2.read(in, [](int) {});
  });
  EXPECT_EQ(out.get(), 41);
  rt.set(in, 2);
  rt.propagate();
  EXPECT_EQ(out.get(), 42);
  expect_healthy(rt);
}


// ================================================================ closure lifetimes

/// Counts live instances of the closures that hold it.
struct LiveCount {
  static inline long live = 0;
  LiveCount() { ++live; }
  LiveCount(const LiveCount&) { ++live; }
  LiveCount(LiveCount&&) noexcept { ++live; }
  LiveCount& operator=(const LiveCount&) = default;
  LiveCount& operator=(LiveCount&&) noexcept = default;
  ~LiveCount() { --live; }
};

/// A closure type with a non-trivial destructor and heap-owning members captured by value.
struct CapturingBody {
  std::string label;
  std::vector<int> data;
  LiveCount lc;
  Mod<long>* out;
  Mod<int>* inner;
  void operator()(Engine& rt, const int& v) const {
    long s = 0;
    for (int d : data) s += d;
    rt.write(*out, static_cast<long>(label.size()) + s + v);
    // A nested read created (and later undone) on every re-execution, with its own copies.
    rt.read(*inner, body([label2 = label + "/inner", data2 = data, o = out, lc2 = lc](Engine& rt2, int w) {
      (void)lc2;
      if (label2.compare(0, 5, "body-") != 0 || data2.size() != 40) throw std::logic_error("corrupt");
      if (w < 0) rt2.write(*o, -1L);
    }));
  }
};

TEST(EngineClosures, CapturedStringsAndVectorsSurviveManyReexecutions) {
  const int reps = 2000 / kScale;
  const int k = 8;
  LiveCount::live = 0;
  {
    Engine rt;
    std::vector<Mod<int>> ins(k);
    Mod<int> inner;
    std::vector<Mod<long>> outs(k);
    std::vector<Mod<std::string>> souts(k);
    rt.set(inner, 0);
    for (int i = 0; i < k; ++i) rt.set(ins[static_cast<std::size_t>(i)], 0);
    rt.run([&](Engine& rt2) {
      for (int i = 0; i < k; ++i) {
        std::string label = "body-" + std::string(40, static_cast<char>('a' + i));
        std::vector<int> data(40, i);
        rt2.read(ins[static_cast<std::size_t>(i)],
                body(CapturingBody{label, data, LiveCount{}, &outs[static_cast<std::size_t>(i)], &inner}));
        // A lambda capturing a string and a vector by value (moved-from locals afterwards).
        rt2.read(ins[static_cast<std::size_t>(i)],
                body([s = std::move(label), d = std::move(data), po = &souts[static_cast<std::size_t>(i)]](
                    Engine& rt3, const int& v) {
                  rt3.write(*po, s + ":" + std::to_string(d.size() + static_cast<std::size_t>(v)));
                }));
      }
    });
    expect_healthy(rt);
    const long live_after_run = LiveCount::live;
    EXPECT_EQ(live_after_run, 2 * k) << "one closure per outer read and one per inner read";
    std::mt19937_64 rng(9);
    for (int r = 0; r < reps; ++r) {
      const int i = static_cast<int>(rng() % k);
      const int v = static_cast<int>(rng() % 1000);
      rt.set(ins[static_cast<std::size_t>(i)], v);
      if (r % 7 == 0) rt.set(inner, static_cast<int>(rng() % 3));
      rt.propagate();
      const long expect_out = 45 + 40L * i + v;
      EXPECT_EQ(outs[static_cast<std::size_t>(i)].get(), expect_out);
      EXPECT_EQ(souts[static_cast<std::size_t>(i)].get(),
                "body-" + std::string(40, static_cast<char>('a' + i)) + ":" + std::to_string(40 + v));
      EXPECT_EQ(LiveCount::live, live_after_run) << "closures leaked or destroyed twice";
      if (r % 100 == 0) expect_healthy(rt);
    }
    expect_healthy(rt);
  }
  EXPECT_EQ(LiveCount::live, 0) << "the engine destroys every stored closure";
}

// ================================================================ debugging aids

TEST(EngineDebug, DumpDotOfASmallTrace) {
  Engine rt;
  Mod<int> in, out;
  int calls = 0;
  rt.set(in, 1);
  rt.run([&](Engine& rt2) {
    rt2.read(in, body([po = &out, pc = &calls](Engine& rt3, int v) {
      rt3.write(*po, v);
      rt3.memo(sac::fn<bump>(pc, 1));
      rt3.alloc<int>(5, 5);
    }));
  });
  std::ostringstream os;
  rt.dump_dot(os);
  const std::string dot = os.str();
  EXPECT_EQ(dot.rfind("digraph", 0), 0u) << dot;
  EXPECT_NE(dot.find("read"), std::string::npos) << dot;
  EXPECT_NE(dot.find("write"), std::string::npos) << dot;
  EXPECT_NE(dot.find('}'), std::string::npos);
  rt.set(in, 2);
  rt.propagate();
  std::ostringstream os2;
  rt.dump_dot(os2);
  // An alloc issued after the memo call lands outside the memo entry, so an update does not
  // duplicate it.
  EXPECT_EQ(os2.str(), dot) << "same trace shape after an update";
  expect_healthy(rt);
}

TEST(EngineDebug, CheckInvariantsAfterMultipleRuns) {
  // Several run() calls append their traces; propagation works across them.
  Engine rt;
  Mod<int> a, b, x, y;
  rt.set(a, 1);
  rt.set(b, 2);
  rt.run([&](Engine& rt2) { rt2.read(a, body([px = &x](Engine& rt3, int v) { rt3.write(*px, v + 1); })); });
  expect_healthy(rt);
  rt.run([&](Engine& rt2) {
    rt2.read(x, body([py = &y, pb = &b](Engine& rt3, int v) {
      rt3.read(*pb, body([py, v](Engine& rt4, int w) { rt4.write(*py, v * w); }));
    }));
  });
  expect_healthy(rt);
  EXPECT_EQ(y.get(), 4);
  rt.set(a, 4);
  rt.propagate();
  expect_healthy(rt);
  EXPECT_EQ(y.get(), 10);
  rt.set(b, 3);
  rt.propagate();
  EXPECT_EQ(y.get(), 15);
  expect_healthy(rt);
}

// ================================================================ the checker sees corruption
//
// Each test builds a small trace with every kind of record, sees check_invariants() pass,
// breaks exactly one rule through EngineTestAccess, expects InvariantError naming that rule,
// and repairs the trace before the engine is destroyed.

using sac::EngineTestAccess;
using sac::detail::Stamp;
using sac::detail::StampKind;
using sac::detail::AllocNode;
using sac::detail::MemoNode;
using sac::detail::ReadNode;
using sac::detail::VersionBase;

/// A trace of one read of `in` whose body writes `acc` three times, makes a keyed allocation,
/// calls a memoized function and reads `acc` (nested) to write `out`.
struct SmallTrace {
  Mod<int> in, acc, out;
  int calls = 0;
  Engine rt;  // declared last, destroyed first: its records refer to the modifiables above

  SmallTrace() {
    rt.set(in, 1);
    rt.run([this](Engine& rt2) {
      rt2.read(in, [this](Engine& rt3, int v) {
        rt3.write(acc, v);
        rt3.write(acc, v + 1);
        rt3.write(acc, v + 2);
        rt3.alloc<int>(7, v);
        rt3.memo(sac::fn<bump>(&calls, 1));
        rt3.read(acc, [this](Engine& rt4, int w) { rt4.write(out, w); });
      });
    });
  }

  /// The stamps of kind k, in trace order.
  std::vector<Stamp*> stamps(StampKind k) {
    std::vector<Stamp*> out_stamps;
    for (Stamp* s = EngineTestAccess::order(rt).base()->next(); s; s = s->next())
      if (s->kind() == k) out_stamps.push_back(s);
    return out_stamps;
  }
  /// The stamp right before s.
  Stamp* before(const Stamp* s) {
    Stamp* p = EngineTestAccess::order(rt).base();
    while (p->next() != s) p = p->next();
    return p;
  }
  /// The three versions of acc, oldest first.
  std::vector<VersionBase*> acc_versions() {
    std::vector<VersionBase*> v;
    for (Stamp* s : stamps(StampKind::Write))
      if (sac::detail::version_of(s)->mod() == &acc) v.push_back(sac::detail::version_of(s));
    return v;
  }
  /// The nested read (of acc).
  ReadNode* inner_read() { return sac::detail::read_of_start(stamps(StampKind::ReadStart).at(1)); }
  /// Moves s (linked) to right after pos.
  void move_stamp(Stamp* s, Stamp* pos) {
    const StampKind k = s->kind();
    EngineTestAccess::order(rt).erase(s);
    EngineTestAccess::order(rt).insert_after(pos, s, k);
  }
};

/// The message of the sac::InvariantError that e.check_invariants() throws, or "" if none.
std::string invariant_message(const Engine& rt) {
  try {
    rt.check_invariants();
  } catch (const sac::InvariantError& err) {
    return err.what();
  }
  return {};
}

using testing::HasSubstr;

TEST(EngineChecker, ReadDetachedFromItsVersion) {
  SmallTrace t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  ReadNode* r = t.inner_read();
  VersionBase* v = t.acc_versions().at(2);
  ASSERT_EQ(v->readers, &r->link);
  EngineTestAccess::detach(r);
  EXPECT_THROW(t.rt.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("not attached"));
  EngineTestAccess::attach(r, v);
  EXPECT_NO_THROW(t.rt.check_invariants());
}

TEST(EngineChecker, ReaderListWithABrokenBackLink) {
  SmallTrace t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  ReadNode* r = t.inner_read();
  sac::detail::ReaderLink** saved = r->link.rpprev();
  r->link.set_rpprev(&r->link.rnext);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("broken back link"));
  r->link.set_rpprev(saved);
  EXPECT_NO_THROW(t.rt.check_invariants());
}

/// Two reads of a default that has no version: they hang on the modifiable.
struct DefaultReads {
  Mod<int> d, out1, out2;
  Engine rt;
  DefaultReads() {
    rt.init_default(d);
    rt.run([this](Engine& rt2) {
      rt2.read(d, [this](Engine& rt3, int v) { rt3.write(out1, v); });
      rt2.read(d, [this](Engine& rt3, int v) { rt3.write(out2, v); });
    });
  }
  ReadNode* read(int i) {
    int k = 0;
    for (Stamp* s = EngineTestAccess::order(rt).base()->next(); s; s = s->next())
      if (s->kind() == StampKind::ReadStart && k++ == i) return sac::detail::read_of_start(s);
    return nullptr;
  }
};

TEST(EngineChecker, DefaultReaderDetachedOrWithABrokenBackLink) {
  DefaultReads t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  ReadNode* first = t.read(1);  // the later read was attached last: it heads the list
  ReadNode* second = t.read(0);
  ASSERT_EQ(first->link.rnext, &second->link);
  sac::detail::ReaderLink** saved = second->link.rpprev();
  second->link.set_rpprev(&second->link.rnext);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("default reader list has a broken back link"));
  second->link.set_rpprev(saved);
  ASSERT_NO_THROW(t.rt.check_invariants());
  EngineTestAccess::detach(second);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("not attached"));
  EngineTestAccess::attach_default(second, t.d);
  EXPECT_NO_THROW(t.rt.check_invariants());
}

TEST(EngineChecker, ReadAttachedToAnOlderVersion) {
  SmallTrace t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  ReadNode* r = t.inner_read();
  const std::vector<VersionBase*> v = t.acc_versions();
  EngineTestAccess::detach(r);
  EngineTestAccess::attach(r, v.at(1));  // the read comes after v[2], so it must see v[2]
  EXPECT_THROW(t.rt.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("reader after the next version"));
  EngineTestAccess::detach(r);
  EngineTestAccess::attach(r, v.at(2));
  EXPECT_NO_THROW(t.rt.check_invariants());
}

TEST(EngineChecker, ReadersOutOfOrderOrOnTheWrongList) {
  // Two reads of one input: its ordered readers are the second, then the first.
  Mod<int> in, out1, out2;
  Engine rt;
  rt.set(in, 1);
  rt.run([&](Engine& rt2) {
    rt2.read(in, [&out1](Engine& rt3, int v) { rt3.write(out1, v); });
    rt2.read(in, [&out2](Engine& rt3, int v) { rt3.write(out2, v); });
  });
  ASSERT_NO_THROW(rt.check_invariants());
  ReadNode* first = nullptr;
  for (Stamp* s = EngineTestAccess::order(rt).base()->next(); s && !first; s = s->next())
    if (s->kind() == StampKind::ReadStart) first = sac::detail::read_of_start(s);
  ASSERT_NE(first, nullptr);
  // The list is the second read, then the first: the first's back link is the second's
  // rnext (a ReaderLink's first field), and the second's is the version's head.
  ReadNode* second = sac::detail::owner_of(reinterpret_cast<sac::detail::ReaderLink*>(first->link.rpprev()));
  ASSERT_NE(second, first);
  auto* v = reinterpret_cast<VersionBase*>(reinterpret_cast<char*>(second->link.rpprev()) - offsetof(VersionBase, readers));
  EngineTestAccess::detach(first);
  EngineTestAccess::attach(first, v);  // ahead of the newer read
  EXPECT_THAT(invariant_message(rt), HasSubstr("ordered readers are not newest first"));
  EngineTestAccess::detach(first);
  EngineTestAccess::detach(second);
  EngineTestAccess::attach(first, v);
  EngineTestAccess::attach(second, v);
  EXPECT_NO_THROW(rt.check_invariants());
  second->link.set_unordered(true);
  EXPECT_THAT(invariant_message(rt), HasSubstr("on the other list than its flag says"));
  second->link.set_unordered(false);
  EXPECT_NO_THROW(rt.check_invariants());
}

TEST(EngineChecker, VersionsOutOfOrder) {
  SmallTrace t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  const std::vector<VersionBase*> v = t.acc_versions();
  ASSERT_EQ(v.size(), 3u);
  ASSERT_EQ(v[2]->older(), v[1]);
  const std::uintptr_t end = v[0]->link;  // the oldest's link: the modifiable, marked
  // newest v2 -> v1 -> v0 becomes v2 -> v0 -> v1: every version is still in the list.
  v[2]->set_older(v[0]);
  v[0]->set_older(v[1]);
  v[1]->link = end;
  EXPECT_THROW(t.rt.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("versions out of order"));
  v[2]->set_older(v[1]);
  v[1]->set_older(v[0]);
  v[0]->link = end;
  EXPECT_NO_THROW(t.rt.check_invariants());
}

TEST(EngineChecker, ReadIntervalsNotWellNested) {
  SmallTrace t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  // The nested read's end moves after its parent's end.
  const std::vector<Stamp*> ends = t.stamps(StampKind::ReadEnd);
  ASSERT_EQ(ends.size(), 2u);
  Stamp* inner_end = &t.inner_read()->end;
  ASSERT_EQ(ends[0], inner_end);
  Stamp* pred = t.before(inner_end);
  t.move_stamp(inner_end, ends[1]);
  EXPECT_THROW(t.rt.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("not well nested"));
  t.move_stamp(inner_end, pred);
  EXPECT_NO_THROW(t.rt.check_invariants());
}

TEST(EngineChecker, LiveEventCountMismatch) {
  SmallTrace t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  ++EngineTestAccess::stats(t.rt).live_events;
  EXPECT_THROW(t.rt.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("live event count mismatch"));
  --EngineTestAccess::stats(t.rt).live_events;
  EXPECT_NO_THROW(t.rt.check_invariants());
}

TEST(EngineChecker, AllocationMissingFromItsTable) {
  SmallTrace t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  AllocNode* n = sac::detail::alloc_of(t.stamps(StampKind::Alloc).at(0));
  const std::size_t h = n->ops()->hash(n);
  EngineTestAccess::allocs(t.rt).erase(n, h);
  EXPECT_THROW(t.rt.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("allocation table size mismatch"));
  EngineTestAccess::allocs(t.rt).insert(n, h, [](const AllocNode* x) { return x->ops()->hash(x); });
  EXPECT_NO_THROW(t.rt.check_invariants());
}

TEST(EngineChecker, MemoEntryMissingFromItsTable) {
  SmallTrace t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  MemoNode* n = sac::detail::memo_of_start(t.stamps(StampKind::MemoStart).at(0));
  const std::size_t h = n->ops()->hash(n);
  EngineTestAccess::memos(t.rt).erase(n, h);
  EXPECT_THROW(t.rt.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("memo table size mismatch"));
  EngineTestAccess::memos(t.rt).insert(n, h, [](const MemoNode* x) { return x->ops()->hash(x); });
  EXPECT_NO_THROW(t.rt.check_invariants());
}

TEST(EngineChecker, UndoneAllocationLeftInItsTable) {
  SmallTrace t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  // An undo that forgot the table: the record leaves the trace (and the live count) but
  // stays in the allocation table.
  Stamp* s = t.stamps(StampKind::Alloc).at(0);
  Stamp* pred = t.before(s);
  EngineTestAccess::order(t.rt).erase(s);
  --EngineTestAccess::stats(t.rt).live_events;
  EXPECT_THROW(t.rt.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("allocation table"));
  EngineTestAccess::order(t.rt).insert_after(pred, s, StampKind::Alloc);
  ++EngineTestAccess::stats(t.rt).live_events;
  EXPECT_NO_THROW(t.rt.check_invariants());
}

TEST(EngineChecker, ReadLeftInTheQueue) {
  SmallTrace t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  ReadNode* r = t.inner_read();
  EngineTestAccess::queue(t.rt).push(r);
  EXPECT_THROW(t.rt.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(t.rt), HasSubstr("queue not empty"));
  EngineTestAccess::queue(t.rt).remove(r);
  EXPECT_NO_THROW(t.rt.check_invariants());
}

TEST(EngineChecker, PropagateRunsTheCheckerUnderSacDebugChecks) {
  SmallTrace t;
  ASSERT_NO_THROW(t.rt.check_invariants());
  ++EngineTestAccess::stats(t.rt).live_events;  // survives the update: propagate adjusts it
  t.rt.set(t.in, 2);
  if (test_support::kDebugChecks) {
    EXPECT_THROW(t.rt.propagate(), sac::InvariantError);
  } else {
    EXPECT_NO_THROW(t.rt.propagate());
  }
  EXPECT_FALSE(t.rt.poisoned()) << "a failed check reports, it does not poison";
  EXPECT_EQ(t.out.get(), 4);
  --EngineTestAccess::stats(t.rt).live_events;
  EXPECT_NO_THROW(t.rt.check_invariants());
}

// ================================================================ random differential

template <class Program>
void differential(std::uint64_t seed, int n, int steps) {
  SCOPED_TRACE("seed " + std::to_string(seed) + " n " + std::to_string(n));
  std::mt19937_64 rng(seed);
  std::vector<long> values = random_values(rng, n);
  std::vector<bool> present(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < present.size(); ++i) present[i] = rng() % 5 != 0;
  Engine rt;
  Input in(rt, values, present);
  Program p;
  p.start(rt, in);
  expect_healthy(rt);
  std::vector<long> first;
  ASSERT_NO_THROW(first = p.result());
  ASSERT_EQ(first, Program::expected(in.sequence()));
  ASSERT_EQ(figures(rt), fresh_figures<Program>(values, in.presence()));
  for (int step = 0; step < steps; ++step) {
    SCOPED_TRACE("step " + std::to_string(step));
    const int r = static_cast<int>(rng() % 10);
    const int k = r < 6 ? 1 : r < 9 ? 2 + static_cast<int>(rng() % 4) : 0;  // 0: empty batch
    for (int j = 0; j < k; ++j) in.toggle(rng() % static_cast<std::size_t>(n));
    rt.propagate();
    ASSERT_NO_THROW(rt.check_invariants()) << rt.stats();
    ASSERT_FALSE(rt.poisoned());
    const Stats& s = rt.stats();
    ASSERT_EQ(s.live_events, s.events_created - s.events_undone);
    if (k == 0) {
      ASSERT_EQ(s.last_reexecuted, 0u);
    }
    std::vector<long> scratch_result;
    const Figures scratch = fresh_figures<Program>(values, in.presence(), &scratch_result);
    std::vector<long> got;
    ASSERT_NO_THROW(got = p.result()) << "an output modifiable lost its value";
    ASSERT_EQ(got, Program::expected(in.sequence()));
    ASSERT_EQ(got, scratch_result);
    ASSERT_EQ(figures(rt), scratch) << "live trace differs from a from-scratch run";
  }
}

TEST(EngineReaderOrder, AReexecutedWriteTestsTheReadersAfterItNotAllOfThem) {
  // m is read 2,000 times, then a read of sel writes m when sel is odd, then m is read 5
  // more times. A write of m that re-execution adds must find the 5 later readers of m's
  // base version among its 2,005: the version's ordered readers are newest first, so it
  // tests those 5 and one more, not all. Changes of m re-run every reader, which keep their
  // places; the outputs and the checker are tested after every change (seed printed).
  constexpr int kBefore = 2000, kAfter = 5;
  Mod<int> sel, m;
  auto outs = std::make_unique<Mod<int>[]>(kBefore + kAfter);
  Engine rt;
  int vsel = 0, vm = 1;
  rt.set(sel, vsel);
  rt.set(m, vm);
  rt.run([&](Engine& rt2) {
    for (int i = 0; i < kBefore; ++i) rt2.read(m, [o = &outs[i]](Engine& rt3, int v) { rt3.write(*o, v); });
    rt2.read(sel, [&m](Engine& rt3, int s) {
      if (s % 2 == 1) rt3.write(m, 100 + s);
    });
    for (int i = kBefore; i < kBefore + kAfter; ++i) rt2.read(m, [o = &outs[i]](Engine& rt3, int v) { rt3.write(*o, v); });
  });
  std::mt19937 rng(20261129);
  std::printf("seed 20261129\n");
  int writes_added = 0;
  for (int t = 0; t < 60; ++t) {
    const std::uint64_t tested0 = rt.stats().readers_tested;
    const bool was_odd = vsel % 2 == 1;
    if (rng() % 3 == 0) {
      rt.set(m, vm = static_cast<int>(rng() % 50));
    } else {
      rt.set(sel, vsel = static_cast<int>(rng() % 9));
    }
    rt.propagate();
    const bool adds_write = !was_odd && vsel % 2 == 1;
    if (adds_write) {
      ++writes_added;
      EXPECT_LE(rt.stats().readers_tested - tested0, std::uint64_t{kAfter + 1}) << "change " << t;
    }
    for (int i = 0; i < kBefore; ++i) ASSERT_EQ(outs[i].get(), vm) << "change " << t;
    for (int i = kBefore; i < kBefore + kAfter; ++i)
      ASSERT_EQ(outs[i].get(), vsel % 2 == 1 ? 100 + vsel : vm) << "change " << t;
    rt.check_invariants();
  }
  EXPECT_GT(writes_added, 5);
}

TEST(EngineReaderOrder, AnUndoneVersionsReadersMoveOntoTheWriteThatReplacesIt) {
  // A read of sel writes m, and 50 reads of m follow. A change of sel re-executes the write:
  // the new version lands before the old one, which is then undone, and its readers move
  // onto the new version whole. They re-run only when m's value changed. Outputs, re-runs
  // and the checker are tested after every change (seed printed).
  constexpr int kAfter = 50;
  Mod<int> sel, m, tag;
  auto outs = std::make_unique<Mod<int>[]>(kAfter);
  Engine rt;
  int vsel = 0, reruns = 0;
  rt.set(sel, vsel);
  rt.set(m, -1);
  rt.run([&](Engine& rt2) {
    rt2.read(m, [&tag](Engine& rt3, int v) { rt3.write(tag, v); });  // a reader of the older version
    rt2.read(sel, [&m](Engine& rt3, int s) { rt3.write(m, s / 3); });
    for (int i = 0; i < kAfter; ++i)
      rt2.read(m, [o = &outs[i], &reruns](Engine& rt3, int v) {
        ++reruns;
        rt3.write(*o, v + 1);
      });
  });
  std::mt19937 rng(20261130);
  std::printf("seed 20261130\n");
  int same_value = 0, new_value = 0;
  for (int t = 0; t < 80; ++t) {
    const int before = vsel / 3;
    rt.set(sel, vsel = static_cast<int>(rng() % 12));
    reruns = 0;
    rt.propagate();
    if (vsel / 3 == before) {
      ++same_value;
      EXPECT_EQ(reruns, 0) << "change " << t;
    } else {
      ++new_value;
      EXPECT_EQ(reruns, kAfter) << "change " << t;
    }
    for (int i = 0; i < kAfter; ++i) ASSERT_EQ(outs[i].get(), vsel / 3 + 1) << "change " << t;
    ASSERT_EQ(tag.get(), -1) << "change " << t;
    rt.check_invariants();
  }
  EXPECT_GT(same_value, 5);
  EXPECT_GT(new_value, 5);
}

TEST(EngineReaderOrder, AnUndoneVersionsUnorderedReadersMoveWithoutARelinkOfTheOthers) {
  // A read of sel writes m, and 2,000 reads follow, each of pick[i] around a read of m. A
  // change of pick[i] re-executes that inner read of m, which hangs on m's version among
  // its unordered readers. A change of sel then re-executes the write: the old version is
  // undone onto the new one, which has no readers yet, and both of its lists move over
  // whole, rather than being merged into order, which would relink all 2,000 (a cell read by
  // the steps of every class: docs/DESIGN.md, "Change propagation"). Outputs, re-runs and
  // the checker are tested after every change (seed printed).
  constexpr int kReaders = 2000;
  Mod<int> sel, m;
  auto pick = std::make_unique<Mod<int>[]>(kReaders);
  auto outs = std::make_unique<Mod<int>[]>(kReaders);
  std::vector<int> vpick(kReaders, 0);
  Engine rt;
  int vsel = 0, reruns = 0;
  rt.set(sel, vsel);
  for (int i = 0; i < kReaders; ++i) rt.set(pick[i], 0);
  rt.run([&](Engine& rt2) {
    rt2.read(sel, [&m](Engine& rt3, int s) { rt3.write(m, s / 3); });
    for (int i = 0; i < kReaders; ++i)
      rt2.read(pick[i], [&m, &reruns, o = &outs[i]](Engine& rt3, int p) {
        rt3.read(m, [&reruns, o, p](Engine& rt4, int v) {
          ++reruns;
          rt4.write(*o, 10 * v + p);
        });
      });
  });
  std::mt19937 rng(20261201);
  std::printf("seed 20261201\n");
  int whole_moves = 0;
  for (int t = 0; t < 40; ++t) {
    // Re-execute a few of the inner reads: they hang on m's version unordered.
    for (int k = 0; k < 5; ++k) {
      const int i = static_cast<int>(rng() % kReaders);
      rt.set(pick[i], ++vpick[i] % 7);
    }
    rt.propagate();
    rt.check_invariants();
    const int before = vsel;
    rt.set(sel, vsel = static_cast<int>(rng() % 12));
    const std::uint64_t relinked0 = rt.stats().readers_relinked;
    reruns = 0;
    rt.propagate();
    const bool rewritten = vsel != before;  // the read of sel re-ran and wrote m again
    if (vsel / 3 == before / 3) {
      EXPECT_EQ(reruns, 0) << "change " << t;
    } else {
      EXPECT_EQ(reruns, kReaders) << "change " << t;
    }
    if (rewritten) {
      ++whole_moves;
      EXPECT_LE(rt.stats().readers_relinked - relinked0, std::uint64_t{5}) << "change " << t;
    }
    for (int i = 0; i < kReaders; ++i) ASSERT_EQ(outs[i].get(), 10 * (vsel / 3) + vpick[i] % 7) << "change " << t;
    rt.check_invariants();
  }
  EXPECT_GT(whole_moves, 10);
}

TEST(EngineDifferential, MapWithMemoReadAndKeyedCells) {
  for (std::uint64_t seed : {1u, 2u, 3u}) differential<MapProgram>(seed, 120 / kScale, 200 / kScale);
}

TEST(EngineDifferential, PrefixSumsWithMemoRead) {
  for (std::uint64_t seed : {11u, 12u, 13u, 14u})
    differential<PsumProgram>(seed, 100 / kScale, 200 / kScale);
}

// Writes after reads in the same body (the close chaining of WriteAfterANestedReadStaysOutsideIt).
TEST(EngineDifferential, PrefixSumsWithWritesAfterReads) {
  for (std::uint64_t seed : {15u, 16u, 17u})
    differential<PsumLateProgram>(seed, 100 / kScale, 200 / kScale);
}

TEST(EngineDifferential, AccumulatorWrittenManyTimes) {
  for (std::uint64_t seed : {21u, 22u, 23u, 24u})
    differential<AccProgram>(seed, 100 / kScale, 200 / kScale);
}

TEST(EngineDifferential, TinyListsIncludingEmpty) {
  for (std::uint64_t seed : {31u, 32u, 33u}) {
    differential<PsumProgram>(seed, 3, 60);
    differential<AccProgram>(seed, 2, 60);
    differential<MapProgram>(seed, 1, 30);
  }
}

}  // namespace

namespace {

TEST(EngineChecker, MultiReadSlotDetachedOrOnAnotherModifiable) {
  Mod<int> a, b, out;
  Engine rt;
  rt.set(a, 1);
  rt.set(b, 2);
  rt.run([&](Engine& rt2) {
    rt2.read_many({&a, &b}, [&out](Engine& rt3, std::span<const int* const> v) { rt3.write(out, *v[0] + *v[1]); });
  });
  ASSERT_NO_THROW(rt.check_invariants());
  Stamp* s = EngineTestAccess::order(rt).base()->next();
  ASSERT_EQ(s->kind(), StampKind::ReadStart);
  sac::detail::ReadManyHeader* h = sac::detail::many_of(sac::detail::read_of_start(s));
  ASSERT_EQ(h->k(), 2u);
  // Each slot is the only reader of its modifiable's base version: rpprev is &v->readers.
  auto version_of_slot = [](sac::detail::ReaderLink* l) {
    return reinterpret_cast<VersionBase*>(reinterpret_cast<char*>(l->rpprev()) - offsetof(VersionBase, readers));
  };
  sac::detail::ReaderLink* slot = &h->slots()[1].link;
  VersionBase* va = version_of_slot(&h->slots()[0].link);
  VersionBase* vbv = version_of_slot(slot);
  ASSERT_EQ(va->readers, &h->slots()[0].link);
  ASSERT_EQ(vbv->readers, slot);
  EngineTestAccess::detach(slot);
  EXPECT_THAT(invariant_message(rt), HasSubstr("not attached"));
  EngineTestAccess::attach(slot, va);
  EXPECT_THAT(invariant_message(rt), HasSubstr("another modifiable"));
  EngineTestAccess::detach(slot);
  EngineTestAccess::attach(slot, vbv);
  EXPECT_NO_THROW(rt.check_invariants());
  h->read.set_qpos(0);
  EXPECT_THAT(invariant_message(rt), HasSubstr("still queued"));
  h->read.set_qpos(sac::detail::kNotQueued);
  EXPECT_NO_THROW(rt.check_invariants());
  // The numbers kept in the links' spare bits: an ops number of no table, a slot mark on
  // the read's own link.
  const std::uint16_t ops = h->read.ops_id();
  h->read.set_ops_id(0);
  EXPECT_THAT(invariant_message(rt), HasSubstr("a read with no ops table"));
  h->read.set_ops_id(ops);
  h->read.link.back |= sac::detail::ReaderLink::kSlotBit;
  EXPECT_THAT(invariant_message(rt), HasSubstr("marked as a slot"));
  h->read.link.back &= ~sac::detail::ReaderLink::kSlotBit;
  EXPECT_NO_THROW(rt.check_invariants());
}

}  // namespace
