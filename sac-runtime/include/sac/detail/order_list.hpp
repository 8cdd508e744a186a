// sac/detail/order_list.hpp — order-maintenance list of timestamps (two-level).
//
// Purpose: every trace event owns a Stamp; the list keeps them in execution order and answers
// "does a come before b?" in O(1). Follows Dietz & Sleator (STOC'87) and Bender, Cole,
// Demaine, Farach-Colton & Zito, "Two simplified algorithms for maintaining order in a list"
// (ESA'02): the top level is a list of groups with 64-bit labels relabelled by the
// density-threshold rule; the bottom level puts at most kGroupCap stamps in each group,
// labelled with 32-bit labels.
//
// Stamps are intrusive (16 bytes) and owned by the caller; the list never allocates them.
// The bottom level is singly linked: a stamp's predecessor is found by walking its group,
// which holds at most kGroupCap stamps, so single erase is O(kGroupCap) = O(1); whole
// intervals, which is how the trace is undone, are erased in O(length).
//
// Invariants (check_invariants()):
//   - the stamps reachable from base() are exactly the linked ones, size() of them plus base;
//   - the stamps of one group are contiguous; group.first is the first of them;
//     group.count is their number, 1 <= count <= kGroupCap;
//   - labels strictly increase within a group, and group labels strictly increase along the
//     top-level list, so less() is the list order.
// Complexity: less O(1); insert_after O(1) amortized (group relabel/split O(kGroupCap),
//             top-level relabel O(log n) amortized, spread over Theta(kGroupCap) inserts);
//             erase O(kGroupCap); erase_between O(number erased).
// Paper: Dietz, Sleator (STOC'87); Bender et al. (ESA'02); docs/DESIGN.md, "The runtime".
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sac::detail {

/// What a stamp marks in the trace; stored in the low bits of the stamp's link.
enum class StampKind : std::uint8_t {
  Sentinel = 0,
  ReadStart = 1,
  ReadEnd = 2,
  Write = 3,
  Alloc = 4,
  MemoStart = 5,
  MemoEnd = 6,
  User = 7,  // free for tests and other clients of OrderList
};

/// A timestamp. 16 bytes; must be 8-byte aligned (the kind lives in the link's low bits).
/// The link's top 16 bits are free for the record that embeds the stamp (aux(): a record's
/// ops number, or half a read's queue position), which the list never changes: user-space
/// addresses fit in 48 bits on every 64-bit target we build for (Pool checks its chunks).
struct Stamp {
  static constexpr std::uint32_t kUnlinked = 0xffffffffu;
  static constexpr int kAuxShift = 48;
  static constexpr std::uintptr_t kAuxMask = ~std::uintptr_t{0} << kAuxShift;
  static constexpr std::uintptr_t kKindMask = 7;
  static constexpr std::uintptr_t kNextMask = ~(kAuxMask | kKindMask);

  std::uintptr_t link = 0;             // aux << 48 | next stamp | kind
  std::uint32_t group = kUnlinked;     // index of the group, kUnlinked when not in a list
  std::uint32_t label = 0;             // label within the group

  Stamp* next() const { return reinterpret_cast<Stamp*>(link & kNextMask); }
  StampKind kind() const { return static_cast<StampKind>(link & kKindMask); }
  bool linked() const { return group != kUnlinked; }
  std::uint16_t aux() const { return static_cast<std::uint16_t>(link >> kAuxShift); }

  void set_next(Stamp* n) { link = reinterpret_cast<std::uintptr_t>(n) | (link & ~kNextMask); }
  void set_kind(StampKind k) { link = (link & ~kKindMask) | static_cast<std::uintptr_t>(k); }
  void set_aux(std::uint16_t a) { link = (link & ~kAuxMask) | (std::uintptr_t{a} << kAuxShift); }
  /// Sets next and kind at once, keeping aux.
  void reset(Stamp* n, StampKind k) {
    link = (link & kAuxMask) | reinterpret_cast<std::uintptr_t>(n) | static_cast<std::uintptr_t>(k);
  }
};
static_assert(sizeof(Stamp) == 16);

class OrderList {
 public:
  static constexpr std::uint32_t kGroupCap = 64;
  /// Appends at the very end of the list (every from-scratch run) start a new group once a
  /// group holds this many, leaving room for later insertions: inserting into a full group
  /// splits it, which walks and relabels its (cold) stamps.
  static constexpr std::uint32_t kAppendFill = 48;

  OrderList();
  OrderList(const OrderList&) = delete;
  OrderList& operator=(const OrderList&) = delete;

  /// The sentinel that precedes every other stamp. Never erased.
  Stamp* base() { return &base_; }
  const Stamp* base() const { return &base_; }

  /// True iff a comes strictly before b. Both must be linked.
  bool less(const Stamp* a, const Stamp* b) const {
    if (a->group == b->group) return a->label < b->label;
    return groups_[a->group].label < groups_[b->group].label;
  }

  /// Links s (unlinked) right after pos (linked), with kind k.
  void insert_after(Stamp* pos, Stamp* s, StampKind k) {
    s->reset(nullptr, k);
    Group& g = groups_[pos->group];
    Stamp* n = pos->next();
    // Appends at the list's end (every from-scratch step) step the label by kAppendStep
    // while the group has room; the general path below gives the same label.
    if (!n && g.count < kAppendFill && pos->label < kBottomRange - kAppendStep) {
      s->label = pos->label + static_cast<std::uint32_t>(kAppendStep);
      s->group = pos->group;
      pos->set_next(s);
      ++g.count;
      ++size_;
      return;
    }
    // Fast path: room in the group and between the labels (appends step by kAppendStep).
    if (g.count < kGroupCap && (n || g.count < kAppendFill)) {
      std::uint64_t lo = pos->label;
      std::uint64_t hi = (n && n->group == pos->group) ? n->label : kBottomRange;
      if (hi - lo >= 2) {
        std::uint64_t lab = (hi == kBottomRange && hi - lo > kAppendStep) ? lo + kAppendStep
                                                                          : lo + (hi - lo) / 2;
        s->label = static_cast<std::uint32_t>(lab);
        s->group = pos->group;
        s->set_next(n);
        pos->set_next(s);
        ++g.count;
        ++size_;
        return;
      }
    }
    insert_slow(pos, s);
  }

  /// Unlinks a single stamp (not base()). O(kGroupCap). `hint`, if given, is a stamp that
  /// may precede s closely: the predecessor is first looked for in the few stamps after it.
  void erase(Stamp* s, Stamp* hint = nullptr);

  /// Unlinks every stamp strictly between a and b (b == nullptr: to the end), in order,
  /// calling on_erase(stamp) after each is unlinked. on_erase may free the stamp's memory but
  /// must not insert into or erase from this list.
  template <class F>
  void erase_between(Stamp* a, Stamp* b, F&& on_erase) {
    Stamp* x = a->next();
    while (x != b) {
      Stamp* nx = x->next();
      unlink_from_group(x, nx);
      on_erase(x);
      x = nx;
    }
    a->set_next(b);
  }

  std::size_t size() const { return size_; }
  std::size_t group_count() const { return group_count_; }
  std::size_t memory_bytes() const { return groups_.capacity() * sizeof(Group); }
  /// Cuts the group array's growth slack to 1/8 (after a bulk build such as a from-scratch
  /// run, whose appends double the array up to twice the size it needs), keeping enough that
  /// the first updates do not reallocate it at once. O(groups).
  void trim() {
    const std::size_t want = groups_.size() + groups_.size() / 8 + 16;
    if (groups_.capacity() <= want) return;
    std::vector<Group> g;
    g.reserve(want);
    g.assign(groups_.begin(), groups_.end());
    groups_.swap(g);
  }
  std::uint64_t top_relabels() const { return top_relabels_; }

  /// Throws sac::InvariantError describing the first broken invariant.
  void check_invariants() const;

 private:
  // Test-only hook: tests/sac/order_list_test.cpp defines it to corrupt the groups and see
  // check_invariants() fail. Nothing else may define it.
  friend struct OrderListTestAccess;

  static constexpr std::uint64_t kBottomRange = std::uint64_t{1} << 32;
  static constexpr std::uint64_t kAppendStep = kBottomRange / kGroupCap;
  static constexpr std::uint64_t kTopAppendStep = std::uint64_t{1} << 24;
  static constexpr std::uint32_t kNone = 0xffffffffu;

  struct Group {
    std::uint64_t label = 0;
    Stamp* first = nullptr;
    std::uint32_t prev = kNone;
    std::uint32_t next = kNone;  // also the free-list link
    std::uint32_t count = 0;
  };

  void insert_slow(Stamp* pos, Stamp* s);
  void unlink_from_group(Stamp* x, Stamp* nx) {
    Group& g = groups_[x->group];
    if (g.first == x) g.first = (nx && nx->group == x->group) ? nx : nullptr;
    if (--g.count == 0) free_group(x->group);
    x->group = Stamp::kUnlinked;
    --size_;
  }
  std::uint32_t new_group_after(std::uint32_t g);
  void free_group(std::uint32_t g);
  void relabel_top(std::uint32_t g);
  void relabel_group(std::uint32_t g);
  void split_group(std::uint32_t g);

  Stamp base_;
  std::vector<Group> groups_;
  std::uint32_t free_list_ = kNone;
  std::size_t size_ = 0;
  std::size_t group_count_ = 0;
  std::uint64_t top_relabels_ = 0;
};

}  // namespace sac::detail
