// Tests of Engine::read_many: k modifiables read as one trace event.
//
// What is checked: re-execution counts (one re-run per affected multi-read, none for cut-off
// writes or writes inside its interval, changes outside a read of a projection's
// projection), the version it sees when a modifiable is written
// several times or a write it saw is undone, defaults (init_default), that it is one event,
// that a change undone before propagation reaches a read does not re-run it, that a read
// with follow() moves a slot instead of re-running and then depends on the new modifiable,
// and random differential programs (plain and inside memoized regions) against the same
// programs written with k nested reads: equal outputs after every propagate(), a live trace
// of a from-scratch run's size, and check_invariants() after every update.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <random>
#include <span>
#include <type_traits>
#include <vector>

#include "../sanitized.hpp"
#include "sac/sac.hpp"

namespace {

using sac::Engine;
using sac::Mod;
using sac::ReadSlots;
using Vals = std::span<const int* const>;

int sum(Vals v) {
  int s = 0;
  for (std::size_t i = 0; i < v.size(); ++i) s = s * 10 + *v[i];
  return s;
}

TEST(ReadMany, OneEventAndOneRerunPerChange) {
  Mod<int> a, b, c, d, out;
  Engine rt;
  rt.set(a, 1);
  rt.set(b, 2);
  rt.set(c, 3);
  rt.set(d, 4);
  int runs = 0;
  rt.run([&](Engine& rt2) {
    rt2.read_many({&a, &b, &c, &d}, [&out, &runs](Engine& rt3, Vals v) {
      ++runs;
      rt3.write(out, sum(v));
    });
  });
  EXPECT_EQ(out.get(), 1234);
  EXPECT_EQ(rt.live_events(), 2u);  // the multi-read and the write
  EXPECT_EQ(rt.stats().events_created, 2u);
  rt.check_invariants();

  rt.set(c, 7);
  rt.propagate();
  EXPECT_EQ(out.get(), 1274);
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);
  EXPECT_EQ(runs, 2);

  rt.set(a, 5);  // two of the four change: still one re-run
  rt.set(d, 9);
  rt.propagate();
  EXPECT_EQ(out.get(), 5279);
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);
  EXPECT_EQ(runs, 3);

  rt.set(b, 2);  // equal: cut off
  rt.propagate();
  EXPECT_EQ(rt.stats().last_reexecuted, 0u);
  EXPECT_EQ(runs, 3);
  EXPECT_EQ(rt.live_events(), 2u);
  rt.check_invariants();
}

TEST(ReadMany, BodyWithoutEngineAndRepeatedModifiables) {
  Mod<int> a, b;
  Engine rt;
  rt.set(a, 1);
  rt.set(b, 2);
  int seen = 0;
  rt.run([&](Engine& rt2) {
    const std::array<const Mod<int>*, 3> ms{&a, &b, &a};
    rt2.read_many(std::span<const Mod<int>* const>(ms), [&seen](Vals v) { seen = sum(v); });
  });
  EXPECT_EQ(seen, 121);
  rt.set(a, 3);
  rt.propagate();
  EXPECT_EQ(seen, 323);
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);
  rt.check_invariants();
}

TEST(ReadMany, SizeOutOfRangeIsAUsageError) {
  Mod<int> a;
  Engine rt;
  rt.set(a, 1);
  EXPECT_THROW(rt.run([&](Engine& rt2) {
    rt2.read_many(std::span<const Mod<int>* const>(), [](Vals) {});
  }),
               sac::UsageError);
  Engine rt2;
  Mod<int> a2;
  rt2.set(a2, 1);
  std::vector<const Mod<int>*> many2(17, &a2);
  EXPECT_THROW(rt2.run([&](Engine& rt3) {
    rt3.read_many(std::span<const Mod<int>* const>(many2), [](Vals) {});
  }),
               sac::UsageError);
}

TEST(ReadMany, SeesTheLatestVersionBeforeItAndIgnoresWritesInsideItsInterval) {
  // sel -> m written before the multi-read; the multi-read writes m itself (inside its
  // interval) and a later plain read sees that write.
  Mod<int> sel, m, y, out, out2;
  Engine rt;
  rt.set(sel, 1);
  rt.set(m, 0);
  rt.set(y, 5);
  int runs = 0;
  rt.run([&](Engine& rt2) {
    rt2.read(sel, [&m](Engine& rt3, int s) { rt3.write(m, s * 10); });
    rt2.write(m, 7);  // a second version before the multi-read: the one it sees
    rt2.read_many({&m, &y}, [&out, &m, &runs](Engine& rt3, Vals v) {
      ++runs;
      rt3.write(out, *v[0] + *v[1]);
      rt3.write(m, 100 + *v[1]);  // inside its own interval: does not affect it
    });
    rt2.read(m, [&out2](Engine& rt3, int v) { rt3.write(out2, v); });
  });
  EXPECT_EQ(out.get(), 12);
  EXPECT_EQ(out2.get(), 105);
  EXPECT_EQ(runs, 1);

  rt.set(sel, 2);  // the version before 7: hidden from the multi-read
  rt.propagate();
  EXPECT_EQ(runs, 1);
  EXPECT_EQ(rt.stats().last_reexecuted, 1u);  // only the read of sel

  rt.set(y, 6);  // the multi-read re-runs, its own write changes, the later read follows
  rt.propagate();
  EXPECT_EQ(runs, 2);
  EXPECT_EQ(out.get(), 13);
  EXPECT_EQ(out2.get(), 106);
  EXPECT_EQ(rt.stats().last_reexecuted, 2u);
  rt.check_invariants();
}

TEST(ReadMany, AWriteInsertedBeforeItOrUndoneRerunsItOnce) {
  Mod<int> sel, m, a, out;
  Engine rt;
  rt.set(sel, 0);
  rt.set(m, 1);
  rt.set(a, 2);
  int runs = 0;
  rt.run([&](Engine& rt2) {
    rt2.read(sel, [&m](Engine& rt3, int s) {
      if (s) rt3.write(m, s);
    });
    rt2.read_many({&a, &m}, [&out, &runs](Engine& rt3, Vals v) {
      ++runs;
      rt3.write(out, sum(v));
    });
  });
  EXPECT_EQ(out.get(), 21);
  rt.set(sel, 5);  // a new version of m before it: the split moves its slot, once
  rt.propagate();
  EXPECT_EQ(out.get(), 25);
  EXPECT_EQ(runs, 2);
  rt.check_invariants();
  rt.set(sel, 1);  // the version it sees is replaced by an equal-to-base value: changed (5 -> 1)
  rt.propagate();
  EXPECT_EQ(out.get(), 21);
  EXPECT_EQ(runs, 3);
  rt.set(sel, 0);  // the write is undone: m's base value 1 again, equal: cut off
  rt.propagate();
  EXPECT_EQ(runs, 3);
  EXPECT_EQ(out.get(), 21);
  rt.set(m, 4);
  rt.propagate();
  EXPECT_EQ(out.get(), 24);
  EXPECT_EQ(runs, 4);
  rt.check_invariants();
}

TEST(ReadMany, DefaultsAndTheirVersions) {
  Mod<int> sel, d, a, out;
  Engine rt;
  rt.set(sel, 0);
  rt.init_default(d);
  rt.set(a, 3);
  int runs = 0;
  rt.run([&](Engine& rt2) {
    rt2.read_many({&d, &a}, [&out, &runs](Engine& rt3, Vals v) {
      ++runs;
      rt3.write(out, sum(v));
    });
    rt2.read(sel, [&d](Engine& rt3, int s) {
      if (s) rt3.write(d, s);  // after the multi-read: a version it does not see
    });
  });
  EXPECT_EQ(out.get(), 3);
  rt.set(sel, 4);
  rt.propagate();
  EXPECT_EQ(runs, 1);
  EXPECT_EQ(out.get(), 3);
  rt.check_invariants();
  rt.set(a, 5);
  rt.propagate();
  EXPECT_EQ(runs, 2);
  EXPECT_EQ(out.get(), 5);
  rt.set(sel, 0);
  rt.propagate();
  EXPECT_EQ(runs, 2);
  rt.check_invariants();
}

TEST(ReadMany, DefaultWrittenBeforeItThenUndone) {
  Mod<int> sel, d, out;
  Engine rt;
  rt.set(sel, 0);
  rt.init_default(d);
  int runs = 0;
  rt.run([&](Engine& rt2) {
    rt2.read(sel, [&d](Engine& rt3, int s) {
      if (s) rt3.write(d, s);
    });
    rt2.read_many({&d, &d}, [&out, &runs](Engine& rt3, Vals v) {
      ++runs;
      rt3.write(out, sum(v));
    });
  });
  EXPECT_EQ(out.get(), 0);
  rt.set(sel, 3);
  rt.propagate();
  EXPECT_EQ(out.get(), 33);
  EXPECT_EQ(runs, 2);
  rt.check_invariants();
  rt.set(sel, 0);  // undone: back to the default
  rt.propagate();
  EXPECT_EQ(out.get(), 0);
  EXPECT_EQ(runs, 3);
  rt.check_invariants();
}

// ------------------------------------------------------------------ differential

/// A random program: groups of steps, each group under a read of a control input and a
/// memoized call; a step reads k modifiables (inputs and cells, repeats allowed) and writes
/// one or two cells. Run with read_many or with k nested reads.
struct Step {
  std::array<int, 16> src{};  // indices into mods(): inputs first, then cells
  int k = 0;
  int dst = 0, dst2 = 0;
};

struct Program {
  static constexpr int kInputs = 8, kCells = 8, kGroups = 4;
  std::vector<Step> steps;  // kGroups groups of equal length
  bool many = false;
  std::array<Mod<int>, kInputs> in;
  std::array<Mod<int>, kCells> cell;
  std::array<Mod<int>, kGroups> ctrl;
  std::array<Mod<int>, kGroups> gout;
  Engine rt;

  const Mod<int>* mod(int i) const { return i < kInputs ? &in[i] : &cell[i - kInputs]; }

  static void finish(Engine& rt2, Program* p, int s, const std::array<int, 16>& vals) {
    const Step& st = p->steps[s];
    std::uint64_t h = 1469598103934665603ull + s;
    for (int i = 0; i < st.k; ++i) h = (h ^ static_cast<std::uint64_t>(vals[i] + 7)) * 1099511628211ull;
    rt2.write(p->cell[st.dst], static_cast<int>(h % 5));
    if (h % 3 == 0) rt2.write(p->cell[st.dst2], static_cast<int>((h >> 8) % 4));
  }
  struct Nest {
    Program* p;
    int s, i;
    std::array<int, 16> vals;
    void operator()(Engine& rt2, int v) const {
      Nest n = *this;
      n.vals[i] = v;
      if (++n.i == p->steps[s].k) finish(rt2, p, s, n.vals);
      else rt2.read(*p->mod(p->steps[s].src[n.i]), n);
    }
  };
  static void step(Engine& rt2, Program* p, int s) {
    const Step& st = p->steps[s];
    if (p->many) {
      std::array<const Mod<int>*, 16> ms{};
      for (int i = 0; i < st.k; ++i) ms[i] = p->mod(st.src[i]);
      rt2.read_many(std::span<const Mod<int>* const>(ms.data(), st.k), [p, s](Engine& rt3, Vals v) {
        std::array<int, 16> vals{};
        for (std::size_t i = 0; i < v.size(); ++i) vals[i] = *v[i];
        finish(rt3, p, s, vals);
      });
    } else {
      rt2.read(*p->mod(st.src[0]), Nest{p, s, 0, {}});
    }
  }
  static void group(Engine& rt2, Program* p, int g, int parity) {
    const int per = static_cast<int>(p->steps.size()) / kGroups;
    for (int s = g * per; s < (g + 1) * per; ++s) step(rt2, p, s);
    rt2.write(p->gout[g], parity);
  }
  void body(Engine& rt2) {
    for (int g = 0; g < kGroups; ++g)
      rt2.read(ctrl[g], [this, g](Engine& rt3, int c) {
        rt3.memo(sac::fn<&Program::group>(this, g, c % 2));  // odd changes miss, even hit
        rt3.write(gout[g], c);
      });
  }
  void setup(const std::vector<int>& inputs) {
    for (int i = 0; i < kInputs; ++i) rt.set(in[i], inputs[i]);
    for (int i = 0; i < kCells; ++i) {
      if (i % 2) rt.init_default(cell[i]);
      else rt.set(cell[i], 1);
    }
    for (int g = 0; g < kGroups; ++g) rt.set(ctrl[g], inputs[kInputs + g]);
    rt.run([this](Engine& rt2) { body(rt2); });
  }
  void propagate_and_check() {
    rt.propagate();
    rt.check_invariants();
  }
  void set(int i, int v) {
    if (i < kInputs) rt.set(in[i], v);
    else rt.set(ctrl[i - kInputs], v);
  }
  std::vector<int> outputs() const {
    std::vector<int> o;
    for (const auto& c : cell) o.push_back(c.get());
    for (const auto& g : gout) o.push_back(g.get());
    return o;
  }
};

TEST(ReadManyDifferential, MatchesNestedReadsAndFromScratch) {
  const int kSeeds = test_support::kSanitized ? 8 : 40;
  const int kUpdates = test_support::kSanitized ? 20 : 60;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 rng(static_cast<unsigned>(seed));
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    std::vector<Step> steps(Program::kGroups * uni(1, 4));
    for (Step& st : steps) {
      st.k = uni(1, seed % 3 == 0 ? 16 : 5);
      for (int i = 0; i < st.k; ++i) st.src[i] = uni(0, Program::kInputs + Program::kCells - 1);
      st.dst = uni(0, Program::kCells - 1);
      st.dst2 = uni(0, Program::kCells - 1);
    }
    std::vector<int> inputs(Program::kInputs + Program::kGroups);
    for (int& v : inputs) v = uni(0, 3);
    auto many = std::make_unique<Program>();
    auto nested = std::make_unique<Program>();
    many->steps = nested->steps = steps;
    many->many = true;
    many->setup(inputs);
    nested->setup(inputs);
    ASSERT_EQ(many->outputs(), nested->outputs());
    for (int u = 0; u < kUpdates; ++u) {
      const int n = uni(1, 3);
      for (int j = 0; j < n; ++j) {
        const int i = uni(0, static_cast<int>(inputs.size()) - 1);
        inputs[i] = uni(0, 3);
        many->set(i, inputs[i]);
        nested->set(i, inputs[i]);
      }
      many->propagate_and_check();
      nested->rt.propagate();
      ASSERT_EQ(many->outputs(), nested->outputs()) << "update " << u;
      // From scratch on the same inputs: same outputs, same live trace.
      auto scratch = std::make_unique<Program>();
      scratch->steps = steps;
      scratch->many = true;
      scratch->setup(inputs);
      ASSERT_EQ(many->outputs(), scratch->outputs()) << "update " << u;
      ASSERT_EQ(many->rt.live_events(), scratch->rt.live_events()) << "update " << u;
      ASSERT_EQ(many->rt.record_bytes(), scratch->rt.record_bytes()) << "update " << u;
      ASSERT_LE(many->rt.live_events(), nested->rt.live_events());
    }
  }
}

}  // namespace

namespace {

// A nested read_many that extends the outer one's set: the inner body looks the outer
// values up with Engine::current. A change to any of them re-runs the outer read, and so
// the whole nest; a change to an inner one re-runs only the inner read.
struct Extend {
  std::array<const Mod<int>*, 2> outer;
  Mod<int>* out;
  int* inner_runs;
  void operator()(Engine& rt, Vals v) const {
    ++*inner_runs;
    rt.write(*out, rt.current(*outer[0]) * 100 + rt.current(*outer[1]) * 10 + *v[0]);
  }
};

}  // namespace

TEST(ReadMany, CurrentLooksUpTheValuesOfAnEnclosingRead) {
  Mod<int> a, b, c, d, out;
  Engine rt;
  rt.set(a, 1);
  rt.set(b, 2);
  rt.set(c, 3);
  rt.set(d, 4);
  int outer_runs = 0, inner_runs = 0;
  rt.run([&](Engine& rt2) {
    rt2.read_many({&a, &b}, [&](Engine& rt3, Vals v) {
      ++outer_runs;
      // Which inner modifiable depends on the outer values, as a search's next cell does.
      const Mod<int>* next = *v[0] + *v[1] > 5 ? &d : &c;
      rt3.read_many({next}, Extend{{&a, &b}, &out, &inner_runs});
    });
  });
  EXPECT_EQ(out.get(), 123);
  rt.check_invariants();

  rt.set(c, 8);  // inner only
  rt.propagate();
  EXPECT_EQ(out.get(), 128);
  EXPECT_EQ(outer_runs, 1);
  EXPECT_EQ(inner_runs, 2);

  rt.set(b, 7);  // outer: the nest re-runs and now reads d
  rt.propagate();
  EXPECT_EQ(out.get(), 174);
  EXPECT_EQ(outer_runs, 2);
  EXPECT_EQ(inner_runs, 3);
  rt.check_invariants();

  rt.set(c, 9);  // no longer read
  rt.propagate();
  EXPECT_EQ(inner_runs, 3);
  rt.set(a, 2);  // an outer value the inner body looks up
  rt.propagate();
  EXPECT_EQ(out.get(), 274);
  rt.check_invariants();
}

TEST(ReadMany, CurrentOutsideTheComputationIsAUsageError) {
  Mod<int> a;
  Engine rt;
  rt.set(a, 1);
  EXPECT_THROW((void)rt.current(a), sac::UsageError);
}

TEST(ReadMany, PeekSeesTheValueVisibleNowAndRecordsNothing) {
  Mod<int> a, b, guess, later, out;
  Engine rt;
  rt.set(a, 1);
  rt.set(b, 0);
  rt.set(guess, 5);
  int runs = 0, before = 0, after = 0;
  rt.run([&](Engine& rt2) {
    rt2.read(a, [&](Engine& rt3, int v) {
      ++runs;
      const int* p = rt3.peek(later);  // written later in this body: no version visible yet
      before = p ? *p : -1;
      rt3.write(later, v * 10);
      rt3.write(out, v + *rt3.peek(guess));
      rt3.read(b, [&](Engine& rt4, int) { after = *rt4.peek(later); });  // later in time: seen
    });
  });
  EXPECT_EQ(before, -1);
  EXPECT_EQ(after, 10);
  EXPECT_EQ(out.get(), 6);

  rt.set(guess, 7);  // peeked, not read: nothing re-runs, so out keeps the old guess
  rt.propagate();
  EXPECT_EQ(runs, 1);
  EXPECT_EQ(out.get(), 6);

  rt.set(a, 2);  // the re-run undoes its old write first: the peek sees none again
  rt.propagate();
  EXPECT_EQ(runs, 2);
  EXPECT_EQ(before, -1);
  EXPECT_EQ(after, 20);
  EXPECT_EQ(out.get(), 9);
  rt.check_invariants();
}

TEST(ReadMany, PeekSeesAWriteJustMadeByTheSameBody) {
  // The write's time is now itself: a peek right after it must see it, on the first run
  // (at the trace's end) and on a re-run inside the trace alike.
  Mod<int> a, m, seen;
  Engine rt;
  rt.set(a, 1);
  rt.run([&](Engine& rt2) {
    rt2.read(a, [&](Engine& rt3, int v) {
      rt3.write(m, v * 10);
      const int* p = rt3.peek(m);
      rt3.write(seen, p ? *p : -1);
    });
  });
  EXPECT_EQ(seen.get(), 10);
  for (int v : {2, 3, 5}) {
    rt.set(a, v);
    rt.propagate();
    EXPECT_EQ(seen.get(), v * 10);
    rt.check_invariants();
  }
}

namespace {

// The prefetch pattern: a chain walk through cells[] (each value the next index, -1 ends)
// learns its cells by peeking, reads them as one read_many, and walks again on the values
// read; a cell the walk needs that the rounds have not read makes one more nested round.
constexpr int kChainCells = 12;
struct ChainWalk {
  std::array<Mod<int>, kChainCells>* cells;
  Mod<int>* out;
  int* rounds;
  std::uint32_t read_mask = 0;  // the cells this round and the rounds around it read
  template <class Value>
  std::pair<int, std::uint32_t> walk(Value value) const {
    int sum = 0;
    std::uint32_t need = 0;
    for (int i = 0, steps = 0; i >= 0 && steps < kChainCells; ++steps) {
      need |= 1u << i;
      const int next = value(i);
      sum += i;
      i = next;
    }
    return {sum, need};
  }
  void round(Engine& rt) const {
    ++*rounds;
    // Values: read ones through current (the enclosing reads depend on them), others peeked.
    const auto [sum, need] = walk([&](int i) {
      if (read_mask >> i & 1) return rt.current((*cells)[i]);
      const int* p = rt.peek((*cells)[i]);
      return p ? *p : -1;
    });
    const std::uint32_t missing = need & ~read_mask;
    if (missing == 0) return rt.write(*out, sum);
    std::vector<const Mod<int>*> mods;
    for (int i = 0; i < kChainCells; ++i)
      if (missing >> i & 1) mods.push_back(&(*cells)[i]);
    ChainWalk next = *this;
    next.read_mask |= missing;
    rt.read_many(std::span<const Mod<int>* const>(mods), [next](Engine& rt2, Vals) { next.round(rt2); });
  }
};

}  // namespace

TEST(ReadMany, APeekedPrefetchMatchesFromScratchAfterEveryChange) {
  std::array<Mod<int>, kChainCells> cells;
  Mod<int> out;
  Engine rt;
  std::mt19937 rng(20261125);
  std::printf("seed 20261125\n");
  std::array<int, kChainCells> v{};
  for (int i = 0; i < kChainCells; ++i) {
    v[i] = i + 1 < kChainCells ? i + 1 : -1;
    rt.set(cells[i], v[i]);
  }
  int rounds = 0;
  rt.run([&](Engine& rt2) { ChainWalk{&cells, &out, &rounds}.round(rt2); });
  const auto expected = [&] {
    int sum = 0;
    for (int i = 0, steps = 0; i >= 0 && steps < kChainCells; ++steps) {
      sum += i;
      i = v[i];
    }
    return sum;
  };
  EXPECT_EQ(out.get(), expected());
  EXPECT_EQ(rounds, 2);  // one peeking walk, then one round that reads every cell it needs
  for (int t = 0; t < 200; ++t) {
    const int i = static_cast<int>(rng() % kChainCells);
    v[i] = static_cast<int>(rng() % (kChainCells + 1)) - 1;
    rt.set(cells[i], v[i]);
    rt.propagate();
    ASSERT_EQ(out.get(), expected()) << "change " << t;
    rt.check_invariants();
  }
}

// --- reads of a projection (a closure with affected()) ---------------------------------------

// Depends on the last decimal digit of each value only.
struct LastDigits {
  Mod<int>* out;
  int* runs;
  void operator()(Engine& rt, Vals v) const {
    ++*runs;
    int s = 0;
    for (const int* p : v) s = s * 10 + *p % 10;
    rt.write(*out, s);
  }
  bool affected(std::size_t, const int& before, const int& after) const { return before % 10 != after % 10; }
};

TEST(ReadManyProjection, ReRunsOnlyWhenTheProjectionChanges) {
  Mod<int> sel, a, b, out;
  Engine rt;
  rt.set(sel, 0);
  rt.set(a, 11);
  rt.set(b, 22);
  int runs = 0;
  rt.run([&](Engine& rt2) {
    rt2.read(sel, [&b](Engine& rt3, int s) {
      if (s) rt3.write(b, s);  // a version of b before the multi-read
    });
    rt2.read_many({&a, &b}, LastDigits{&out, &runs});
  });
  EXPECT_EQ(out.get(), 12);
  EXPECT_EQ(runs, 1);
  // Sets m to v and propagates: the body has then run `want_runs` times in all and written
  // `want_out`.
  const auto change = [&](Mod<int>& m, int v, int want_runs, int want_out) {
    rt.set(m, v);
    rt.propagate();
    EXPECT_EQ(runs, want_runs) << "after setting " << v;
    EXPECT_EQ(out.get(), want_out) << "after setting " << v;
  };
  // set(): a new base value with the same last digit does not re-run it ...
  change(a, 41, 1, 12);
  EXPECT_EQ(rt.stats().last_reexecuted, 0u);
  // ... one with another does, and it sees the newest value.
  change(a, 43, 2, 32);
  // A write inserted before it (link_write): 72 ends in 2, as b's 22 does.
  change(sel, 72, 2, 32);
  rt.check_invariants();
  // The write replaced by one ending in 5: a change.
  change(sel, 75, 3, 35);
  // The write undone: b's base 22 ends in 2, not 5: a change.
  change(sel, 0, 4, 32);
  // Written again with 2 at the end, then undone: neither re-runs it.
  change(sel, 92, 4, 32);
  change(sel, 0, 4, 32);
  // The base value b sees changes its digit while the read is attached to it.
  change(b, 28, 5, 38);
  rt.check_invariants();
}

// LastDigits with its modulus and counters in the engine's context: affected() gets the
// engine for it, so the closure holds nothing.
struct DigitsContext {
  Mod<int>* out;
  int runs = 0;
  int asked = 0;
  int modulus = 10;
};
struct LastDigitsInContext {
  void operator()(Engine& rt, Vals v) const {
    DigitsContext* c = rt.context<DigitsContext>();
    ++c->runs;
    int s = 0;
    for (const int* p : v) s = s * c->modulus + *p % c->modulus;
    rt.write(*c->out, s);
  }
  bool affected(const Engine& rt, std::size_t, const int& before, const int& after) const {
    DigitsContext* c = rt.context<DigitsContext>();
    ++c->asked;
    return before % c->modulus != after % c->modulus;
  }
};
static_assert(std::is_empty_v<LastDigitsInContext>);

TEST(ReadManyProjection, AffectedMayTakeTheEngineForItsContext) {
  Mod<int> a, b, out;
  DigitsContext c{&out};
  Engine rt;
  rt.set_context(&c);
  rt.set(a, 11);
  rt.set(b, 22);
  rt.run([&a, &b](Engine& rt2) { rt2.read_many({&a, &b}, LastDigitsInContext{}); });
  EXPECT_EQ(out.get(), 12);
  EXPECT_EQ(c.runs, 1);
  rt.set(a, 41);  // the same last digit: asked, not re-run
  rt.propagate();
  EXPECT_EQ(c.runs, 1);
  EXPECT_GE(c.asked, 1);
  EXPECT_EQ(out.get(), 12);
  c.modulus = 100;  // the context's state is what affected() answers from
  rt.set(b, 122);  // the same two last digits: not re-run
  rt.propagate();
  EXPECT_EQ(c.runs, 1);
  rt.set(b, 133);
  rt.propagate();
  EXPECT_EQ(c.runs, 2);
  EXPECT_EQ(out.get(), 41 * 100 + 33);
  rt.check_invariants();
}

// Counts the values of slots 1.. that are below slot 0's value: it depends on all of slot 0,
// and on each other slot's side of that threshold, which the body narrows as it runs (the
// closure's mutable threshold is the read's own state).
struct BelowThreshold {
  Mod<int>* out;
  int* runs;
  mutable int threshold = 0;
  void operator()(Engine& rt, Vals v) const {
    ++*runs;
    if (v.empty()) return;  // never (k >= 1); tells g++ that v[0] was filled
    threshold = *v[0];
    int below = 0;
    for (std::size_t i = 1; i < v.size(); ++i) below += *v[i] < threshold;
    rt.write(*out, below);
  }
  bool affected(std::size_t i, const int& before, const int& after) const {
    return i == 0 || (before < threshold) != (after < threshold);
  }
};

TEST(ReadManyProjection, MatchesFromScratchAfterEveryChange) {
  // Inputs in[0..7]; the computation copies in[i] into mid[i] when sel[i] is set (a version
  // written before the reads, made, replaced and undone by the changes), then four
  // projected multi-reads count below a threshold over mid, and a plain read sums them.
  constexpr int kN = 8, kReads = 4;
  std::array<Mod<int>, kN> in, mid;
  std::array<Mod<int>, kN> sel;
  std::array<Mod<int>, kReads> outs;
  Mod<int> total;
  std::array<int, kN> vin{}, vsel{}, vmid{};
  std::mt19937 rng(20261127);
  std::printf("seed 20261127\n");
  Engine rt;
  for (int i = 0; i < kN; ++i) {
    vin[i] = static_cast<int>(rng() % 20);
    vsel[i] = static_cast<int>(rng() % 2);
    vmid[i] = static_cast<int>(rng() % 20);
    rt.set(in[i], vin[i]);
    rt.set(sel[i], vsel[i]);
    rt.set(mid[i], vmid[i]);
  }
  // Slots of read r: mid[r] (the threshold), then mid[r+1], mid[r+3], mid[r+4].
  const auto slots = [](int r) { return std::array<int, 4>{r, (r + 1) % kN, (r + 3) % kN, (r + 4) % kN}; };
  int runs = 0;
  rt.run([&](Engine& rt2) {
    for (int i = 0; i < kN; ++i)
      rt2.read(sel[i], [&, i](Engine& rt3, int s) {
        if (s) rt3.read(in[i], [&, i](Engine& rt4, int v) { rt4.write(mid[i], v); });
      });
    for (int r = 0; r < kReads; ++r) {
      const auto s = slots(r);
      rt2.read_many({&mid[s[0]], &mid[s[1]], &mid[s[2]], &mid[s[3]]}, BelowThreshold{&outs[r], &runs});
    }
    rt2.read_many({&outs[0], &outs[1], &outs[2], &outs[3]}, [&total](Engine& rt3, Vals v) {
      int t = 0;
      for (const int* p : v) t = t * 10 + *p;
      rt3.write(total, t);
    });
  });
  const auto expected = [&] {
    std::array<int, kN> m{};
    for (int i = 0; i < kN; ++i) m[i] = vsel[i] ? vin[i] : vmid[i];
    int t = 0;
    for (int r = 0; r < kReads; ++r) {
      const auto s = slots(r);
      int below = 0;
      for (int k = 1; k < 4; ++k) below += m[s[k]] < m[s[0]];
      t = t * 10 + below;
    }
    return t;
  };
  ASSERT_EQ(total.get(), expected());
  const auto effective = [&] {
    std::array<int, kN> m{};
    for (int k = 0; k < kN; ++k) m[k] = vsel[k] ? vin[k] : vmid[k];
    return m;
  };
  int cut = 0;  // changes of a value the projected reads see that re-ran none of them
  for (int t = 0; t < 400; ++t) {
    const int i = static_cast<int>(rng() % kN);
    const int runs_before = runs;
    const auto m_before = effective();
    switch (rng() % 3) {
      case 0: rt.set(in[i], vin[i] = static_cast<int>(rng() % 20)); break;
      case 1: rt.set(sel[i], vsel[i] = 1 - vsel[i]); break;
      default: rt.set(mid[i], vmid[i] = static_cast<int>(rng() % 20)); break;
    }
    rt.propagate();
    ASSERT_EQ(total.get(), expected()) << "change " << t;
    rt.check_invariants();
    cut += effective() != m_before && runs == runs_before;  // every mid[] is some read's slot
  }
  // The projections cut re-runs off: changes on the same side of every threshold.
  std::printf("%d of 400 changes of a value read were cut off by the projections\n", cut);
  EXPECT_GT(cut, 0);
}

TEST(ReadMany, AReexecutedWriteMovesTheReadsBeforeItsOldVersion) {
  // A read of sel writes m in its body, between reads of m: on a change it re-runs and
  // writes m again just before its old write, so the readers to move onto the new version
  // are those of the old body before the old write (Engine::link_write finds them by
  // walking that stretch when it is short and names no plain read of m's type, and by
  // scanning the older version's readers otherwise). Twenty multi-reads of m before the
  // re-run read and ten after it make the older version's reader list long; some bodies
  // add a plain read of m before the write (the scan) or a long stretch of trace (likewise).
  // Outputs must equal the expected ones after every change, with check_invariants().
  constexpr int kBefore = 20, kAfter = 10;
  Mod<int> sel, m, a, o1, o2, o3;
  std::array<Mod<int>, kBefore> early;
  std::array<Mod<int>, kAfter> late;
  std::array<Mod<int>, 80> pad;
  int vsel = 3, vm = 1, va = 2;
  std::mt19937 rng(20261128);
  std::printf("seed 20261128\n");
  Engine rt;
  rt.set(sel, vsel);
  rt.set(m, vm);
  rt.set(a, va);
  rt.run([&](Engine& rt2) {
    for (auto& o : early) rt2.read_many({&m, &a}, [&o](Engine& rt3, Vals v) { rt3.write(o, sum(v)); });
    rt2.read(sel, [&](Engine& rt3, int s) {
      rt3.read_many({&a, &m}, [&o1](Engine& rt4, Vals v) { rt4.write(o1, sum(v)); });
      if (s % 4 == 1) rt3.read(m, [&o3](Engine& rt4, int z) { rt4.write(o3, z); });
      if (s % 4 == 2)
        for (auto& p : pad) rt3.write(p, s);
      rt3.write(m, s);
      rt3.read_many({&m, &a}, [&o2](Engine& rt4, Vals v) { rt4.write(o2, sum(v)); });
    });
    for (auto& o : late) rt2.read_many({&a, &m}, [&o](Engine& rt3, Vals v) { rt3.write(o, sum(v)); });
  });
  for (int t = 0; t < 300; ++t) {
    switch (rng() % 3) {
      case 0: rt.set(sel, vsel = static_cast<int>(rng() % 9)); break;
      case 1: rt.set(m, vm = static_cast<int>(rng() % 9)); break;
      default: rt.set(a, va = static_cast<int>(rng() % 9)); break;
    }
    rt.propagate();
    for (auto& o : early) ASSERT_EQ(o.get(), vm * 10 + va) << "change " << t;
    ASSERT_EQ(o1.get(), va * 10 + vm) << "change " << t;
    if (vsel % 4 == 1) {
      ASSERT_EQ(o3.get(), vm) << "change " << t;
    }
    ASSERT_EQ(o2.get(), vsel * 10 + va) << "change " << t;
    for (auto& o : late) ASSERT_EQ(o.get(), va * 10 + vsel) << "change " << t;
    rt.check_invariants();
  }
}

// --- affected when propagation reaches it, and reads that follow -----------------------------

// A read of m's value as it is (a projection that is all of it).
struct WholeValue {
  Mod<int>* out;
  int* runs;
  void operator()(Engine& rt, Vals v) const {
    ++*runs;
    rt.write(*out, *v[0]);
  }
  bool affected(std::size_t, const int& before, const int& after) const { return before != after; }
};

TEST(ReadManyLazy, AChangeUndoneBeforePropagationReachesAReadDoesNotRerunIt) {
  // A writes m = 7 when sel is 0, B (later) when sel is 1, and R (later still) reads m. Going
  // from 0 to 1 undoes A's write (R sees m's base value for a while) and B writes 7 again
  // before R's time: when propagation reaches R, a read of a projection, it sees what it
  // saw, so it does not re-run. A plain read re-runs (its change was noted, not checked
  // again: a record per change would cost plain reads more than it saves).
  for (const bool projection : {true, false}) {
    Mod<int> sel, m, out;
    Engine rt;
    rt.set(sel, 0);
    rt.set(m, 0);
    int runs = 0;
    rt.run([&](Engine& rt2) {
      rt2.read(sel, [&m](Engine& rt3, int s) {
        if (s == 0) rt3.write(m, 7);
      });
      rt2.read(sel, [&m](Engine& rt3, int s) {
        if (s == 1) rt3.write(m, 7);
      });
      if (projection)
        rt2.read_many({&m}, WholeValue{&out, &runs});
      else
        rt2.read(m, [&](Engine& rt3, int v) {
          ++runs;
          rt3.write(out, v);
        });
    });
    ASSERT_EQ(out.get(), 7);
    ASSERT_EQ(runs, 1);
    rt.set(sel, 1);
    rt.propagate();
    EXPECT_EQ(out.get(), 7);
    EXPECT_EQ(runs, projection ? 1 : 2);
    EXPECT_EQ(rt.stats().reads_unaffected, projection ? 1u : 0u);
    rt.check_invariants();
    // Neither writes: R sees the base value and re-runs.
    rt.set(sel, 2);
    rt.propagate();
    EXPECT_EQ(out.get(), 0);
    EXPECT_EQ(runs, projection ? 2 : 3);
    rt.check_invariants();
    // A set() of the base value and back, before propagating: R saw 0, sees 0.
    rt.set(m, 5);
    rt.set(m, 0);
    rt.propagate();
    EXPECT_EQ(out.get(), 0);
    EXPECT_EQ(runs, projection ? 2 : 4);
    rt.check_invariants();
  }
}

// Sums its slots' values; a slot whose modifiable changes may move to the first modifiable
// of `pool` that holds, at the read's time, the value it saw: the sum stays what it was.
struct FollowingSum {
  Mod<int>* out;
  int* runs;
  std::span<Mod<int>> pool;
  std::array<int, 4>* names;  // which pool member slot i reads: follow() keeps it (test-owned)
  void operator()(Engine& rt, Vals v) const {
    ++*runs;
    rt.write(*out, sum(v));
  }
  bool affected(std::size_t, const int& before, const int& after) const { return before != after; }
  const Mod<int>* follow(std::size_t i, const int& seen, const int&, const Engine::At& at) const {
    for (std::size_t j = 0; j < pool.size(); ++j)
      if (const int* v = at.value(pool[j]); v && *v == seen) {
        (*names)[i] = static_cast<int>(j);
        return &pool[j];
      }
    return nullptr;
  }
};

// The follow tests' start: a pool of 1, 2, 1 (pool[2] holds what pool[0] does), and an output.
struct FollowPool {
  Mod<int> out;
  std::array<Mod<int>, 3> pool;
  Engine rt;  // after the modifiables: it goes first
  FollowPool() {
    rt.set(pool[0], 1);
    rt.set(pool[1], 2);
    rt.set(pool[2], 1);
  }
};

TEST(ReadManyFollow, AReadMovesToAModifiableThatHoldsWhatItSaw) {
  FollowPool p;
  Mod<int>& out = p.out;
  std::array<Mod<int>, 3>& pool = p.pool;
  Engine& rt = p.rt;
  int runs = 0;
  std::array<int, 4> names{0, 1, 0, 0};
  rt.run([&](Engine& rt2) { rt2.read_many({&pool[0], &pool[1]}, FollowingSum{&out, &runs, pool, &names}); });
  ASSERT_EQ(out.get(), 12);
  // pool[0] becomes 5: slot 0 saw 1, which pool[2] holds: it reads pool[2], no re-run.
  rt.set(pool[0], 5);
  rt.propagate();
  EXPECT_EQ(runs, 1);
  EXPECT_EQ(out.get(), 12);
  EXPECT_EQ(rt.stats().reads_followed, 1u);
  EXPECT_EQ(names[0], 2);
  rt.check_invariants();
  // pool[0] is no longer read ...
  rt.set(pool[0], 6);
  rt.propagate();
  EXPECT_EQ(runs, 1);
  EXPECT_EQ(out.get(), 12);
  // ... pool[2] is: 3 is held by no pool member (follow() says null), so it re-runs.
  rt.set(pool[2], 3);
  rt.propagate();
  EXPECT_EQ(runs, 2);
  EXPECT_EQ(out.get(), 32);
  rt.check_invariants();
}

// FollowingSum whose body takes its modifiables (ReadSlots) and keeps them, rather than
// holding copies: the view shows what each slot reads, a followed slot's new modifiable too.
struct SlotsSum {
  Mod<int>* out;
  std::span<Mod<int>> pool;
  std::vector<const Mod<int>*>* seen;  // what the body's slots named, its last run (test-owned)
  const Mod<int>** moved_from;         // the kept view's slot, asked in follow() (test-owned)
  mutable ReadSlots<int> kept;
  void operator()(Engine& rt, Vals v, ReadSlots<int> slots) const {
    kept = slots;
    seen->clear();
    for (std::size_t i = 0; i < v.size(); ++i) seen->push_back(&slots[i]);
    rt.write(*out, sum(v));
  }
  bool affected(std::size_t, const int& before, const int& after) const { return before != after; }
  const Mod<int>* follow(std::size_t i, const int& seen_value, const int&, const Engine::At& at) const {
    *moved_from = &kept[i];
    for (Mod<int>& m : pool)
      if (const int* v = at.value(m); v && *v == seen_value) return &m;
    return nullptr;
  }
};

TEST(ReadManySlots, TheBodySeesItsModifiablesAndAFollowedSlotsNewOne) {
  FollowPool p;
  Mod<int>& out = p.out;
  std::array<Mod<int>, 3>& pool = p.pool;
  Engine& rt = p.rt;
  std::vector<const Mod<int>*> seen;
  const Mod<int>* moved_from = nullptr;
  rt.run([&](Engine& rt2) {
    rt2.read_many({&pool[0], &pool[1]}, SlotsSum{&out, std::span<Mod<int>>(pool).last(1), &seen, &moved_from, {}});
  });
  EXPECT_EQ(seen, (std::vector<const Mod<int>*>{&pool[0], &pool[1]}));
  // pool[0] becomes 5: slot 0, as the kept view names it, moves to pool[2], which holds 1.
  rt.set(pool[0], 5);
  rt.propagate();
  EXPECT_EQ(moved_from, &pool[0]);
  EXPECT_EQ(rt.stats().reads_followed, 1u);
  // pool[2] becomes 7: the read re-runs, and its slots name pool[2] and pool[1].
  rt.set(pool[2], 7);
  rt.propagate();
  EXPECT_EQ(moved_from, &pool[2]);  // asked first: 7 is held by no member
  EXPECT_EQ(seen, (std::vector<const Mod<int>*>{&pool[2], &pool[1]}));
  EXPECT_EQ(out.get(), 72);  // sum() writes the values as digits
  rt.check_invariants();
}

TEST(ReadManyFollow, MatchesTheValuesOfTheModifiablesItNamesAfterEveryChange) {
  // mid[i] is in[i] when sel[i] is set (a version written before the reads, made, replaced
  // and undone by the changes), else its base value; four following sums read four of mid
  // each and may move to any mid[j] holding what they saw, at their time. After every
  // propagate(), each sum must be that of the values its closure names.
  constexpr int kN = 8, kReads = 4;
  std::array<Mod<int>, kN> in, mid, sel;
  std::array<Mod<int>, kReads> outs;
  std::array<int, kN> vin{}, vsel{}, vmid{};
  std::mt19937 rng(20261129);
  std::printf("seed 20261129\n");
  Engine rt;
  for (int i = 0; i < kN; ++i) {
    vin[i] = static_cast<int>(rng() % 6);
    vsel[i] = static_cast<int>(rng() % 2);
    vmid[i] = static_cast<int>(rng() % 6);
    rt.set(in[i], vin[i]);
    rt.set(sel[i], vsel[i]);
    rt.set(mid[i], vmid[i]);
  }
  int runs = 0;
  std::array<std::array<int, 4>, kReads> names{};
  rt.run([&](Engine& rt2) {
    for (int i = 0; i < kN; ++i)
      rt2.read(sel[i], [&, i](Engine& rt3, int s) {
        if (s) rt3.read(in[i], [&, i](Engine& rt4, int v) { rt4.write(mid[i], v); });
      });
    for (int r = 0; r < kReads; ++r) {
      names[r] = {r, (r + 1) % kN, (r + 3) % kN, (r + 5) % kN};
      const auto& s = names[r];
      rt2.read_many({&mid[s[0]], &mid[s[1]], &mid[s[2]], &mid[s[3]]},
                   FollowingSum{&outs[r], &runs, std::span<Mod<int>>(mid), &names[r]});
    }
  });
  const auto check = [&](int t) {
    std::array<int, kN> m{};
    for (int k = 0; k < kN; ++k) m[k] = vsel[k] ? vin[k] : vmid[k];
    for (int r = 0; r < kReads; ++r) {
      int want = 0;
      for (int i = 0; i < 4; ++i) want = want * 10 + m[names[r][i]];
      ASSERT_EQ(outs[r].get(), want) << "change " << t << " read " << r;
    }
  };
  check(-1);
  for (int t = 0; t < 400; ++t) {
    const int i = static_cast<int>(rng() % kN);
    switch (rng() % 3) {
      case 0: rt.set(in[i], vin[i] = static_cast<int>(rng() % 6)); break;
      case 1: rt.set(sel[i], vsel[i] = 1 - vsel[i]); break;
      default: rt.set(mid[i], vmid[i] = static_cast<int>(rng() % 6)); break;
    }
    rt.propagate();
    check(t);
    rt.check_invariants();
  }
  std::printf("%llu slots followed, %d runs\n", static_cast<unsigned long long>(rt.stats().reads_followed), runs);
  EXPECT_GT(rt.stats().reads_followed, 0u);
}
