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

using detail::AllocNode;
using detail::Stamp;
using detail::StampKind;
using detail::default_head;
using detail::kNotQueued;
using detail::Kind;
using detail::MemoNode;
using detail::ReaderLink;
using detail::ReadNode;
using detail::ReadSlot;
using detail::VersionBase;
using detail::owner_of;
using detail::visit_record;

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

void Engine::check_invariants() const {
  if (in_computation_) throw UsageError("sac::Engine::check_invariants: not inside the computation");
  // Every message starts with the number of the invariant it breaks (sac/engine.hpp).
  auto fail = [](const std::string& what) { throw InvariantError("Engine trace: " + what); };
  // I1: the order list and the queue (the tables are checked at the end).
  order_.check_invariants();
  queue_.check_invariants();
  // I7: nothing left over from the last propagate().
  if (!queue_.empty()) fail("I7: queue not empty outside propagate()");
  if (!deferred_.empty()) fail("I7: deferred frees left after propagate()");
  if (!dead_versions_.empty() || !seen_.empty()) fail("I7: undone versions or seen lists left after propagate()");

  // Walk the trace: nesting (I2), per-record checks, counts (I6).
  struct Open {
    const Stamp* close;   // stamp that closes this interval
    bool is_memo;
  };
  std::vector<Open> stack;
  std::uint64_t events = 0;
  std::size_t nkeyed = 0, nmemo = 0;
  AddressSet mods(stats_.live_events / 2);  // the modifiables written (then: or read)
  AddressSet reads(stats_.live_events / 2);  // the reader list entries: links and slots
  std::vector<const ModBase*> default_mods;  // one per modifiable whose default reads hang on it
  for (const Stamp* s = order_.base()->next(); s; s = s->next()) {
    visit_record(s, [&]<StampKind K>(Kind<K>, auto* rec) {
      if constexpr (K == StampKind::ReadStart) {
        const ReadNode* r = rec;
        ++events;
        if (!r->end.linked()) fail("I2: read without end stamp");
        if (!order_.less(&r->start, &r->end)) fail("I2: read end not after start");
        // Attachment to the version visible at its start is checked below, from the
        // version side (a read record does not name its modifiable; scanning the visible
        // version's readers here would also be quadratic in a modifiable's fan-out).
        if (r->link.qpos != kNotQueued) fail("I7: read still queued");
        if (r->many()) {
          // A multi-read hangs on versions through its slots only; each slot is checked
          // below, with its modifiable, like a read.
          const detail::ReadManyHeader* h = detail::many_of(r);
          if (r->link.rpprev) fail("I4: a multi-read's own link is attached");
          if (h->k == 0 || h->k > detail::kMaxReadMany) fail("I4: a multi-read with a bad slot count");
          for (std::uint32_t i = 0; i < h->k; ++i) {
            const ReaderLink* l = &h->slots()[i].link;
            if (!detail::is_slot(l) || l->qpos != i || owner_of(l) != r) fail("I4: a multi-read's slot is malformed");
            reads.insert(l);
            if (const ModBase* m = default_head(l)) default_mods.push_back(m);
          }
        } else {
          reads.insert(&r->link);
          if (const ModBase* m = default_head(&r->link)) default_mods.push_back(m);
        }
        stack.push_back({&r->end, false});
      } else if constexpr (K == StampKind::ReadEnd) {
        if (stack.empty() || stack.back().close != s || stack.back().is_memo)
          fail("I2: read intervals not well nested");
        stack.pop_back();
      } else if constexpr (K == StampKind::Write) {
        const VersionBase* v = rec;
        ++events;
        mods.insert(v->mod());
        bool found = false;
        for (const VersionBase* x = v->mod()->newest(); x; x = x->older())
          if (x == v) found = true;
        if (!found) fail("I3: write not in its modifiable's version list");
      } else if constexpr (K == StampKind::Alloc) {
        ++events;
        if (rec->ops->key_equal) ++nkeyed;
      } else if constexpr (K == StampKind::MemoStart) {
        const MemoNode* n = rec;
        ++events;
        ++nmemo;
        if (!n->end.linked() ||
            !order_.less(&n->start, &n->end))
          fail("I2: memo entry without a proper end stamp");
        stack.push_back({&n->end, true});
      } else if constexpr (K == StampKind::MemoEnd) {
        if (stack.empty() || stack.back().close != s || !stack.back().is_memo)
          fail("I2: memo intervals not well nested");
        stack.pop_back();
      } else {
        fail("I2: unexpected stamp kind");
      }
    });
  }
  if (!stack.empty()) fail("I2: unclosed intervals at the end of the trace");
  if (events != stats_.live_events) fail("I6: live event count mismatch");
  if (nkeyed != allocs_.size()) fail("I6: allocation table size mismatch");
  if (nmemo != memos_.size()) fail("I6: memo table size mismatch");

  // Versions of every written or read modifiable: strictly decreasing time, base last (I3);
  // readers between this version and the next newer one (so each reader hangs on the version
  // visible at its time), and every reader a live read of the trace, each exactly once (I4);
  // each list in the order its flag says (I5).
  // A live read hangs on a computation's version, a base version or (below) a default with
  // no version; so these cover every read.
  for (const VersionBase* b : bases_) mods.insert(b->mod());
  std::size_t attached = 0;
  mods.for_each([&](const void* mod) {
    const auto* m = static_cast<const ModBase*>(mod);
    const VersionBase* newer = nullptr;
    for (const VersionBase* v = m->newest(); v; v = v->older()) {
      if (v->mod() != m) fail("I3: version chain does not end at its modifiable");
      if (v->is_base()) {
        if (v->older()) fail("I3: base version is not the oldest");
      } else {
        if (!v->stamp.linked()) fail("I3: version with unlinked stamp");
        if (newer && !order_.less(&v->stamp, &newer->stamp)) fail("I3: versions out of order");
      }
      for (int list = 0; list < 2; ++list) {
        const ReaderLink* const* back = list == 0 ? &v->readers : &v->unordered_readers;
        const Stamp* last_ordered = nullptr;  // the time of the last ordered reader seen
        for (const ReaderLink* r = *back; r; back = &r->rnext, r = r->rnext) {
          if (r->rpprev != back) fail("I4: a version's reader list has a broken back link");
          // Membership first: only then may r be decoded (a slot's owner from its index).
          if (!reads.contains(r)) fail("I4: a version's reader is not a live read of the trace");
          if (detail::is_slot(r) && reinterpret_cast<const ReadSlot*>(r)->mod != m)
            fail("I4: a multi-read's slot hangs on another modifiable's version");
          const Stamp* t = &owner_of(r)->start;
          if (!v->is_base() && !order_.less(&v->stamp, t)) fail("I4: reader before its version");
          if (newer && !order_.less(t, &newer->stamp)) fail("I4: reader after the next version");
          if (r->unordered != list)
            fail("I5: a version's reader is on the other list than its flag says");
          if (list == 0) {
            if (last_ordered && order_.less(last_ordered, t))
              fail("I5: a version's ordered readers are not newest first");
            last_ordered = t;
          }
          ++attached;
        }
      }
      newer = v;
    }
  });
  // I4: reads of a default with no version hang on the modifiable; it has no version then.
  for (const ModBase* m : default_mods) {
    if (!m->default_only()) fail("I4: a read hangs on the default of a modifiable that has versions");
    const ReaderLink* first = m->default_readers();
    if (!first || default_head(first) != m) fail("I4: a modifiable's default readers do not start at its head");
    for (const ReaderLink* r = first; r; r = r->rnext) {
      if (r->rnext && r->rnext->rpprev != &r->rnext) fail("I4: a default reader list has a broken back link");
      if (!reads.contains(r)) fail("I4: a default reader is not a live read of the trace");
      if (detail::is_slot(r) && reinterpret_cast<const ReadSlot*>(r)->mod != m)
        fail("I4: a multi-read's slot hangs on another modifiable's default");
      ++attached;
    }
  }
  if (attached != reads.size()) fail("I4: read not attached to the version visible at its time");
  // I1 and I6: the tables' own structure, and that they hold only live records.
  allocs_.check_invariants("allocation table", [](const AllocNode* n) { return n->ops->hash(n); },
                           [&](const AllocNode* n) {
                             if (!n->stamp.linked()) fail("I6: allocation table holds an undone record");
                           });
  memos_.check_invariants("memo table", [](const MemoNode* n) { return n->ops->hash(n); },
                          [&](const MemoNode* n) {
                            if (!n->start.linked()) fail("I6: memo table holds an undone record");
                          });
}

}  // namespace sac
