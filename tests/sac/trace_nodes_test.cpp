// Tests of sac/detail/trace_nodes.hpp: the numbers a dense record keeps in its links' spare
// bits (a stamp's aux, a reader link's tag and flags) survive everything done to the links,
// and the links survive the numbers.
//
// - Stamp::aux through the order list's inserts (into full groups: splits and relabels),
//   single erases and interval erases, against the next pointer and the kind.
// - A reader link's back link, unordered flag, slot flag and tag, set in every order, through
//   push_reader, detach and the default-reader head.
// - A read's queue position across its 16-bit halves (ReadNode::qpos), with the link attached.
// - An engine whose queue holds more than 2^16 reads at once, so that positions use both
//   halves: the outputs must equal a from-scratch run's, and check_invariants() must pass.
#include <gtest/gtest.h>

#include <cstdint>
#include <deque>
#include <memory>
#include <unordered_map>
#include <vector>

#include "sac/sac.hpp"

namespace {

using sac::detail::OrderList;
using sac::detail::ReaderLink;
using sac::detail::ReadNode;
using sac::detail::Stamp;
using sac::detail::StampKind;

std::uint16_t aux_of(std::size_t i) { return static_cast<std::uint16_t>(0x9e37u * (i + 1)); }

TEST(TraceNodes, StampAuxSurvivesTheOrderList) {
  OrderList ol;
  std::deque<Stamp> stamps(6000);
  for (std::size_t i = 0; i < stamps.size(); ++i) stamps[i].set_aux(aux_of(i));
  // All inserted right after the base: every group fills and splits, the top relabels.
  const StampKind kinds[] = {StampKind::ReadStart, StampKind::ReadEnd, StampKind::Write, StampKind::User};
  for (std::size_t i = 0; i < stamps.size(); ++i) ol.insert_after(ol.base(), &stamps[i], kinds[i % 4]);
  ASSERT_NO_THROW(ol.check_invariants());
  // The list is the reverse of the insertion order, each with its kind and aux.
  std::size_t i = stamps.size();
  for (const Stamp* s = ol.base()->next(); s; s = s->next()) {
    ASSERT_GT(i, 0u);
    --i;
    ASSERT_EQ(s, &stamps[i]);
    EXPECT_EQ(s->kind(), kinds[i % 4]);
    EXPECT_EQ(s->aux(), aux_of(i));
  }
  EXPECT_EQ(i, 0u);
  // set_aux leaves next and kind; set_next and set_kind leave aux.
  Stamp* s = ol.base()->next();
  Stamp* n = s->next();
  s->set_aux(0xffff);
  EXPECT_EQ(s->next(), n);
  EXPECT_EQ(s->kind(), kinds[(stamps.size() - 1) % 4]);
  s->set_aux(aux_of(stamps.size() - 1));
  // Erase every third stamp alone, then an interval, and check the others again.
  for (std::size_t j = 0; j < stamps.size(); j += 3) ol.erase(&stamps[j]);
  ol.erase_between(&stamps[3001], &stamps[1001], [](Stamp*) {});  // 3000 .. 1002 go
  ASSERT_NO_THROW(ol.check_invariants());
  std::unordered_map<const Stamp*, std::size_t> index;
  for (std::size_t j = 0; j < stamps.size(); ++j) index[&stamps[j]] = j;
  std::size_t left = 0;
  for (const Stamp* x = ol.base()->next(); x; x = x->next(), ++left) {
    const std::size_t j = index.at(x);
    EXPECT_NE(j % 3, 0u);
    EXPECT_FALSE(j > 1001 && j < 3001);
    EXPECT_EQ(x->aux(), aux_of(j));
  }
  EXPECT_EQ(left, ol.size());
  for (std::size_t j = 0; j < stamps.size(); ++j) EXPECT_EQ(stamps[j].aux(), aux_of(j)) << j;
}

TEST(TraceNodes, ReaderLinkFlagsAndTagSurviveTheList) {
  // Three links on one head: a plain read's (tag 0xbeef), a slot (tag 5) and a read on the
  // unordered list; detach the middle one and check what each keeps.
  ReaderLink* head = nullptr;
  ReaderLink a{}, b{}, c{};
  a.set_tag(0xbeef);
  b.back = ReaderLink::kSlotBit;
  b.set_tag(5);
  c.set_tag(0x0001);
  sac::detail::push_reader(&a, &head, false);
  sac::detail::push_reader(&b, &head, true);
  sac::detail::push_reader(&c, &head, false);
  EXPECT_EQ(head, &c);
  EXPECT_EQ(c.rnext, &b);
  EXPECT_EQ(b.rnext, &a);
  EXPECT_EQ(a.rpprev(), &b.rnext);
  EXPECT_EQ(b.rpprev(), &c.rnext);
  EXPECT_EQ(c.rpprev(), &head);
  EXPECT_TRUE(b.unordered());
  EXPECT_FALSE(a.unordered());
  EXPECT_TRUE(b.slot());
  EXPECT_FALSE(a.slot());
  EXPECT_EQ(a.tag(), 0xbeef);
  EXPECT_EQ(b.tag(), 5);
  sac::detail::detach(&b);
  EXPECT_FALSE(b.attached());
  EXPECT_EQ(b.tag(), 5);
  EXPECT_TRUE(b.slot());
  EXPECT_EQ(c.rnext, &a);
  EXPECT_EQ(a.rpprev(), &c.rnext);
  EXPECT_EQ(a.tag(), 0xbeef);
  EXPECT_FALSE(a.slot());
  // The first default reader points at a modifiable's head word, marked.
  std::uintptr_t mod_head = sac::detail::kDefaultOnlyMark;
  sac::detail::detach(&a);
  sac::detail::detach(&c);
  sac::detail::push_default_reader(&a, &mod_head, nullptr);
  sac::detail::push_default_reader(&c, &mod_head, &a);
  EXPECT_EQ(mod_head, reinterpret_cast<std::uintptr_t>(&c) | sac::detail::kDefaultOnlyMark);
  EXPECT_EQ(reinterpret_cast<const std::uintptr_t*>(sac::detail::default_head(&c)), &mod_head);
  EXPECT_EQ(sac::detail::default_head(&a), nullptr);
  EXPECT_EQ(a.tag(), 0xbeef);
  sac::detail::detach(&c);
  EXPECT_EQ(mod_head, reinterpret_cast<std::uintptr_t>(&a) | sac::detail::kDefaultOnlyMark);
  EXPECT_EQ(reinterpret_cast<const std::uintptr_t*>(sac::detail::default_head(&a)), &mod_head);
  EXPECT_EQ(c.tag(), 0x0001);
}

TEST(TraceNodes, QueuePositionUsesBothHalves) {
  ReadNode r{};
  r.set_ops_id(0x1234);
  ReaderLink* head = nullptr;
  sac::detail::push_reader(&r.link, &head, true);
  for (std::uint32_t q : {0u, 1u, 0xffffu, 0x10000u, 0x12345678u, 0xfffffffeu, sac::detail::kNotQueued}) {
    r.set_qpos(q);
    EXPECT_EQ(r.qpos(), q);
    EXPECT_EQ(r.ops_id(), 0x1234);
    EXPECT_EQ(r.link.rpprev(), &head);
    EXPECT_TRUE(r.link.unordered());
    EXPECT_FALSE(r.link.slot());
  }
}

TEST(TraceNodes, OpsNumbersAreDistinctPerType) {
  using sac::detail::VersionOpsFor;
  EXPECT_NE(VersionOpsFor<int>::id(), 0);
  EXPECT_NE(VersionOpsFor<int>::id(), VersionOpsFor<double>::id());
  EXPECT_EQ(VersionOpsFor<int>::id(), VersionOpsFor<int>::id());
  EXPECT_EQ(sac::detail::version_ops_table[VersionOpsFor<long>::id()], &VersionOpsFor<long>::ops);
}

// More than 2^16 reads affected by one propagation are in the queue together.
TEST(TraceNodes, AQueueOfMoreThan65536Reads) {
  constexpr int kN = 70000;
  sac::Engine rt;
  std::vector<std::unique_ptr<sac::Mod<int>>> in, out;
  for (int i = 0; i < kN; ++i) {
    in.push_back(std::make_unique<sac::Mod<int>>());
    out.push_back(std::make_unique<sac::Mod<int>>());
    rt.set(*in.back(), i);
  }
  rt.run([&](sac::Engine& e) {
    for (int i = 0; i < kN; ++i) {
      sac::Mod<int>* o = out[i].get();
      e.read(*in[i], [o](sac::Engine& e2, int v) { e2.write(*o, 3 * v + 1); });
    }
  });
  for (int i = 0; i < kN; ++i) rt.set(*in[i], kN + i);
  rt.propagate();
  ASSERT_NO_THROW(rt.check_invariants());
  EXPECT_GE(rt.stats().queue_pops, static_cast<std::uint64_t>(kN));
  for (int i = 0; i < kN; ++i) ASSERT_EQ(out[i]->get(), 3 * (kN + i) + 1) << i;
  // And half of them back, in reverse order of position.
  for (int i = kN - 1; i >= 0; i -= 2) rt.set(*in[i], i);
  rt.propagate();
  ASSERT_NO_THROW(rt.check_invariants());
  for (int i = 0; i < kN; ++i) ASSERT_EQ(out[i]->get(), 3 * ((kN - 1 - i) % 2 == 0 ? i : kN + i) + 1) << i;
}

}  // namespace
