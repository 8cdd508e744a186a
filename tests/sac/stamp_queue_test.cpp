// Tests of sac/detail/stamp_queue.hpp: StampQueue against a std::multiset ordered by reference
// position.
//
// The elements own stamps linked in an OrderList; the reference order is a std::list of ids
// (ranks recomputed whenever the list changed). Random push/pop/remove must keep top() equal
// to the reference minimum and check_invariants() valid after every operation, also when
// heavy clustered inserts relabel the order list under the queued elements.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <deque>
#include <iterator>
#include <list>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "sac/detail/order_list.hpp"
#include "sac/detail/stamp_queue.hpp"
#include "sac/errors.hpp"

#if defined(__SANITIZE_ADDRESS__)
#define SAC_SQ_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SAC_SQ_TEST_SANITIZED 1
#endif
#endif
#ifndef SAC_SQ_TEST_SANITIZED
#define SAC_SQ_TEST_SANITIZED 0
#endif

namespace {

using sac::detail::OrderList;
using sac::detail::Stamp;
using sac::detail::StampKind;

constexpr int kScale = SAC_SQ_TEST_SANITIZED ? 4 : 1;

struct Elem {
  Stamp stamp;
  std::uint32_t qpos = sac::detail::kNotQueued;
  int id = 0;
};

struct ElemTraits {
  static const Stamp* stamp(const Elem* e) { return &e->stamp; }
  static std::uint32_t pos(const Elem* e) { return e->qpos; }
  static void set_pos(Elem* e, std::uint32_t p) { e->qpos = p; }
};

using Queue = sac::detail::StampQueue<Elem, ElemTraits>;

/// Elements, their order list and the reference order.
class World {
 public:
  OrderList ol;
  std::deque<Elem> elems;  // stable addresses
  std::list<int> ref;
  std::vector<std::list<int>::iterator> where;
  std::vector<int> rank;   // valid after ranks()

  int add_after(int pos) {  // pos -1 = base
    elems.emplace_back();
    Elem& e = elems.back();
    e.id = static_cast<int>(elems.size()) - 1;
    ol.insert_after(pos < 0 ? ol.base() : &elems[static_cast<std::size_t>(pos)].stamp, &e.stamp,
                    StampKind::User);
    auto it = pos < 0 ? ref.begin() : std::next(where[static_cast<std::size_t>(pos)]);
    where.push_back(ref.insert(it, e.id));
    dirty_ = true;
    return e.id;
  }

  const std::vector<int>& ranks() {
    if (dirty_) {
      rank.assign(elems.size(), -1);
      int k = 0;
      for (int id : ref) rank[static_cast<std::size_t>(id)] = k++;
      dirty_ = false;
    }
    return rank;
  }

  Elem* elem(int id) { return &elems[static_cast<std::size_t>(id)]; }

 private:
  bool dirty_ = true;
};

/// Orders element pointers by their reference rank. The ranks of existing elements keep
/// their relative order when the list grows, so the multiset stays valid.
struct ByRank {
  World* w;
  bool operator()(const Elem* a, const Elem* b) const {
    const std::vector<int>& r = w->ranks();
    return r[static_cast<std::size_t>(a->id)] < r[static_cast<std::size_t>(b->id)];
  }
};

void run_random(std::uint64_t seed, int n_elems, int ops, bool relabel_heavy) {
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937_64 rng(seed);
  World w;
  int last = -1;
  for (int i = 0; i < n_elems; ++i)
    last = w.add_after(rng() % 3 == 0 && i > 0 ? static_cast<int>(rng() % static_cast<std::uint64_t>(i)) : last);
  Queue q(w.ol);
  std::multiset<Elem*, ByRank> model(ByRank{&w});
  ASSERT_TRUE(q.empty());
  ASSERT_NO_THROW(q.check_invariants());
  for (int op = 0; op < ops; ++op) {
    const int r = static_cast<int>(rng() % 100);
    if (r < 45) {
      // Push a random element not yet queued.
      Elem* e = w.elem(static_cast<int>(rng() % w.elems.size()));
      if (!q.contains(e)) {
        q.push(e);
        model.insert(e);
      }
    } else if (r < 70) {
      if (!model.empty()) {
        Elem* expect = *model.begin();
        ASSERT_EQ(q.top(), expect);
        Elem* got = q.pop();
        ASSERT_EQ(got, expect);
        ASSERT_FALSE(q.contains(got));
        ASSERT_EQ(got->qpos, sac::detail::kNotQueued);
        model.erase(model.begin());
      }
    } else if (r < 90) {
      if (!model.empty()) {
        // Remove a random queued element (any heap position).
        auto it = model.begin();
        std::advance(it, static_cast<std::ptrdiff_t>(rng() % model.size()));
        Elem* e = *it;
        ASSERT_TRUE(q.contains(e));
        q.remove(e);
        ASSERT_FALSE(q.contains(e));
        model.erase(it);
      }
    } else {
      // New stamps in the order list, possibly between queued elements: relabels must not
      // change the queue's order.
      const int count = relabel_heavy ? 300 : 20;
      const int spot = static_cast<int>(rng() % w.elems.size());
      if (rng() % 2) {
        for (int k = 0; k < count; ++k) w.add_after(spot);  // clustered: group splits
      } else {
        int p = spot;
        for (int k = 0; k < count; ++k) p = w.add_after(p);
      }
    }
    ASSERT_EQ(q.size(), model.size());
    ASSERT_EQ(q.empty(), model.empty());
    if (!model.empty()) {
      ASSERT_EQ(q.top(), *model.begin());
    }
    ASSERT_NO_THROW(q.check_invariants()) << "op " << op;
  }
  ASSERT_NO_THROW(w.ol.check_invariants());
  if (relabel_heavy) {
    EXPECT_GT(w.ol.top_relabels(), 0u);
  }
  // Drain: pops come out in reference order.
  while (!model.empty()) {
    ASSERT_EQ(q.pop(), *model.begin());
    model.erase(model.begin());
    ASSERT_NO_THROW(q.check_invariants());
  }
  EXPECT_TRUE(q.empty());
}

TEST(StampQueue, RandomPushPopRemoveAgainstMultiset) {
  for (std::uint64_t seed : {101u, 102u, 103u}) run_random(seed, 400, 8000 / kScale, false);
}

TEST(StampQueue, OrderSurvivesRelabelHeavyInserts) {
  for (std::uint64_t seed : {201u, 202u}) run_random(seed, 200, 4000 / kScale, true);
}

TEST(StampQueue, PushAllThenPopAllIsSorted) {
  std::mt19937_64 rng(7);
  World w;
  int last = -1;
  for (int i = 0; i < 3000; ++i)
    last = w.add_after(rng() % 2 == 0 && i > 0 ? static_cast<int>(rng() % static_cast<std::uint64_t>(i)) : last);
  std::vector<int> ids(w.elems.size());
  for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<int>(i);
  std::shuffle(ids.begin(), ids.end(), rng);
  Queue q(w.ol);
  for (int id : ids) q.push(w.elem(id));
  ASSERT_NO_THROW(q.check_invariants());
  const std::vector<int>& rank = w.ranks();
  int prev = -1;
  while (!q.empty()) {
    Elem* e = q.pop();
    ASSERT_GT(rank[static_cast<std::size_t>(e->id)], prev);
    prev = rank[static_cast<std::size_t>(e->id)];
  }
  EXPECT_EQ(prev, static_cast<int>(ids.size()) - 1);
}

TEST(StampQueue, RemoveTheOnlyAndTheLastElement) {
  World w;
  int a = w.add_after(-1);
  int b = w.add_after(a);
  Queue q(w.ol);
  q.push(w.elem(a));
  q.remove(w.elem(a));
  EXPECT_TRUE(q.empty());
  EXPECT_FALSE(q.contains(w.elem(a)));
  q.push(w.elem(b));
  q.push(w.elem(a));
  EXPECT_EQ(q.top(), w.elem(a));
  q.remove(w.elem(b));  // the last heap slot
  EXPECT_EQ(q.size(), 1u);
  EXPECT_EQ(q.top(), w.elem(a));
  EXPECT_NO_THROW(q.check_invariants());
}

// An element's Aux value travels with it through sifts and removals of others.
TEST(StampQueue, AuxValuesStayWithTheirElements) {
  World w;
  std::mt19937_64 rng(11);
  std::vector<int> ids;
  for (int i = 0; i < 300; ++i) ids.push_back(w.add_after(ids.empty() ? -1 : ids[rng() % ids.size()]));
  const std::vector<int> rank = w.ranks();
  sac::detail::StampQueue<Elem, ElemTraits, long> q(w.ol);
  std::shuffle(ids.begin(), ids.end(), rng);
  for (int id : ids) q.push(w.elem(id), 1000L + id);
  for (std::size_t i = 0; i < ids.size(); i += 3) q.remove(w.elem(ids[i]));
  ASSERT_NO_THROW(q.check_invariants());
  int prev = -1;
  while (!q.empty()) {
    long aux = 0;
    Elem* e = q.pop(&aux);
    ASSERT_EQ(aux, 1000L + e->id);
    ASSERT_GT(rank[static_cast<std::size_t>(e->id)], prev);
    prev = rank[static_cast<std::size_t>(e->id)];
  }
}

TEST(StampQueue, CheckInvariantsDetectsCorruption) {
  World w;
  int last = -1;
  for (int i = 0; i < 16; ++i) last = w.add_after(last);
  Queue q(w.ol);
  for (int i = 15; i >= 0; --i) q.push(w.elem(i));
  ASSERT_NO_THROW(q.check_invariants());
  // A stored heap index that lies.
  Elem* top = q.top();
  top->qpos = 3;
  EXPECT_THROW(q.check_invariants(), sac::InvariantError);
  top->qpos = 0;
  ASSERT_NO_THROW(q.check_invariants());
  // A queued element whose stamp left the order list.
  Elem* e = w.elem(9);
  w.ol.erase(&e->stamp);
  EXPECT_THROW(q.check_invariants(), sac::InvariantError);
  q.remove(e);
  EXPECT_NO_THROW(q.check_invariants());
  // Heap order broken by moving a stamp: erase the top's stamp and re-link it at the end.
  Elem* t = q.top();
  ASSERT_EQ(t, w.elem(0));
  w.ol.erase(&t->stamp);
  w.ol.insert_after(&w.elem(15)->stamp, &t->stamp, StampKind::User);
  EXPECT_THROW(q.check_invariants(), sac::InvariantError);
  w.ol.erase(&t->stamp);
  w.ol.insert_after(w.ol.base(), &t->stamp, StampKind::User);
  EXPECT_NO_THROW(q.check_invariants());
}

}  // namespace
