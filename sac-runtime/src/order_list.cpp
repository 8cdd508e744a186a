// order_list.cpp — the order-maintenance list's slow paths.
//
// Purpose: group relabel and split, top-level relabel, erase and the checker of
// sac/detail/order_list.hpp (the fast paths are inline there).
// Invariants: those of sac/detail/order_list.hpp, restored by every function here.
// Complexity: as stated in sac/detail/order_list.hpp.
// Paper: Dietz, Sleator (STOC'87); Bender, Cole, Demaine, Farach-Colton, Zito (ESA'02);
// docs/DESIGN.md, "The runtime".
#include "sac/detail/order_list.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "sac/errors.hpp"

namespace sac::detail {

namespace {
// Bender et al.'s density threshold: a label range of size 2^i may hold at most (2/T)^i groups.
constexpr double kThresholdT = 1.3;
}  // namespace

OrderList::OrderList() {
  groups_.reserve(64);
  groups_.push_back(Group{});
  Group& g = groups_[0];
  g.label = 0;
  g.first = &base_;
  g.count = 1;
  group_count_ = 1;
  base_.group = 0;
  base_.label = 0;
  base_.reset(nullptr, StampKind::Sentinel);
}

void OrderList::insert_slow(Stamp* pos, Stamp* s) {
  for (;;) {
    std::uint32_t gi = pos->group;
    Stamp* n = pos->next();
    bool n_same = n && n->group == gi;
    if (groups_[gi].count >= kGroupCap || (!n && groups_[gi].count >= kAppendFill)) {
      if (!n_same) {
        // pos ends a full group, or the list at the append fill: open a fresh group for s
        // (the common append case).
        std::uint32_t g2 = new_group_after(gi);
        Group& G2 = groups_[g2];
        G2.first = s;
        G2.count = 1;
        s->group = g2;
        s->label = 0;
        s->set_next(n);
        pos->set_next(s);
        ++size_;
        return;
      }
      split_group(gi);
      continue;
    }
    std::uint64_t lo = pos->label;
    std::uint64_t hi = n_same ? n->label : kBottomRange;
    if (hi - lo >= 2) {
      s->label = static_cast<std::uint32_t>(lo + (hi - lo) / 2);
      s->group = gi;
      s->set_next(n);
      pos->set_next(s);
      ++groups_[gi].count;
      ++size_;
      return;
    }
    relabel_group(gi);
  }
}

void OrderList::relabel_group(std::uint32_t gi) {
  Group& g = groups_[gi];
  std::uint64_t step = kBottomRange / (std::uint64_t{g.count} + 1);
  std::uint64_t lab = 0;
  for (Stamp* x = g.first; x && x->group == gi; x = x->next()) {
    x->label = static_cast<std::uint32_t>(lab);
    lab += step;
  }
}

void OrderList::split_group(std::uint32_t gi) {
  std::uint32_t keep = groups_[gi].count / 2;
  Stamp* x = groups_[gi].first;
  for (std::uint32_t i = 1; i < keep; ++i) x = x->next();
  Stamp* y = x->next();
  std::uint32_t g2 = new_group_after(gi);  // may reallocate groups_
  Group& G = groups_[gi];
  Group& G2 = groups_[g2];
  G2.first = y;
  G2.count = G.count - keep;
  G.count = keep;
  for (Stamp* z = y; z && z->group == gi; z = z->next()) z->group = g2;
  relabel_group(gi);
  relabel_group(g2);
}

std::uint32_t OrderList::new_group_after(std::uint32_t gi) {
  constexpr std::uint64_t kMax = ~std::uint64_t{0};
  std::uint64_t lab;
  for (;;) {
    std::uint64_t a = groups_[gi].label;
    std::uint32_t nx = groups_[gi].next;
    if (nx == kNone) {
      if (kMax - a > kTopAppendStep) {
        lab = a + kTopAppendStep;
        break;
      }
      if (kMax - a >= 2) {
        lab = a + (kMax - a) / 2;
        break;
      }
    } else {
      std::uint64_t b = groups_[nx].label;
      if (b - a >= 2) {
        lab = a + (b - a) / 2;
        break;
      }
    }
    relabel_top(gi);
  }
  std::uint32_t ng;
  if (free_list_ != kNone) {
    ng = free_list_;
    free_list_ = groups_[ng].next;
  } else {
    ng = static_cast<std::uint32_t>(groups_.size());
    if (ng == kNone) throw std::length_error("sac::OrderList: too many groups");
    groups_.push_back(Group{});
  }
  Group& G = groups_[gi];
  Group& N = groups_[ng];
  N.label = lab;
  N.first = nullptr;
  N.count = 0;
  N.prev = gi;
  N.next = G.next;
  if (G.next != kNone) groups_[G.next].prev = ng;
  G.next = ng;
  ++group_count_;
  return ng;
}

void OrderList::free_group(std::uint32_t gi) {
  Group& g = groups_[gi];
  if (g.prev != kNone) groups_[g.prev].next = g.next;
  if (g.next != kNone) groups_[g.next].prev = g.prev;
  g.first = nullptr;
  g.prev = kNone;
  g.next = free_list_;
  free_list_ = gi;
  --group_count_;
}

void OrderList::relabel_top(std::uint32_t gi) {
  // Smallest aligned label range around gi whose density is under the threshold; relabel its
  // groups evenly so that every gap is at least 2.
  ++top_relabels_;
  const std::uint64_t L = groups_[gi].label;
  std::uint32_t lo = gi, hi = gi;
  std::uint64_t cnt = 1;
  for (int i = 1; i <= 64; ++i) {
    const std::uint64_t mask = i == 64 ? ~std::uint64_t{0} : ((std::uint64_t{1} << i) - 1);
    const std::uint64_t rlo = L & ~mask;
    const std::uint64_t rhi = rlo | mask;
    while (groups_[lo].prev != kNone && groups_[groups_[lo].prev].label >= rlo) {
      lo = groups_[lo].prev;
      ++cnt;
    }
    while (groups_[hi].next != kNone && groups_[groups_[hi].next].label <= rhi) {
      hi = groups_[hi].next;
      ++cnt;
    }
    const double cap = std::pow(2.0 / kThresholdT, i);
    // Room for cnt + 1 groups with gaps >= 2 (the +1 is the group about to be inserted).
    const std::uint64_t span_div = (cnt + 1);
    const std::uint64_t step = (i == 64 ? mask : (std::uint64_t{1} << i)) / span_div;
    if (static_cast<double>(cnt + 1) <= cap && step >= 4) {
      std::uint64_t lab = rlo;
      for (std::uint32_t x = lo;; x = groups_[x].next) {
        groups_[x].label = lab;
        lab += step;
        if (x == hi) break;
      }
      // The last group of the whole list also needs room after it.
      return;
    }
  }
  throw std::length_error("sac::OrderList: label space exhausted");
}

void OrderList::erase(Stamp* s, Stamp* hint) {
  if (s == &base_) throw UsageError("sac::OrderList::erase: the base stamp cannot be erased");
  // A short walk from the hint touches a few nearby records instead of up to kGroupCap cold
  // ones from the start of the group.
  constexpr int kHintSteps = 8;
  Stamp* pred = nullptr;
  Stamp* x = hint;
  for (int i = 0; x && i < kHintSteps; ++i, x = x->next())
    if (x->next() == s) {
      pred = x;
      break;
    }
  if (!pred) {
    // Walk the group; when s opens its group, its predecessor ends the previous one (base_
    // guarantees there is one).
    const Group& g = groups_[s->group];
    pred = g.first == s ? groups_[g.prev].first : g.first;
    while (pred->next() != s) pred = pred->next();
  }
  Stamp* nx = s->next();
  pred->set_next(nx);
  unlink_from_group(s, nx);
}

void OrderList::check_invariants() const {
  auto fail = [](const std::string& what) { throw InvariantError("OrderList: " + what); };
  std::size_t n = 0, ngroups = 0;
  std::uint32_t gi = 0;
  const Stamp* x = &base_;
  if (base_.group != 0 || groups_[0].first != &base_) fail("base stamp is not first in group 0");
  if (groups_[0].prev != kNone) fail("group 0 has a predecessor");
  std::uint32_t prev_group = kNone;
  while (gi != kNone) {
    const Group& g = groups_[gi];
    ++ngroups;
    if (g.prev != prev_group) fail("top-level prev link broken at group " + std::to_string(gi));
    if (prev_group != kNone && !(groups_[prev_group].label < g.label))
      fail("group labels not increasing at group " + std::to_string(gi));
    if (g.first != x) fail("group.first is not the first stamp of group " + std::to_string(gi));
    if (g.count == 0 || g.count > kGroupCap) fail("bad group count");
    std::uint32_t c = 0;
    std::int64_t last = -1;
    while (x && x->group == gi) {
      if (static_cast<std::int64_t>(x->label) <= last) fail("labels not increasing in a group");
      last = x->label;
      ++c;
      x = x->next();
    }
    if (c != g.count) fail("group count mismatch in group " + std::to_string(gi));
    n += c;
    prev_group = gi;
    gi = g.next;
    if (x && (gi == kNone || x->group != gi))
      fail("stamps of a group are not contiguous / top list out of order");
  }
  if (x) fail("stamps after the last group");
  if (n != size_ + 1) fail("size mismatch");
  if (ngroups != group_count_) fail("group count total mismatch");
}

}  // namespace sac::detail
