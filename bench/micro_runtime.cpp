// Micro-benchmarks of the runtime's hot primitives (Google Benchmark; linked into sac_micro
// with benchmark_main).
//
//   OrderList:  append insert, insert after a random existing stamp, less() on random pairs.
//   StampQueue: push n elements in random order, then pop them all.
//   Engine:     from-scratch run of n reads that each write (per element), a run of n writes,
//               and change propagation of a memoized map over a list (one remove or reinsert
//               per propagate; memo_read hits reuse the rest of the list); k = 4
//               modifiables per step read by one read_many vs 4 nested reads, from scratch
//               and propagating one changed input (4 steps affected), with trace bytes and
//               events per step; the same steps as reads of a projection (affected()), when
//               a change leaves the projection as it was and when it does not.
// Items processed = primitive operations, so the reported items/s invert to ns per operation.
// Setup (building lists, engines, inputs) is excluded from timing; fixed seeds.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <deque>
#include <memory>
#include <span>
#include <random>
#include <vector>

#include "sac/sac.hpp"
#include "sac/detail/order_list.hpp"
#include "sac/detail/stamp_queue.hpp"

namespace {

using sac::Engine;
using sac::Mod;
using sac::detail::OrderList;
using sac::detail::Stamp;
using sac::detail::StampKind;

// ------------------------------------------------------------------------- OrderList

void BM_OrderListAppend(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<Stamp> stamps(n);
  for (auto _ : state) {
    state.PauseTiming();
    auto ol = std::make_unique<OrderList>();
    for (Stamp& s : stamps) s = Stamp{};
    state.ResumeTiming();
    Stamp* pos = ol->base();
    for (Stamp& s : stamps) {
      ol->insert_after(pos, &s, StampKind::User);
      pos = &s;
    }
    benchmark::DoNotOptimize(ol->size());
    state.PauseTiming();
    ol.reset();
    state.ResumeTiming();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_OrderListAppend)->Arg(1 << 12)->Arg(1 << 20);

/// Builds n stamps, each inserted right after a uniformly random earlier stamp (or the base).
void build_random(OrderList& ol, std::vector<Stamp>& stamps, const std::vector<std::uint32_t>& where) {
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    Stamp* pos = where[i] == 0 ? ol.base() : &stamps[where[i] - 1];
    ol.insert_after(pos, &stamps[i], StampKind::User);
  }
}

std::vector<std::uint32_t> random_positions(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::uint32_t> where(n);
  for (std::size_t i = 0; i < n; ++i) where[i] = static_cast<std::uint32_t>(rng() % (i + 1));
  return where;
}

void BM_OrderListInsertRandom(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<Stamp> stamps(n);
  const std::vector<std::uint32_t> where = random_positions(n, 1);
  for (auto _ : state) {
    state.PauseTiming();
    auto ol = std::make_unique<OrderList>();
    for (Stamp& s : stamps) s = Stamp{};
    state.ResumeTiming();
    build_random(*ol, stamps, where);
    benchmark::DoNotOptimize(ol->size());
    state.PauseTiming();
    ol.reset();
    state.ResumeTiming();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_OrderListInsertRandom)->Arg(1 << 12)->Arg(1 << 20);

void BM_OrderListLess(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<Stamp> stamps(n);
  OrderList ol;
  build_random(ol, stamps, random_positions(n, 2));
  constexpr std::size_t kPairs = 4096;
  std::mt19937_64 rng(3);
  std::vector<std::pair<const Stamp*, const Stamp*>> pairs(kPairs);
  for (auto& p : pairs) p = {&stamps[rng() % n], &stamps[rng() % n]};
  for (auto _ : state) {
    std::size_t count = 0;
    for (const auto& p : pairs) count += ol.less(p.first, p.second) ? 1 : 0;
    benchmark::DoNotOptimize(count);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(kPairs));
}
BENCHMARK(BM_OrderListLess)->Arg(1 << 12)->Arg(1 << 20);

// ------------------------------------------------------------------------- StampQueue

struct QElem {
  Stamp stamp;
  std::uint32_t qpos = sac::detail::kNotQueued;
};
struct QTraits {
  static const Stamp* stamp(const QElem* e) { return &e->stamp; }
  static std::uint32_t pos(const QElem* e) { return e->qpos; }
  static void set_pos(QElem* e, std::uint32_t p) { e->qpos = p; }
};

void BM_StampQueuePushPop(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::deque<QElem> elems(n);
  OrderList ol;
  Stamp* pos = ol.base();
  for (QElem& e : elems) {
    ol.insert_after(pos, &e.stamp, StampKind::User);
    pos = &e.stamp;
  }
  std::vector<QElem*> order;
  for (QElem& e : elems) order.push_back(&e);
  std::shuffle(order.begin(), order.end(), std::mt19937_64(4));
  sac::detail::StampQueue<QElem, QTraits> q(ol);
  for (auto _ : state) {
    for (QElem* e : order) q.push(e);
    while (!q.empty()) benchmark::DoNotOptimize(q.pop());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * 2 * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_StampQueuePushPop)->Arg(1 << 10)->Arg(1 << 16);

// ------------------------------------------------------------------------- Engine

// Read bodies are comparable structs rather than lambdas (read() currently needs an
// operator== on the closure; see tests/sac/engine_test.cpp, PlainLambdaReadBodies_Bug).
struct AddOne {
  Mod<int>* out;
  void operator()(Engine& rt, int v) const { rt.write(*out, v + 1); }
  bool operator==(const AddOne&) const = default;
};

/// Inputs and outputs of the flat benchmarks; fresh per engine (a Mod belongs to one engine).
struct Flat {
  std::vector<Mod<int>> in, out;
  explicit Flat(std::size_t n) : in(n), out(n) {}
};

void BM_EngineReadWriteFromScratch(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  for (auto _ : state) {
    state.PauseTiming();
    auto rt = std::make_unique<Engine>();
    auto f = std::make_unique<Flat>(n);
    for (std::size_t i = 0; i < n; ++i) rt->set(f->in[i], static_cast<int>(i));
    state.ResumeTiming();
    rt->run([&](Engine& rt2) {
      for (std::size_t i = 0; i < n; ++i) rt2.read(f->in[i], AddOne{&f->out[i]});
    });
    benchmark::DoNotOptimize(f->out[n - 1].get());
    state.PauseTiming();
    rt.reset();
    f.reset();
    state.ResumeTiming();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_EngineReadWriteFromScratch)->Arg(1 << 10)->Arg(1 << 18);

void BM_EngineWrite(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  for (auto _ : state) {
    state.PauseTiming();
    auto rt = std::make_unique<Engine>();
    auto f = std::make_unique<Flat>(n);
    state.ResumeTiming();
    rt->run([&](Engine& rt2) {
      for (std::size_t i = 0; i < n; ++i) rt2.write(f->out[i], static_cast<int>(i));
    });
    benchmark::DoNotOptimize(f->out[n - 1].get());
    state.PauseTiming();
    rt.reset();
    f.reset();
    state.ResumeTiming();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_EngineWrite)->Arg(1 << 10)->Arg(1 << 18);

// Map over a modifiable list: output cells keyed by the input cell's id; the recursion is
// memoized with memo_read, so one remove/reinsert re-runs one read and reuses the rest of the
// list through a memo hit.
struct Cell {
  int value;
  std::uint64_t id;
  Mod<Cell*> next;
  Cell(int v, std::uint64_t i) : value(v), id(i) {}
};
struct OutCell {
  int value;
  Mod<OutCell*> next;
  explicit OutCell(int v) : value(v) {}
};

void map_step(Engine& rt, Cell* c, Mod<OutCell*>* dst) {
  if (!c) {
    rt.write(*dst, static_cast<OutCell*>(nullptr));
    return;
  }
  OutCell* o = rt.alloc<OutCell>(c->id, 2 * c->value);
  rt.write(*dst, o);
  rt.memo_read(c->next, sac::fn<map_step>(&o->next));
}

void BM_EngineMemoMapPropagate(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Engine rt;
  Mod<Cell*> head;
  Mod<OutCell*> out;
  std::vector<std::unique_ptr<Cell>> cells;
  for (std::size_t i = 0; i < n; ++i) cells.push_back(std::make_unique<Cell>(static_cast<int>(i), i));
  for (std::size_t i = 0; i < n; ++i) rt.set(cells[i]->next, i + 1 < n ? cells[i + 1].get() : nullptr);
  rt.set(head, cells[0].get());
  rt.run([&](Engine& rt2) { rt2.memo_read(head, sac::fn<map_step>(&out)); });
  std::mt19937_64 rng(5);
  const std::uint64_t hits0 = rt.stats().memo_hits;
  std::uint64_t propagations = 0;
  for (auto _ : state) {
    // Remove element i (1 <= i < n-1) and put it back: two propagations.
    const std::size_t i = 1 + static_cast<std::size_t>(rng() % (n - 2));
    Cell* c = cells[i].get();
    rt.set(cells[i - 1]->next, c->next.get());
    rt.propagate();
    rt.set(cells[i - 1]->next, c);
    rt.propagate();
    propagations += 2;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(propagations));
  state.counters["memo_hits_per_propagate"] =
      propagations ? static_cast<double>(rt.stats().memo_hits - hits0) / static_cast<double>(propagations) : 0.0;
  state.counters["live_events"] = static_cast<double>(rt.live_events());
}
BENCHMARK(BM_EngineMemoMapPropagate)->Arg(1 << 10)->Arg(1 << 16);

// The same map with each element's own work (64 multiply-adds) memoized apart from the list
// step, on the element alone: memo() (Near = false) or memo_near(16). The list steps' keys
// hold the element and its predecessor, so only the work's reuse can reach far. Each iteration moves a random element to a random
// place and back: four places change, the moved element's work is far from its old call.
struct NearOut {
  long value = 0;
  Mod<long> work;
  Mod<NearOut*> next;
};
void near_work(Engine& rt, Cell* c, NearOut* o) {
  long x = c->value;
  for (int k = 0; k < 64; ++k) x = x * 6364136223846793005L + 1442695040888963407L;
  rt.write(o->work, x);
}
// pred, grand: the two elements before c (the key of the read of c->next holds c and pred).
template <bool Near>
void near_step(Engine& rt, Cell* c, Mod<NearOut*>* dst, Cell* pred, Cell* grand) {
  (void)grand;
  if (!c) return rt.write(*dst, static_cast<NearOut*>(nullptr));
  NearOut* o = rt.alloc<NearOut>(c->id);
  rt.write(*dst, o);
  if constexpr (Near) rt.memo_near(16, sac::fn<near_work>(c, o));
  else rt.memo(sac::fn<near_work>(c, o));
  rt.memo_read(c->next, sac::fn<near_step<Near>>(&o->next, c, pred));
}

template <bool Near>
void BM_EngineMemoNearMove(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Engine rt;
  Mod<Cell*> head;
  Mod<NearOut*> out;
  std::vector<std::unique_ptr<Cell>> cells;
  std::vector<Cell*> order;
  for (std::size_t i = 0; i < n; ++i) {
    cells.push_back(std::make_unique<Cell>(static_cast<int>(i), i));
    order.push_back(cells.back().get());
  }
  const auto relink = [&] {
    rt.set(head, order.front());
    for (std::size_t i = 0; i < n; ++i) rt.set(order[i]->next, i + 1 < n ? order[i + 1] : nullptr);
  };
  relink();
  // After a move between places a and b, only the links around them can differ.
  const auto fix = [&](std::size_t a, std::size_t b) {
    rt.set(head, order.front());
    for (const std::size_t p : {a, b})
      for (std::size_t i = p >= 2 ? p - 2 : 0; i < std::min(n, p + 2); ++i)
        rt.set(order[i]->next, i + 1 < n ? order[i + 1] : nullptr);
  };
  rt.run([&](Engine& rt2) { rt2.memo_read(head, sac::fn<near_step<Near>>(&out, static_cast<Cell*>(nullptr), static_cast<Cell*>(nullptr))); });
  std::mt19937_64 rng(5);
  const std::uint64_t d0 = rt.stats().events_created + rt.stats().events_undone;
  std::uint64_t propagations = 0;
  for (auto _ : state) {
    const std::size_t from = rng() % n, to = rng() % n;
    Cell* c = order[from];
    order.erase(order.begin() + static_cast<long>(from));
    order.insert(order.begin() + static_cast<long>(to), c);
    fix(from, to);
    rt.propagate();
    order.erase(order.begin() + static_cast<long>(to));
    order.insert(order.begin() + static_cast<long>(from), c);
    fix(from, to);
    rt.propagate();
    propagations += 2;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(propagations));
  state.counters["distance_per_propagate"] =
      propagations ? static_cast<double>(rt.stats().events_created + rt.stats().events_undone - d0) /
                         static_cast<double>(propagations)
                   : 0.0;
}
BENCHMARK_TEMPLATE(BM_EngineMemoNearMove, true)->Arg(1 << 10)->Arg(1 << 14);
BENCHMARK_TEMPLATE(BM_EngineMemoNearMove, false)->Arg(1 << 10)->Arg(1 << 14);

// Steps that each read k = 4 modifiables (step i: in[i..i+3] cyclically, overlapping as the
// mesh's neighbouring cells do) and write their sum: one read_many, or 4 nested reads.
constexpr int kManyK = 4;

struct SumMany {
  Mod<int>* out;
  void operator()(Engine& rt, std::span<const int* const> v) const {
    int s = 0;
    for (const int* x : v) s += *x;
    rt.write(*out, s);
  }
};

struct SumNested {
  const std::vector<Mod<int>>* in;
  Mod<int>* out;
  std::uint32_t step, j;
  int acc;
  void operator()(Engine& rt, int v) const {
    if (j + 1 == kManyK) {
      rt.write(*out, acc + v);
      return;
    }
    const std::size_t n = in->size();
    rt.read((*in)[(step + j + 1) % n], SumNested{in, out, step, j + 1, acc + v});
  }
};

template <bool kMany>
void run_steps(Engine& rt, Flat& f) {
  const std::size_t n = f.in.size();
  for (std::size_t i = 0; i < n; ++i) {
    if constexpr (kMany) {
      rt.read_many({&f.in[i], &f.in[(i + 1) % n], &f.in[(i + 2) % n], &f.in[(i + 3) % n]},
                   SumMany{&f.out[i]});
    } else {
      rt.read(f.in[i], SumNested{&f.in, &f.out[i], static_cast<std::uint32_t>(i), 0, 0});
    }
  }
}

template <bool kMany>
void BM_EngineRead4FromScratch(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  double bytes = 0, events = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto rt = std::make_unique<Engine>();
    auto f = std::make_unique<Flat>(n);
    for (std::size_t i = 0; i < n; ++i) rt->set(f->in[i], static_cast<int>(i));
    state.ResumeTiming();
    rt->run([&](Engine& rt2) { run_steps<kMany>(rt2, *f); });
    benchmark::DoNotOptimize(f->out[n - 1].get());
    state.PauseTiming();
    bytes = static_cast<double>(rt->record_bytes()) / static_cast<double>(n);
    events = static_cast<double>(rt->live_events()) / static_cast<double>(n);
    rt.reset();
    f.reset();
    state.ResumeTiming();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(n));
  state.counters["record_bytes_per_step"] = bytes;
  state.counters["events_per_step"] = events;
}
BENCHMARK_TEMPLATE(BM_EngineRead4FromScratch, true)->Arg(1 << 10)->Arg(1 << 18);
BENCHMARK_TEMPLATE(BM_EngineRead4FromScratch, false)->Arg(1 << 10)->Arg(1 << 18);

/// The timed loop of the propagate benchmarks: each iteration adds delta to a random input
/// and propagates.
void propagate_changes(benchmark::State& state, Engine& rt, Flat& f, int delta) {
  const std::size_t n = f.in.size();
  std::mt19937_64 rng(7);
  std::uint64_t propagations = 0, reexecuted = 0;
  for (auto _ : state) {
    const std::size_t i = static_cast<std::size_t>(rng() % n);
    rt.set(f.in[i], f.in[i].get() + delta);
    rt.propagate();
    ++propagations;
    reexecuted += rt.stats().last_reexecuted;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(propagations));
  state.counters["reexecuted_per_propagate"] =
      propagations ? static_cast<double>(reexecuted) / static_cast<double>(propagations) : 0.0;
}

template <bool kMany>
void BM_EngineRead4Propagate(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Engine rt;
  Flat f(n);
  for (std::size_t i = 0; i < n; ++i) rt.set(f.in[i], static_cast<int>(i));
  rt.run([&](Engine& rt2) { run_steps<kMany>(rt2, f); });
  propagate_changes(state, rt, f, 1);  // always a change: 4 steps read it
  state.counters["trace_bytes_per_step"] = static_cast<double>(rt.trace_bytes()) / static_cast<double>(n);
  state.counters["record_bytes_per_step"] = static_cast<double>(rt.record_bytes()) / static_cast<double>(n);
}
BENCHMARK_TEMPLATE(BM_EngineRead4Propagate, true)->Arg(1 << 10)->Arg(1 << 16);
BENCHMARK_TEMPLATE(BM_EngineRead4Propagate, false)->Arg(1 << 10)->Arg(1 << 16);

// The same steps reading a projection: each sums its 4 values' low 4 bits only. With
// affected() (a read of a projection) a change of the high bits re-runs none of the 4 steps
// that read the input; without it, all 4. Args: n, then the change (16: high bits only; 1:
// the low bits too).
template <bool kProjected>
struct SumLow {
  Mod<int>* out;
  void operator()(Engine& rt, std::span<const int* const> v) const {
    int s = 0;
    for (const int* x : v) s += *x & 15;
    rt.write(*out, s);
  }
};
template <>
struct SumLow<true> : SumLow<false> {
  bool affected(std::size_t, const int& before, const int& after) const { return (before & 15) != (after & 15); }
};

template <bool kProjected>
void BM_EngineRead4ProjectionPropagate(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const int delta = static_cast<int>(state.range(1));
  Engine rt;
  Flat f(n);
  for (std::size_t i = 0; i < n; ++i) rt.set(f.in[i], static_cast<int>(i));
  rt.run([&](Engine& rt2) {
    for (std::size_t i = 0; i < n; ++i)
      rt2.read_many({&f.in[i], &f.in[(i + 1) % n], &f.in[(i + 2) % n], &f.in[(i + 3) % n]},
                   SumLow<kProjected>{{&f.out[i]}});
  });
  propagate_changes(state, rt, f, delta);
}
BENCHMARK_TEMPLATE(BM_EngineRead4ProjectionPropagate, true)->Args({1 << 16, 16})->Args({1 << 16, 1});
BENCHMARK_TEMPLATE(BM_EngineRead4ProjectionPropagate, false)->Args({1 << 16, 16})->Args({1 << 16, 1});

}  // namespace
