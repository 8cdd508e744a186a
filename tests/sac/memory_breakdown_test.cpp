// Tests of Engine::memory_breakdown() (sac/memory_breakdown.hpp): on a list map with keyed
// allocation, unkeyed allocation, memo entries and memoized reads, each record kind's count
// equals the events the program made, its bytes equal the record sizes, the parts sum to
// trace_bytes() exactly, and after updates the breakdown equals a from-scratch run's on the
// same input.
#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "../sanitized.hpp"
#include "sac/detail/ops.hpp"
#include "sac/detail/trace_nodes.hpp"
#include "sac/sac.hpp"

namespace {

using sac::Engine;
using sac::MemoryBreakdown;
using sac::Mod;
using sac::RecordBytes;

// ------------------------------------------------------------------ the program
//
// out = map (2·x) over the input list: per present element, one keyed allocation (the
// output cell, under the element's id), one write (the link to it), one memo entry, one
// unkeyed allocation for even values, and one memo_read of the element's tail; plus the
// first read of the head and the final write of the empty tail.

struct Cell {
  long value;
  std::uint64_t id;
  Mod<Cell*> next;
  Cell(long v, std::uint64_t i) : value(v), id(i) {}
};

struct Out {
  long v;
  Mod<Out*> next;
  explicit Out(long x) : v(x) {}
};

struct Tag {
  long v;
  explicit Tag(long x) : v(x) {}
};

void note(Engine&, long* sink, std::uint64_t id) { *sink += static_cast<long>(id); }

void step(Engine& rt, Cell* c, Mod<Out*>* dst, long* sink) {
  if (!c) {
    rt.write(*dst, static_cast<Out*>(nullptr));
    return;
  }
  Out* o = rt.alloc<Out>(c->id, 2 * c->value);
  rt.write(*dst, o);
  if (c->value % 2 == 0) rt.make<Tag>(c->value);
  rt.memo(sac::fn<note>(sink, c->id));
  rt.memo_read(c->next, sac::fn<step>(&o->next, sink));
}

using StepFn = decltype(sac::fn<step>(static_cast<Mod<Out*>*>(nullptr), static_cast<long*>(nullptr)));
using NoteFn = decltype(sac::fn<note>(static_cast<long*>(nullptr), std::uint64_t{0}));

/// The input list over values, element i present or not, and the map's output; the engine
/// is declared last so that it dies first.
class MapRun {
 public:
  MapRun(const std::vector<long>& values, const std::vector<bool>& present) : present_(present) {
    for (std::size_t i = 0; i < values.size(); ++i)
      cells_.push_back(std::make_unique<Cell>(values[i], i));
    Cell* nx = nullptr;
    for (std::size_t i = values.size(); i-- > 0;) {
      rt.set(cells_[i]->next, present_[i] ? nx : static_cast<Cell*>(nullptr));
      if (present_[i]) nx = cells_[i].get();
    }
    rt.set(head_, nx);
    rt.run([this](Engine& rt2) { rt2.read(head_, sac::fn<step>(&out_, &sink_)); });
  }

  void toggle(std::size_t i) {
    Mod<Cell*>& before = link_before(i);
    Cell* c = cells_[i].get();
    if (present_[i]) {
      rt.set(before, c->next.get());
    } else {
      rt.set(c->next, before.get());
      rt.set(before, c);
    }
    present_[i] = !present_[i];
  }

  const std::vector<bool>& presence() const { return present_; }
  std::size_t present_count() const {
    std::size_t k = 0;
    for (bool p : present_) k += p;
    return k;
  }
  std::size_t present_even(const std::vector<long>& values) const {
    std::size_t k = 0;
    for (std::size_t i = 0; i < values.size(); ++i) k += present_[i] && values[i] % 2 == 0;
    return k;
  }
  std::vector<long> output() const {
    std::vector<long> r;
    for (Out* o = out_.get(); o; o = o->next.get()) r.push_back(o->v);
    return r;
  }

 private:
  Mod<Cell*>& link_before(std::size_t i) {
    for (std::size_t j = i; j-- > 0;)
      if (present_[j]) return cells_[j]->next;
    return head_;
  }

  std::vector<std::unique_ptr<Cell>> cells_;
  std::vector<bool> present_;
  Mod<Cell*> head_;
  Mod<Out*> out_;
  long sink_ = 0;

 public:
  Engine rt;
};

std::vector<long> values_of(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<long> v(n);
  for (long& x : v) x = static_cast<long>(rng() % 1000);
  return v;
}

/// The parts sum to trace_bytes(), the records to record_bytes(), the base versions to
/// input_bytes(), and the counts to live_events().
void expect_sums(const Engine& rt, const MemoryBreakdown& b) {
  EXPECT_EQ(b.unaccounted, 0);
  EXPECT_EQ(b.records(), rt.record_bytes());
  EXPECT_EQ(b.trace(), rt.trace_bytes());
  EXPECT_EQ(b.inputs.bytes(), rt.input_bytes());
  std::size_t parts = 0;
  b.for_each_part([&](const char*, std::uint64_t, std::size_t bytes) { parts += bytes; });
  EXPECT_EQ(parts, rt.trace_bytes());
  EXPECT_EQ(b.reads.count + b.versions.count + b.memos.count + b.keyed_allocs.count +
                b.plain_allocs.count,
            rt.live_events());
  std::uint64_t sized = 0;
  std::size_t sized_bytes = 0;
  for (const auto& [bytes, count] : b.read_sizes) {
    sized += count;
    sized_bytes += bytes * count;
  }
  EXPECT_EQ(sized, b.reads.count);
  EXPECT_EQ(sized_bytes, b.reads.bytes());
  EXPECT_EQ(b.size_class_rounding, 0u);  // every record is 8-aligned
  EXPECT_EQ(b.pool_large, 0u);
  EXPECT_GE(b.pool_reserved, b.records() + b.inputs.bytes());
}

RecordBytes kind(std::uint64_t count, std::size_t header, std::size_t key, std::size_t payload) {
  return RecordBytes{count, count * header, count * key, count * payload};
}

// ------------------------------------------------------------------ tests

TEST(MemoryBreakdown, CountsAndBytesFollowTheProgramsEvents) {
  const std::vector<long> values = values_of(200, 1);
  std::vector<bool> present(values.size(), true);
  for (std::size_t i = 0; i < present.size(); i += 7) present[i] = false;
  MapRun run(values, present);
  const std::size_t n = run.present_count();
  const std::size_t even = run.present_even(values);
  const MemoryBreakdown b = run.rt.memory_breakdown();

  using sac::detail::AllocNode;
  using sac::detail::MemoNode;
  using sac::detail::ReadNode;
  using sac::detail::VersionBase;
  // One read of each present element's tail, and the first read of the head.
  EXPECT_EQ(b.reads, kind(n + 1, sizeof(ReadNode), 0, sizeof(sac::detail::ReadNodeT<StepFn>) - sizeof(ReadNode)));
  // One write per present element and the empty tail's.
  EXPECT_EQ(b.versions, kind(n + 1, sizeof(VersionBase), 0, sizeof(sac::detail::Version<Out*>) - sizeof(VersionBase)));
  EXPECT_EQ(b.memos, kind(n, sizeof(MemoNode), 0, sizeof(sac::detail::MemoNodeT<NoteFn>) - sizeof(MemoNode)));
  // Keyed: a 32-byte header, the 8-byte key, the 16-byte Out.
  EXPECT_EQ(b.keyed_allocs, kind(n, sizeof(AllocNode), sizeof(std::uint64_t), sizeof(Out)));
  EXPECT_EQ(b.plain_allocs, kind(even, sizeof(AllocNode), 0, sizeof(Tag)));
  // Base versions: the head and every element's link, present or not.
  EXPECT_EQ(b.inputs, kind(values.size() + 1, sizeof(VersionBase), 0, sizeof(void*)));
  ASSERT_EQ(b.read_sizes.size(), 1u);  // every read is a step
  EXPECT_EQ(b.read_sizes[0].first, sizeof(sac::detail::ReadNodeT<StepFn>));
  expect_sums(run.rt, b);
  EXPECT_GT(b.order_groups, 0u);
  EXPECT_GT(b.order_bytes, 0u);
  EXPECT_GT(b.alloc_table_bytes, 0u);
  EXPECT_GT(b.memo_table_bytes, 0u);
  EXPECT_GT(b.engine_vectors, 0u);
  // The printout ends with the reads by block size.
  std::ostringstream text;
  text << b;
  EXPECT_NE(text.str().find("read blocks (bytes x count): " + std::to_string(sizeof(sac::detail::ReadNodeT<StepFn>)) +
                            'x' + std::to_string(n + 1) + '\n'),
            std::string::npos)
      << text.str();
}

TEST(MemoryBreakdown, KeyBytesAreWhereTheObjectStarts) {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Winvalid-offsetof"
  auto key_bytes = [](auto tag_t, auto tag_k) {
    using T = typename decltype(tag_t)::type;
    using K = typename decltype(tag_k)::type;
    using N = sac::detail::AllocNodeT<T, K>;
    using Ops = sac::detail::AllocOpsFor<T, K>;
    EXPECT_EQ(Ops::keyed.key_bytes, offsetof(N, object) - sizeof(sac::detail::AllocNode));
    EXPECT_EQ(&Ops::ops, &Ops::keyed.ops);
  };
#pragma GCC diagnostic pop
  key_bytes(std::type_identity<Out>{}, std::type_identity<std::uint64_t>{});
  key_bytes(std::type_identity<long>{}, std::type_identity<int>{});
  key_bytes(std::type_identity<char>{}, std::type_identity<char>{});
  key_bytes(std::type_identity<std::string>{}, std::type_identity<std::pair<int, std::uint8_t>>{});
  key_bytes(std::type_identity<std::uint32_t>{}, std::type_identity<std::tuple<void*, int>>{});
}

TEST(MemoryBreakdown, AfterUpdatesEqualsAFromScratchRun) {
  const std::vector<long> values = values_of(test_support::kSanitized ? 120 : 400, 2);
  MapRun run(values, std::vector<bool>(values.size(), true));
  std::mt19937_64 rng(3);
  for (int round = 0; round < 30; ++round) {
    const int k = 1 + static_cast<int>(rng() % 3);  // batches of one to three edits
    for (int j = 0; j < k; ++j) run.toggle(rng() % values.size());
    run.rt.propagate();
    const MemoryBreakdown b = run.rt.memory_breakdown();
    expect_sums(run.rt, b);

    MapRun fresh(values, run.presence());
    ASSERT_EQ(run.output(), fresh.output());
    const MemoryBreakdown f = fresh.rt.memory_breakdown();
    EXPECT_EQ(b.reads, f.reads) << "round " << round;
    EXPECT_EQ(b.versions, f.versions) << "round " << round;
    EXPECT_EQ(b.memos, f.memos) << "round " << round;
    EXPECT_EQ(b.keyed_allocs, f.keyed_allocs) << "round " << round;
    EXPECT_EQ(b.plain_allocs, f.plain_allocs) << "round " << round;
    EXPECT_EQ(b.inputs, f.inputs) << "round " << round;
    EXPECT_EQ(b.records(), f.records());
    EXPECT_EQ(b.reads.count, run.present_count() + 1);
  }
}

TEST(MemoryBreakdown, LargeBlocksAndMisuse) {
  Engine rt;
  Mod<int> m;
  rt.set(m, 1);
  rt.run([&](Engine& rt2) {
    rt2.read(m, [](Engine& rt3, int v) { rt3.make<std::array<char, 600>>(std::array<char, 600>{static_cast<char>(v)}); });
  });
  const MemoryBreakdown b = rt.memory_breakdown();
  EXPECT_EQ(b.plain_allocs.count, 1u);
  EXPECT_EQ(b.reads.count, 1u);
  EXPECT_EQ(b.read_sizes.size(), 1u);
  EXPECT_EQ(b.pool_large, (sizeof(sac::detail::AllocNode) + 600 + 7) / 8 * 8);
  EXPECT_EQ(b.unaccounted, 0);
  EXPECT_EQ(b.trace(), rt.trace_bytes());
  EXPECT_EQ(b.pool_unused(), b.pool_reserved - (b.records() + b.inputs.bytes() - b.pool_large));

  Engine rt2;
  EXPECT_THROW(rt2.run([](Engine& rt3) { (void)rt3.memory_breakdown(); }), sac::UsageError);
}

}  // namespace
