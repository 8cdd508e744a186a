// Tests of sac/detail/order_list.hpp: OrderList against a reference std::list of ids.
//
// Every operation is mirrored on a std::list<int>; after each batch the order list must hold
// exactly the reference sequence (walking next() from base()), less() must agree with the
// reference positions, and check_invariants() must pass. Inserts are spread at random, heavily
// clustered at one spot (group splits, group relabels and top-level relabels) and appended in
// long runs; erase and erase_between remove single stamps and whole intervals. Corrupted
// labels, links and groups (the groups through the test-only OrderListTestAccess) must fail
// check_invariants().
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <deque>
#include <iterator>
#include <list>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include "sac/detail/order_list.hpp"
#include "sac/errors.hpp"

namespace sac::detail {

/// The test-only hook declared in OrderList: the private groups, so that the checker tests
/// below can corrupt one of them and see check_invariants() fail.
struct OrderListTestAccess {
  static std::uint32_t& count(OrderList& ol, std::uint32_t group) { return ol.groups_[group].count; }
  static std::uint64_t& label(OrderList& ol, std::uint32_t group) { return ol.groups_[group].label; }
  static std::size_t& group_count(OrderList& ol) { return ol.group_count_; }
};

}  // namespace sac::detail

#if defined(__SANITIZE_ADDRESS__)
#define SAC_OL_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SAC_OL_TEST_SANITIZED 1
#endif
#endif
#ifndef SAC_OL_TEST_SANITIZED
#define SAC_OL_TEST_SANITIZED 0
#endif

namespace {

using sac::detail::OrderList;
using sac::detail::Stamp;
using sac::detail::StampKind;

constexpr int kScale = SAC_OL_TEST_SANITIZED ? 4 : 1;  // divide loop sizes under ASan

/// An OrderList together with its reference model. Stamp id i lives in stamps[i]; id -1 is
/// the base stamp. A std::deque never moves its elements, so stamp addresses stay valid.
class Model {
 public:
  OrderList ol;
  std::deque<Stamp> stamps;
  std::list<int> ref;                                   // ids in order (base excluded)
  std::vector<std::list<int>::iterator> where;          // id -> position in ref (valid if linked)
  std::vector<bool> linked;

  Stamp* stamp(int id) { return id < 0 ? ol.base() : &stamps[static_cast<std::size_t>(id)]; }

  int new_id() {
    stamps.emplace_back();
    where.emplace_back();
    linked.push_back(false);
    live_idx_.push_back(0);
    return static_cast<int>(stamps.size()) - 1;
  }

  /// Inserts stamp `id` (unlinked) after `pos` (-1 = base).
  void insert_after(int pos, int id) {
    ol.insert_after(stamp(pos), stamp(id), StampKind::User);
    auto it = pos < 0 ? ref.begin() : std::next(where[static_cast<std::size_t>(pos)]);
    where[static_cast<std::size_t>(id)] = ref.insert(it, id);
    mark_linked(id);
    ids_dirty_ = true;
  }
  int insert_new_after(int pos) {
    int id = new_id();
    insert_after(pos, id);
    return id;
  }

  void erase(int id) {
    ol.erase(stamp(id));
    forget(id);
  }
  /// Erase with a hint stamp `hint` (-1 = base) that may or may not lie shortly before id.
  void erase_with_hint(int id, int hint) {
    ol.erase(stamp(id), stamp(hint));
    forget(id);
  }

  /// Removes id from the reference after the order list erased it.
  void forget(int id) {
    ref.erase(where[static_cast<std::size_t>(id)]);
    const std::size_t i = live_idx_[static_cast<std::size_t>(id)];
    live_[i] = live_.back();
    live_idx_[static_cast<std::size_t>(live_[i])] = i;
    live_.pop_back();
    linked[static_cast<std::size_t>(id)] = false;
    ids_dirty_ = true;
  }

  /// A uniformly random linked id, or -1 (base) with probability about 1/(size+1).
  int random_pos(std::mt19937_64& rng) {
    std::uniform_int_distribution<std::size_t> d(0, live_.size());
    std::size_t k = d(rng);
    return k == live_.size() ? -1 : live_[k];
  }

  const std::vector<int>& ids() {
    if (ids_dirty_) {
      ids_cache_.assign(ref.begin(), ref.end());
      ids_dirty_ = false;
    }
    return ids_cache_;
  }
  void touch() { ids_dirty_ = true; }

  /// The full consistency check: sequence, size, kinds, labels vs reference, invariants.
  void verify(std::mt19937_64& rng, int pairs = 2000) {
    touch();
    ASSERT_NO_THROW(ol.check_invariants());
    ASSERT_EQ(ol.size(), ref.size());
    // Walk the list from the base: exactly the reference sequence.
    std::unordered_map<const Stamp*, int> id_of;
    for (std::size_t i = 0; i < stamps.size(); ++i) id_of[&stamps[i]] = static_cast<int>(i);
    const Stamp* x = ol.base()->next();
    std::size_t k = 0;
    std::vector<int> rank(stamps.size(), -1);
    for (int id : ref) {
      ASSERT_NE(x, nullptr) << "order list shorter than the reference at " << k;
      ASSERT_EQ(x, stamp(id)) << "order list differs from the reference at position " << k;
      ASSERT_TRUE(x->linked());
      ASSERT_EQ(x->kind(), StampKind::User);
      rank[static_cast<std::size_t>(id)] = static_cast<int>(k);
      x = x->next();
      ++k;
    }
    ASSERT_EQ(x, nullptr) << "order list longer than the reference";
    // Consecutive stamps are strictly increasing; the base precedes everything.
    const Stamp* prev = ol.base();
    for (int id : ref) {
      ASSERT_TRUE(ol.less(prev, stamp(id)));
      ASSERT_FALSE(ol.less(stamp(id), prev));
      prev = stamp(id);
    }
    // Random pairs agree with the reference ranks.
    const std::vector<int>& v = ids();
    if (v.empty()) return;
    std::uniform_int_distribution<std::size_t> d(0, v.size() - 1);
    for (int i = 0; i < pairs; ++i) {
      int a = v[d(rng)], b = v[d(rng)];
      bool expect = rank[static_cast<std::size_t>(a)] < rank[static_cast<std::size_t>(b)];
      ASSERT_EQ(ol.less(stamp(a), stamp(b)), expect) << "ids " << a << " " << b;
    }
    // Unlinked stamps say so.
    for (std::size_t i = 0; i < stamps.size(); ++i)
      ASSERT_EQ(stamps[i].linked(), static_cast<bool>(linked[i])) << "id " << i;
  }

 private:
  void mark_linked(int id) {
    live_idx_[static_cast<std::size_t>(id)] = live_.size();
    live_.push_back(id);
    linked[static_cast<std::size_t>(id)] = true;
  }

  std::vector<int> live_;             // linked ids, unordered (for random choice)
  std::vector<std::size_t> live_idx_; // id -> index in live_
  std::vector<int> ids_cache_;
  bool ids_dirty_ = true;
};

TEST(OrderList, EmptyListHoldsOnlyTheBase) {
  OrderList ol;
  EXPECT_EQ(ol.size(), 0u);
  EXPECT_EQ(ol.group_count(), 1u);
  EXPECT_EQ(ol.base()->next(), nullptr);
  EXPECT_TRUE(ol.base()->linked());
  EXPECT_EQ(ol.base()->kind(), StampKind::Sentinel);
  EXPECT_FALSE(ol.less(ol.base(), ol.base()));
  EXPECT_NO_THROW(ol.check_invariants());
  EXPECT_THROW(ol.erase(ol.base()), sac::UsageError);
  EXPECT_NO_THROW(ol.check_invariants());
}

TEST(OrderList, KindsAreKeptInTheLink) {
  OrderList ol;
  std::deque<Stamp> s(8);
  Stamp* pos = ol.base();
  for (int k = 0; k < 8; ++k) {
    ol.insert_after(pos, &s[static_cast<std::size_t>(k)], static_cast<StampKind>(k));
    pos = &s[static_cast<std::size_t>(k)];
  }
  for (int k = 0; k < 8; ++k) EXPECT_EQ(s[static_cast<std::size_t>(k)].kind(), static_cast<StampKind>(k));
  // Relabelling/splitting must not disturb the kinds: force a lot of inserts in between.
  std::deque<Stamp> more(2000);
  for (auto& m : more) ol.insert_after(&s[3], &m, StampKind::User);
  for (int k = 0; k < 8; ++k) EXPECT_EQ(s[static_cast<std::size_t>(k)].kind(), static_cast<StampKind>(k));
  EXPECT_EQ(s[3].next(), &more.back());
  EXPECT_NO_THROW(ol.check_invariants());
}

TEST(OrderList, LongAppendRun) {
  std::mt19937_64 rng(1);
  Model m;
  int last = -1;
  const int n = 200000 / kScale;
  for (int i = 0; i < n; ++i) {
    last = m.insert_new_after(last);
    if (i % (50000 / kScale) == 0) {
      ASSERT_NO_FATAL_FAILURE(m.verify(rng));
    }
  }
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
  EXPECT_EQ(m.ol.size(), static_cast<std::size_t>(n));
  // Appends fill groups to kAppendFill, leaving room for later insertions.
  EXPECT_LE(m.ol.group_count(), static_cast<std::size_t>(n) / OrderList::kAppendFill + 2);
  EXPECT_GE(m.ol.group_count(), static_cast<std::size_t>(n) / OrderList::kAppendFill);
}

TEST(OrderList, ClusteredInsertsSplitGroupsAndRelabelTheTop) {
  std::mt19937_64 rng(2);
  Model m;
  // A backbone of appended stamps: groups with labels spaced by the top-level append step.
  int last = -1;
  std::vector<int> backbone;
  for (int i = 0; i < 5000; ++i) backbone.push_back(last = m.insert_new_after(last));
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
  const std::uint64_t relabels0 = m.ol.top_relabels();
  // Hammer one spot: always insert right after the same stamp (each new stamp goes before
  // the previous new one), so the gap between two group labels is halved over and over.
  const int spot = backbone[2500];
  const int n = 60000 / kScale;
  for (int i = 0; i < n; ++i) {
    m.insert_new_after(spot);
    if (i % (10000 / kScale) == 0) {
      ASSERT_NO_FATAL_FAILURE(m.verify(rng));
    }
  }
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
  EXPECT_GT(m.ol.top_relabels(), relabels0) << "clustered inserts should force top-level relabels";
  // And the other clustered pattern: always insert after the newest stamp at a spot
  // (a run of appends in the middle of the list).
  int cur = backbone[100];
  for (int i = 0; i < n; ++i) {
    cur = m.insert_new_after(cur);
    if (i % (10000 / kScale) == 0) {
      ASSERT_NO_FATAL_FAILURE(m.verify(rng));
    }
  }
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
  // Clustered at the base (the first group).
  for (int i = 0; i < n / 4; ++i) m.insert_new_after(-1);
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
}

TEST(OrderList, ClusteredInsertsInTheLastGroup) {
  // The last group has no successor group: new groups take labels after it; hammering the
  // end of the list between its last two stamps exercises that path.
  std::mt19937_64 rng(3);
  Model m;
  int a = m.insert_new_after(-1);
  m.insert_new_after(a);
  for (int i = 0; i < 30000 / kScale; ++i) m.insert_new_after(a);
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
}

TEST(OrderList, RandomInsertEraseAgainstReference) {
  for (std::uint64_t seed : {11u, 12u, 13u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    Model m;
    const int batches = 24 / kScale;
    for (int b = 0; b < batches; ++b) {
      // Modes: 0 inserts only; 1 with clustered bursts; 2 with append runs; 3 erase-heavy.
      const int mode = b % 4;
      for (int op = 0; op < 1500; ++op) {
        const int r = static_cast<int>(rng() % 100);
        if ((mode == 1 || mode == 2) && r < 3) {
          int pos = m.random_pos(rng);
          if (mode == 1)  // clustered burst: always right after the same stamp
            for (int k = 0; k < 150; ++k) m.insert_new_after(pos);
          else            // append run starting at a random spot
            for (int k = 0; k < 150; ++k) pos = m.insert_new_after(pos);
        } else if (r < (mode == 3 ? 35 : 60) || m.ref.empty()) {
          // Insert a new stamp, or re-link an erased one.
          int pos = m.random_pos(rng);
          int id = -1;
          if (rng() % 3 == 0) {
            for (int tries = 0; tries < 4 && id < 0; ++tries) {
              int c = static_cast<int>(rng() % (m.stamps.size() + 1)) - 1;
              if (c >= 0 && !m.linked[static_cast<std::size_t>(c)]) id = c;
            }
          }
          if (id < 0) id = m.new_id();
          m.insert_after(pos, id);
        } else {
          int id = m.random_pos(rng);
          if (id >= 0) m.erase(id);
        }
      }
      ASSERT_NO_FATAL_FAILURE(m.verify(rng));
    }
  }
}

TEST(OrderList, EraseSingleStampsEverywhere) {
  std::mt19937_64 rng(21);
  Model m;
  int last = -1;
  for (int i = 0; i < 3000; ++i) last = m.insert_new_after(last);
  // Erase first stamps of groups, last stamps, middles; in random order until empty.
  std::vector<int> order(m.ref.begin(), m.ref.end());
  std::shuffle(order.begin(), order.end(), rng);
  for (std::size_t i = 0; i < order.size(); ++i) {
    m.erase(order[i]);
    if (i % 250 == 0) {
      ASSERT_NO_FATAL_FAILURE(m.verify(rng, 200));
    }
  }
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
  EXPECT_EQ(m.ol.size(), 0u);
  EXPECT_EQ(m.ol.group_count(), 1u);
  // The emptied list is fully usable again (freed groups are recycled).
  last = -1;
  for (int i = 0; i < 3000; ++i) last = m.insert_new_after(rng() % 2 ? last : m.random_pos(rng));
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
}

TEST(OrderList, EraseWithHintsNearFarAfterOrNone) {
  // The hint only shortens the predecessor search: near hints (1-8 stamps before), far hints,
  // hints after the stamp and the base must all give the same list as a plain erase.
  std::mt19937_64 rng(22);
  Model m;
  int last = -1;
  for (int i = 0; i < 3000; ++i) last = m.insert_new_after(rng() % 3 ? last : m.random_pos(rng));
  for (int round = 0; round < 2500; ++round) {
    const std::vector<int>& ids = m.ids();
    const std::size_t k = rng() % ids.size();
    const int id = ids[k];
    int hint = -1;
    switch (rng() % 4) {
      case 0:  // near: up to 8 stamps before
        hint = k >= 1 + rng() % 8 ? ids[k - 1 - rng() % std::min<std::size_t>(k, 8)] : -1;
        break;
      case 1:  // far or anywhere
        hint = m.random_pos(rng);
        if (hint == id) hint = -1;
        break;
      case 2:  // right before
        hint = k > 0 ? ids[k - 1] : -1;
        break;
      default:  // base
        break;
    }
    m.erase_with_hint(id, hint);
    if (rng() % 2) m.insert_new_after(m.random_pos(rng));
    if (round % 250 == 0) {
      ASSERT_NO_FATAL_FAILURE(m.verify(rng, 200));
    }
  }
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
}

TEST(OrderList, EraseBetweenCallsBackWithTheErasedStampsInOrder) {
  for (std::uint64_t seed : {31u, 32u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    Model m;
    int last = -1;
    for (int i = 0; i < 4000; ++i)
      last = m.insert_new_after(rng() % 4 == 0 ? m.random_pos(rng) : last);
    ASSERT_NO_FATAL_FAILURE(m.verify(rng));
    for (int round = 0; round < 120 / kScale; ++round) {
      // Pick a < b in reference order (b may be "the end").
      const std::vector<int>& v = m.ids();
      if (v.size() < 2) break;
      std::size_t i = rng() % v.size();
      const int a_id = (rng() % 10 == 0) ? -1 : v[i];
      std::size_t first_erased = a_id < 0 ? 0 : i + 1;
      // Mostly short intervals (as in undo), sometimes long ones, sometimes to the end.
      std::size_t len;
      const int kind = static_cast<int>(rng() % 10);
      if (kind < 6) len = rng() % 8;
      else if (kind < 9) len = rng() % 600;
      else len = v.size();
      std::size_t end_idx = std::min(v.size(), first_erased + len);
      const int b_id = end_idx < v.size() ? v[end_idx] : -2;  // -2: nullptr (to the end)
      std::vector<int> expected(v.begin() + static_cast<std::ptrdiff_t>(first_erased),
                                v.begin() + static_cast<std::ptrdiff_t>(end_idx));
      std::vector<const Stamp*> seen;
      bool all_unlinked_when_seen = true;
      m.ol.erase_between(m.stamp(a_id), b_id == -2 ? nullptr : m.stamp(b_id), [&](Stamp* s) {
        if (s->linked()) all_unlinked_when_seen = false;
        seen.push_back(s);
      });
      ASSERT_EQ(seen.size(), expected.size());
      for (std::size_t k = 0; k < expected.size(); ++k)
        ASSERT_EQ(seen[k], m.stamp(expected[k])) << "callback order differs at " << k;
      EXPECT_TRUE(all_unlinked_when_seen) << "on_erase must see stamps already unlinked";
      for (int id : expected) m.forget(id);
      m.touch();
      ASSERT_NO_FATAL_FAILURE(m.verify(rng, 300));
      // Refill a bit, including re-linking some of the erased stamps.
      for (int k = 0; k < 40; ++k) {
        int pos = m.random_pos(rng);
        if (!expected.empty() && k < static_cast<int>(expected.size()) && k % 2 == 0)
          m.insert_after(pos, expected[static_cast<std::size_t>(k)]);
        else
          m.insert_new_after(pos);
      }
      ASSERT_NO_FATAL_FAILURE(m.verify(rng, 300));
    }
  }
}

TEST(OrderList, EraseBetweenAdjacentStampsIsANoOp) {
  std::mt19937_64 rng(41);
  Model m;
  int a = m.insert_new_after(-1);
  int b = m.insert_new_after(a);
  int calls = 0;
  m.ol.erase_between(m.stamp(a), m.stamp(b), [&](Stamp*) { ++calls; });
  EXPECT_EQ(calls, 0);
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
  // Everything after the base, then insert again.
  m.ol.erase_between(m.ol.base(), nullptr, [&](Stamp*) { ++calls; });
  EXPECT_EQ(calls, 2);
  m.forget(a);
  m.forget(b);
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
  EXPECT_EQ(m.ol.group_count(), 1u);
  m.insert_after(-1, b);
  m.insert_after(-1, a);
  ASSERT_NO_FATAL_FAILURE(m.verify(rng));
  EXPECT_TRUE(m.ol.less(m.stamp(a), m.stamp(b)));
}

TEST(OrderList, EraseBetweenWholeGroupsAfterClusteredInserts) {
  // Interval erases that span many groups created by splits, then more clustered inserts
  // into the gap they leave.
  std::mt19937_64 rng(51);
  Model m;
  int last = -1;
  std::vector<int> backbone;
  for (int i = 0; i < 300; ++i) backbone.push_back(last = m.insert_new_after(last));
  for (int rep = 0; rep < 20; ++rep) {
    const int spot = backbone[static_cast<std::size_t>(rng() % 150)];
    for (int k = 0; k < 1500 / kScale; ++k) m.insert_new_after(spot);
    m.touch();
    ASSERT_NO_FATAL_FAILURE(m.verify(rng, 300));
    // Erase everything that was inserted after the spot, up to the next backbone stamp.
    auto it = std::next(m.where[static_cast<std::size_t>(spot)]);
    std::vector<int> erased;
    const auto bb_end = std::find(backbone.begin(), backbone.end(), spot) + 1;
    const int stop = *bb_end;
    while (*it != stop) erased.push_back(*it++);
    std::size_t k = 0;
    bool ok = true;
    m.ol.erase_between(m.stamp(spot), m.stamp(stop), [&](Stamp* s) {
      if (k >= erased.size() || s != m.stamp(erased[k])) ok = false;
      ++k;
    });
    EXPECT_TRUE(ok);
    EXPECT_EQ(k, erased.size());
    for (int id : erased) m.forget(id);
    m.touch();
    ASSERT_NO_FATAL_FAILURE(m.verify(rng, 300));
  }
}

TEST(OrderList, CheckInvariantsDetectsACorruptedLabel) {
  Model m;
  int last = -1;
  for (int i = 0; i < 10; ++i) last = m.insert_new_after(last);
  ASSERT_NO_THROW(m.ol.check_invariants());
  // All ten are in the base's group; make stamp 5's label not greater than stamp 4's.
  Stamp* s4 = m.stamp(4);
  Stamp* s5 = m.stamp(5);
  ASSERT_EQ(s4->group, s5->group);
  const std::uint32_t saved = s5->label;
  s5->label = s4->label;
  EXPECT_THROW(m.ol.check_invariants(), sac::InvariantError);
  s5->label = s4->label - 1;
  EXPECT_THROW(m.ol.check_invariants(), sac::InvariantError);
  s5->label = saved;
  EXPECT_NO_THROW(m.ol.check_invariants());
}

TEST(OrderList, CheckInvariantsDetectsOtherCorruption) {
  Model m;
  int last = -1;
  for (int i = 0; i < 200; ++i) last = m.insert_new_after(last);  // several groups
  ASSERT_GE(m.ol.group_count(), 3u);
  ASSERT_NO_THROW(m.ol.check_invariants());
  // A stamp claiming the wrong group.
  Stamp* s = m.stamp(100);
  const std::uint32_t g = s->group;
  s->group = m.stamp(0)->group == g ? m.stamp(199)->group : m.stamp(0)->group;
  EXPECT_THROW(m.ol.check_invariants(), sac::InvariantError);
  s->group = g;
  ASSERT_NO_THROW(m.ol.check_invariants());
  // A link that skips a stamp (the list is shorter than size()).
  Stamp* a = m.stamp(150);
  Stamp* b = a->next();
  a->set_next(b->next());
  EXPECT_THROW(m.ol.check_invariants(), sac::InvariantError);
  a->set_next(b);
  EXPECT_NO_THROW(m.ol.check_invariants());
}

/// The message of the sac::InvariantError that ol.check_invariants() throws, or "" if none.
std::string invariant_message(const OrderList& ol) {
  try {
    ol.check_invariants();
  } catch (const sac::InvariantError& e) {
    return e.what();
  }
  return {};
}

using sac::detail::OrderListTestAccess;
using testing::HasSubstr;

TEST(OrderList, CheckInvariantsDetectsAWrongGroupCount) {
  Model m;
  int last = -1;
  for (int i = 0; i < 200; ++i) last = m.insert_new_after(last);  // several groups
  ASSERT_GE(m.ol.group_count(), 3u);
  ASSERT_NO_THROW(m.ol.check_invariants());
  const std::uint32_t g = m.stamp(100)->group;
  std::uint32_t& count = OrderListTestAccess::count(m.ol, g);
  ++count;
  EXPECT_THROW(m.ol.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(m.ol), HasSubstr("group count mismatch"));
  --count;
  EXPECT_NO_THROW(m.ol.check_invariants());
}

TEST(OrderList, CheckInvariantsDetectsAWrongNumberOfGroups) {
  Model m;
  int last = -1;
  for (int i = 0; i < 200; ++i) last = m.insert_new_after(last);
  ASSERT_NO_THROW(m.ol.check_invariants());
  ++OrderListTestAccess::group_count(m.ol);
  EXPECT_THROW(m.ol.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(m.ol), HasSubstr("group count total mismatch"));
  --OrderListTestAccess::group_count(m.ol);
  EXPECT_NO_THROW(m.ol.check_invariants());
}

TEST(OrderList, CheckInvariantsDetectsGroupLabelsOutOfOrder) {
  Model m;
  int last = -1;
  for (int i = 0; i < 200; ++i) last = m.insert_new_after(last);
  ASSERT_NO_THROW(m.ol.check_invariants());
  // The group of the last stamp gets the base group's label (0): not after its predecessor.
  const std::uint32_t g = m.stamp(199)->group;
  ASSERT_NE(g, m.ol.base()->group);
  std::uint64_t& label = OrderListTestAccess::label(m.ol, g);
  const std::uint64_t saved = label;
  label = OrderListTestAccess::label(m.ol, m.ol.base()->group);
  EXPECT_THROW(m.ol.check_invariants(), sac::InvariantError);
  EXPECT_THAT(invariant_message(m.ol), HasSubstr("group labels not increasing"));
  label = saved;
  EXPECT_NO_THROW(m.ol.check_invariants());
}

}  // namespace
