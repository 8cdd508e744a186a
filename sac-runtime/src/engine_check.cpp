// engine_check.cpp — Engine::check_invariants(): the trace checker (cold code).
//
// Purpose: verify, outside the computation, every invariant that sac/engine.hpp numbers
// (I1 ... ), throwing InvariantError that names the invariant broken.
// Invariants: reads only; the engine is left exactly as it was.
// Complexity: O(trace size + base versions), plus the order list's and the tables' own
// checks.
// Paper: docs/DESIGN.md, "The correctness contract".
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "records.hpp"
#include "sac/engine.hpp"
#include "sac/hash.hpp"

namespace sac {

namespace {

/// The checker's set of record addresses: open addressing in one array, so that the check
/// (which SAC_DEBUG_CHECKS runs after every propagation) allocates once, not per element.
class AddressSet {
 public:
  explicit AddressSet(std::size_t expected) {
    std::size_t n = 64;
    while (n < 2 * expected) n *= 2;
    slots_.assign(n, nullptr);
  }
  /// Adds p (not null); false if it was there already.
  bool insert(const void* p) {
    if (2 * (size_ + 1) > slots_.size()) grow();
    const std::size_t i = slot_of(p);
    if (slots_[i]) return false;
    slots_[i] = p;
    ++size_;
    return true;
  }
  bool contains(const void* p) const { return slots_[slot_of(p)] != nullptr; }
  std::size_t size() const { return size_; }
  template <class F>
  void for_each(F&& f) const {
    for (const void* p : slots_)
      if (p) f(p);
  }

 private:
  /// p's slot, or the empty slot where it would go (linear probing).
  std::size_t slot_of(const void* p) const {
    const std::size_t mask = slots_.size() - 1;
    std::size_t i = static_cast<std::size_t>(mix64(reinterpret_cast<std::uintptr_t>(p))) & mask;
    while (slots_[i] && slots_[i] != p) i = (i + 1) & mask;
    return i;
  }
  void grow() {
    std::vector<const void*> old(slots_.size() * 2, nullptr);
    old.swap(slots_);
    size_ = 0;
    for (const void* p : old)
      if (p) insert(p);
  }

  std::vector<const void*> slots_;
  std::size_t size_ = 0;
};

}  // namespace

namespace detail {

/// check_invariants() as named phases over one engine: the trace walk collects the
/// modifiables, the live reads and the default readers that the later phases check.
class TraceChecker {
 public:
  explicit TraceChecker(const Engine& rt)
      : rt_(rt), mods_(rt.stats_.live_events / 2), reads_(rt.stats_.live_events / 2) {}

  [[noreturn]] static void fail(const std::string& what) { throw InvariantError("Engine trace: " + what); }

  /// I1: the order list and the queue (the tables are checked last, by check_tables).
  void check_order_and_queue() const {
    rt_.order_.check_invariants();
    rt_.queue_.check_invariants();
  }
  /// I7: nothing left over from the last propagate().
  void check_nothing_left() const {
    if (!rt_.queue_.empty()) fail("I7: queue not empty outside propagate()");
    if (!rt_.deferred_.empty()) fail("I7: deferred frees left after propagate()");
    if (!rt_.dead_versions_.empty() || !rt_.seen_.empty())
      fail("I7: undone versions or seen lists left after propagate()");
  }
  /// I2 and I6: walks the trace in time order, checking that intervals nest and counting the
  /// live events, keyed allocations and memo entries; collects what the next phases check.
  void walk_trace();
  /// I3, I4, I5: each written or read modifiable's versions, and the readers on each.
  void check_versions();
  /// I4: reads of a default with no version hang on the modifiable, which has no version;
  /// and every live read hangs somewhere, exactly once.
  void check_default_readers();
  /// I1 and I6: the tables' own structure, and that they hold only live records.
  void check_tables() const;

 private:
  void walk_read(const ReadNode* r);

  struct Open {
    const Stamp* close;  // the stamp that closes this interval
    bool is_memo;
  };

  const Engine& rt_;
  std::vector<Open> stack_;
  AddressSet mods_;                         // the modifiables written (then: or read)
  AddressSet reads_;                        // the reader list entries: links and slots
  std::vector<const ModBase*> default_mods_;  // one per modifiable whose default reads hang on it
  std::size_t attached_ = 0;                // readers found on versions and defaults
};

void TraceChecker::walk_read(const ReadNode* r) {
  if (!r->end.linked()) fail("I2: read without end stamp");
  if (!rt_.order_.less(&r->start, &r->end)) fail("I2: read end not after start");
  // Attachment to the version visible at its start is checked from the version side
  // (check_versions): a read record does not name its modifiable, and scanning the visible
  // version's readers here would be quadratic in a modifiable's fan-out.
  if (r->qpos() != kNotQueued) fail("I7: read still queued");
  // Its ops number (in its end stamp's spare bits) names a registered table, and its own
  // link does not say it is a slot.
  if (r->ops_id() == 0 || !detail::read_ops_table[r->ops_id()]) fail("I4: a read with no ops table");
  if (r->link.slot()) fail("I4: a read's own link is marked as a slot");
  if (r->many()) {
    // A multi-read hangs on versions through its slots only; each slot is checked with its
    // modifiable, like a read.
    const ReadManyHeader* h = many_of(r);
    if (r->link.attached()) fail("I4: a multi-read's own link is attached");
    if (h->k() == 0 || h->k() > kMaxReadMany) fail("I4: a multi-read with a bad slot count");
    for (std::uint32_t i = 0; i < h->k(); ++i) {
      const ReaderLink* l = &h->slots()[i].link;
      if (!is_slot(l) || l->tag() != i || owner_of(l) != r) fail("I4: a multi-read's slot is malformed");
      reads_.insert(l);
      if (const ModBase* m = default_head(l)) default_mods_.push_back(m);
    }
  } else {
    reads_.insert(&r->link);
    if (const ModBase* m = default_head(&r->link)) default_mods_.push_back(m);
  }
  stack_.push_back({&r->end, false});
}

void TraceChecker::walk_trace() {
  std::uint64_t events = 0;
  std::size_t nkeyed = 0, nmemo = 0;
  for (const Stamp* s = rt_.order_.base()->next(); s; s = s->next()) {
    visit_record(s, [&]<StampKind K>(Kind<K>, auto* rec) {
      if constexpr (K == StampKind::ReadStart) {
        ++events;
        walk_read(rec);
      } else if constexpr (K == StampKind::ReadEnd) {
        if (stack_.empty() || stack_.back().close != s || stack_.back().is_memo)
          fail("I2: read intervals not well nested");
        stack_.pop_back();
      } else if constexpr (K == StampKind::Write) {
        const VersionBase* v = rec;
        ++events;
        mods_.insert(v->mod());
        bool found = false;
        for (const VersionBase* x = v->mod()->newest(); x; x = x->older())
          if (x == v) found = true;
        if (!found) fail("I3: write not in its modifiable's version list");
      } else if constexpr (K == StampKind::Alloc) {
        ++events;
        if (rec->ops()->key_equal) ++nkeyed;
      } else if constexpr (K == StampKind::MemoStart) {
        const MemoNode* n = rec;
        ++events;
        ++nmemo;
        if (!n->end.linked() || !rt_.order_.less(&n->start, &n->end))
          fail("I2: memo entry without a proper end stamp");
        stack_.push_back({&n->end, true});
      } else if constexpr (K == StampKind::MemoEnd) {
        if (stack_.empty() || stack_.back().close != s || !stack_.back().is_memo)
          fail("I2: memo intervals not well nested");
        stack_.pop_back();
      } else {
        fail("I2: unexpected stamp kind");
      }
    });
  }
  if (!stack_.empty()) fail("I2: unclosed intervals at the end of the trace");
  if (events != rt_.stats_.live_events) fail("I6: live event count mismatch");
  if (nkeyed != rt_.allocs_.size()) fail("I6: allocation table size mismatch");
  if (nmemo != rt_.memos_.size()) fail("I6: memo table size mismatch");
}

// Versions of every written or read modifiable: strictly decreasing time, base last (I3);
// readers between this version and the next newer one (so each reader hangs on the version
// visible at its time), and every reader a live read of the trace (I4); each list in the
// order its flag says (I5). A live read hangs on a computation's version, a base version or
// (check_default_readers) a default with no version; so these cover every read.
void TraceChecker::check_versions() {
  for (const VersionBase* b : rt_.bases_) mods_.insert(b->mod());
  mods_.for_each([&](const void* mod) {
    const auto* m = static_cast<const ModBase*>(mod);
    const VersionBase* newer = nullptr;
    for (const VersionBase* v = m->newest(); v; v = v->older()) {
      if (v->mod() != m) fail("I3: version chain does not end at its modifiable");
      if (v->is_base()) {
        if (v->older()) fail("I3: base version is not the oldest");
      } else {
        if (!v->stamp.linked()) fail("I3: version with unlinked stamp");
        if (newer && !rt_.order_.less(&v->stamp, &newer->stamp)) fail("I3: versions out of order");
      }
      for (int list = 0; list < 2; ++list) {
        const ReaderLink* const* back = list == 0 ? &v->readers : &v->unordered_readers;
        const Stamp* last_ordered = nullptr;  // the time of the last ordered reader seen
        for (const ReaderLink* r = *back; r; back = &r->rnext, r = r->rnext) {
          if (r->rpprev() != back) fail("I4: a version's reader list has a broken back link");
          // Membership first: only then may r be decoded (a slot's owner from its index).
          if (!reads_.contains(r)) fail("I4: a version's reader is not a live read of the trace");
          if (is_slot(r) && reinterpret_cast<const ReadSlot*>(r)->mod != m)
            fail("I4: a multi-read's slot hangs on another modifiable's version");
          const Stamp* t = &owner_of(r)->start;
          if (!v->is_base() && !rt_.order_.less(&v->stamp, t)) fail("I4: reader before its version");
          if (newer && !rt_.order_.less(t, &newer->stamp)) fail("I4: reader after the next version");
          if (r->unordered() != static_cast<bool>(list))
            fail("I5: a version's reader is on the other list than its flag says");
          if (list == 0) {
            if (last_ordered && rt_.order_.less(last_ordered, t))
              fail("I5: a version's ordered readers are not newest first");
            last_ordered = t;
          }
          ++attached_;
        }
      }
      newer = v;
    }
  });
}

void TraceChecker::check_default_readers() {
  for (const ModBase* m : default_mods_) {
    if (!m->default_only()) fail("I4: a read hangs on the default of a modifiable that has versions");
    const ReaderLink* first = m->default_readers();
    if (!first || default_head(first) != m) fail("I4: a modifiable's default readers do not start at its head");
    for (const ReaderLink* r = first; r; r = r->rnext) {
      if (r->rnext && r->rnext->rpprev() != &r->rnext) fail("I4: a default reader list has a broken back link");
      if (!reads_.contains(r)) fail("I4: a default reader is not a live read of the trace");
      if (is_slot(r) && reinterpret_cast<const ReadSlot*>(r)->mod != m)
        fail("I4: a multi-read's slot hangs on another modifiable's default");
      ++attached_;
    }
  }
  if (attached_ != reads_.size()) fail("I4: read not attached to the version visible at its time");
}

void TraceChecker::check_tables() const {
  rt_.allocs_.check_invariants("allocation table", [](const AllocNode* n) { return n->ops()->hash(n); },
                               [](const AllocNode* n) {
                                 if (!n->stamp.linked()) fail("I6: allocation table holds an undone record");
                               });
  rt_.memos_.check_invariants("memo table", [](const MemoNode* n) { return n->ops()->hash(n); },
                              [](const MemoNode* n) {
                                if (!n->start.linked()) fail("I6: memo table holds an undone record");
                              });
}

}  // namespace detail

// Every message starts with the number of the invariant it breaks (sac/engine.hpp).
void Engine::check_invariants() const {
  if (in_computation_) throw UsageError("sac::Engine::check_invariants: not inside the computation");
  detail::TraceChecker check(*this);
  check.check_order_and_queue();  // I1
  check.check_nothing_left();     // I7
  check.walk_trace();             // I2, I6 (and what follows needs)
  check.check_versions();         // I3, I4, I5
  check.check_default_readers();  // I4
  check.check_tables();           // I1, I6
}

}  // namespace sac
