// The engine's non-template machinery: change propagation, undo, memo matching, checks.
#include "sac/engine.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <map>
#include <ostream>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "sac/hash.hpp"

namespace sac {

using detail::AllocNode;
using detail::MemoNode;
using detail::ReaderLink;
using detail::ReadNode;
using detail::ReadSlot;
using detail::VersionBase;
using detail::owner_of;

namespace {

/// The record whose stamp at `offset` is s (container_of), const when s is.
template <class N, class S>
N* record_at(S* s, std::size_t offset) {
  using Byte = std::conditional_t<std::is_const_v<S>, const char, char>;
  return reinterpret_cast<N*>(reinterpret_cast<Byte*>(s) - offset);
}

/// A stamp kind as a type: the first argument visit_record passes.
template <StampKind K>
using Kind = std::integral_constant<StampKind, K>;

/// The one decoder of stamp kinds: calls f(Kind<k>{}, record) for k = s->kind(), with the
/// record s belongs to typed by k (ReadNode for ReadStart/ReadEnd, VersionBase for Write,
/// AllocNode for Alloc, MemoNode for MemoStart/MemoEnd; s itself for Sentinel and User),
/// const when s is. f is typically [&]<StampKind K>(Kind<K>, auto* rec) { if constexpr ... }.
template <class S, class F>
void visit_record(S* s, F&& f) {
  constexpr bool c = std::is_const_v<S>;
  using Read = std::conditional_t<c, const ReadNode, ReadNode>;
  using Version = std::conditional_t<c, const VersionBase, VersionBase>;
  using Alloc = std::conditional_t<c, const AllocNode, AllocNode>;
  using Memo = std::conditional_t<c, const MemoNode, MemoNode>;
  switch (s->kind()) {
    case StampKind::ReadStart:
      f(Kind<StampKind::ReadStart>{}, record_at<Read>(s, offsetof(ReadNode, start)));
      break;
    case StampKind::ReadEnd:
      f(Kind<StampKind::ReadEnd>{}, record_at<Read>(s, offsetof(ReadNode, end)));
      break;
    case StampKind::Write:
      f(Kind<StampKind::Write>{}, record_at<Version>(s, offsetof(VersionBase, stamp)));
      break;
    case StampKind::Alloc:
      f(Kind<StampKind::Alloc>{}, record_at<Alloc>(s, offsetof(AllocNode, stamp)));
      break;
    case StampKind::MemoStart:
      f(Kind<StampKind::MemoStart>{}, record_at<Memo>(s, offsetof(MemoNode, start)));
      break;
    case StampKind::MemoEnd:
      f(Kind<StampKind::MemoEnd>{}, record_at<Memo>(s, offsetof(MemoNode, end)));
      break;
    case StampKind::Sentinel:
      f(Kind<StampKind::Sentinel>{}, s);
      break;
    case StampKind::User:
      f(Kind<StampKind::User>{}, s);
      break;
  }
}

/// The checker's set of record addresses: open addressing in one array. A node-based hash
/// set allocated per element, which dominated check_invariants() in the sanitizer build,
/// where SAC_DEBUG_CHECKS runs it after every propagation.
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

Engine::Engine() { tail_ = order_.base(); }

Engine::~Engine() { destroy_all(); }

void Engine::require_mutator(const char* what) const {
  if (poisoned_)
    throw PoisonedError(std::string("sac::Engine::") + what +
                        ": the engine is poisoned (a body threw earlier)");
  if (in_computation_)
    throw UsageError(std::string("sac::Engine::") + what +
                     ": called from inside the computation (mutator only)");
}

void Engine::fail_not_in_computation(const char* what) const {
  if (poisoned_)
    throw PoisonedError(std::string("sac::Engine::") + what + ": the engine is poisoned");
  throw UsageError(std::string("sac::Engine::") + what +
                   ": only allowed inside run() or propagate() (the computation)");
}

void Engine::throw_bad_context() {
  throw UsageError("sac::Engine::context: no context of that type was set (set_context)");
}

void Engine::poison() noexcept {
  discard_pending();
  poisoned_ = true;
  in_computation_ = false;
  now_ = nullptr;
  window_end_ = nullptr;
}

// ------------------------------------------------------------------ versions

VersionBase* Engine::visible(const ModBase& m, const Stamp* t) const {
  VersionBase* v = m.newest();
  // At the trace's end (every from-scratch step) the newest version is the one, and its
  // stamp need not be loaded. A version written at t itself is visible at t: a read's
  // start is never a write's stamp, but now_ is one right after a write.
  if (t->next() == nullptr) return v;
  while (v && !(v->is_base() || &v->stamp == t || order_.less(&v->stamp, t))) v = v->older();
  return v;
}

const VersionBase* Engine::visible_or_default(const ModBase& m, const Stamp* t, const detail::VersionOps* ops) {
  if (VersionBase* v = visible(m, t)) return v;
  // No version at all: the read will hang on m itself, and sees the type's shared T{}.
  // Most defaults read are never written (a list's end), so they never cost a version.
  if (m.default_only()) return ops->shared_default ? ops->shared_default() : nullptr;
  const VersionBase* newest = m.newest();
  const bool defaulted = newest && (newest->oldest()->link & VersionBase::kDefaulted);
  return default_base(const_cast<ModBase&>(m), defaulted, ops);
}

VersionBase* Engine::default_base(ModBase& m, bool defaulted, const detail::VersionOps* ops) {
  if (!defaulted || !ops->make_default) return nullptr;
  // What init(m, T{}) would have made before the first run; the reads that hung on m's
  // default hang on it now.
  ReaderLink* readers = m.default_readers();
  VersionBase* base = ops->make_default(allocate(ops->size));
  set_base(m, base, nullptr);
  if (readers) {  // a default's list has no order
    base->unordered_readers = readers;
    readers->rpprev = &base->unordered_readers;
    for (ReaderLink* r = readers; r; r = r->rnext) r->unordered = 1;
  }
  return base;
}

void Engine::link_write(ModBase& m, VersionBase* v) {
  // Readers of the default and a version: the default needs its own version now.
  if (m.default_readers()) default_base(m, true, v->ops);
  order_.insert_after(now_, &v->stamp, StampKind::Write);
  now_ = &v->stamp;
  ++stats_.events_created;
  ++stats_.live_events;
  VersionBase* newer = nullptr;
  VersionBase* older = m.newest();
  while (older && !(older->is_base() || order_.less(&older->stamp, &v->stamp))) {
    newer = older;
    older = older->older();
  }
  if (older) v->set_older(older);
  else v->link = newer ? newer->link : end_link(m, m.default_only());  // v is the oldest now
  v->readers = nullptr;
  v->unordered_readers = nullptr;
  if (newer) newer->set_older(v);
  else m.set_newest(v);
  // Readers of the older version that come after v now see v. When v is the last stamp of
  // the whole trace (every from-scratch write) none can.
  if (older && (older->readers || older->unordered_readers) && v->stamp.next() != nullptr) {
    const bool same = v->ops->equal(v, older);
    const bool one = !older->unordered_readers ? !older->readers->rnext
                                               : !older->readers && !older->unordered_readers->rnext;
    if (newer && !one && move_readers_between(m, older, v, newer, same)) return;
    move_readers_after(m, older, v, same);
  }
}

void Engine::move_readers_after(ModBase& m, VersionBase* older, VersionBase* v, bool same) {
  // Each unordered reader is tested; the ordered ones, newest first, up to the first before
  // v. A slot's time is its multi-read's.
  std::vector<ReaderLink*>& moved = order_scratch_;
  std::vector<ReaderLink*>& kept = fold_scratch_;
  moved.clear();
  kept.clear();
  for (ReaderLink* r = older->unordered_readers; r; r = r->rnext) {
    ++stats_.readers_tested;
    (order_.less(&v->stamp, &owner_of(r)->start) ? moved : kept).push_back(r);
  }
  ReaderLink* first = older->readers;  // the ordered readers after v: first up to stop
  ReaderLink* stop = first;
  ReaderLink* last = nullptr;
  for (; stop; last = stop, stop = stop->rnext) {
    ++stats_.readers_tested;
    if (!order_.less(&v->stamp, &owner_of(stop)->start)) break;
  }
  if (first != stop) {  // cut the run out of older's list
    older->readers = stop;
    if (stop) stop->rpprev = &older->readers;
    last->rnext = nullptr;
  }
  for (ReaderLink* x : moved) detach(x);
  if (!kept.empty()) fold_unordered(older);
  if (moved.empty() && first == stop) return;
  // v had no readers: they are the run merged with the unordered readers moved.
  link_merged(&v->readers, first != stop ? first : nullptr, nullptr);
  if (same) return;
  for (ReaderLink* x = v->readers; x; x = x->rnext) note_change(x, m, older, v, true);
}

void Engine::sort_newest_first(std::vector<ReaderLink*>& xs) const {
  // Readers at one time (slots of one multi-read) may come out in either order.
  if (xs.size() > 1)
    std::sort(xs.begin(), xs.end(), [this](const ReaderLink* a, const ReaderLink* b) {
      return order_.less(&owner_of(b)->start, &owner_of(a)->start);
    });
}

void Engine::fold_unordered(VersionBase* older) {
  // Each reader of fold_scratch_ goes in its place among older's ordered readers, as far
  // as a walk of about as many of those as there are to fold reaches: a step of the walk
  // costs a cache miss, as testing each of these did. The others stay unordered.
  std::vector<ReaderLink*>& xs = fold_scratch_;
  sort_newest_first(xs);
  std::size_t budget = xs.size() + 2, i = 0;
  ReaderLink** at = &older->readers;
  while (i < xs.size()) {
    ReaderLink* x = *at;
    if (x && order_.less(&owner_of(xs[i])->start, &owner_of(x)->start)) {  // xs[i] goes after x
      if (budget == 0) break;
      --budget;
      ++stats_.readers_tested;
      at = &x->rnext;
      continue;
    }
    ReaderLink* y = xs[i++];
    detach(y);
    y->rpprev = at;
    y->rnext = x;
    *at = y;
    if (x) x->rpprev = &y->rnext;
    y->unordered = 0;
    at = &y->rnext;
  }
  xs.clear();
}

void Engine::link_merged(ReaderLink** at, ReaderLink* run, ReaderLink* tail) {
  std::vector<ReaderLink*>& xs = order_scratch_;
  sort_newest_first(xs);
  std::size_t i = 0;
  while (i < xs.size()) {
    ReaderLink* x;
    if (!run || order_.less(&owner_of(run)->start, &owner_of(xs[i])->start)) {
      x = xs[i++];
    } else {
      x = run;
      run = run->rnext;
    }
    x->rpprev = at;
    *at = x;
    at = &x->rnext;
    x->unordered = 0;
    ++stats_.readers_relinked;
  }
  xs.clear();
  if (run) {  // what is left of the run is in order and linked: it goes in whole
    run->rpprev = at;
    *at = run;
    if (!tail) return;  // the run ends in null already
    for (; run->rnext; run = run->rnext) ++stats_.readers_relinked;
    at = &run->rnext;
  }
  *at = tail;
  if (tail) tail->rpprev = at;
}

bool Engine::move_readers_between(ModBase& m, VersionBase* older, VersionBase* v, VersionBase* newer, bool same) {
  // The readers to move are the reads of m timed between v and newer (each sees older,
  // the version visible at its time). A write that re-executes one already in the trace
  // (newer) is mostly close to it, while older may have a hundred readers, nearly all before
  // v: walking the stretch of trace between finds them without touching those. Only
  // multi-read slots name their modifiable; a plain read of the same value type in the
  // stretch, or a long stretch, leaves the work to the scan of older's readers.
  constexpr int kMaxStretch = 64, kMaxFound = 16;
  ReaderLink* found[kMaxFound];
  int n = 0, k = 0;
  for (Stamp* s = v->stamp.next(); s != &newer->stamp; s = s->next()) {
    if (!s || ++k > kMaxStretch) return false;
    if (s->kind() != StampKind::ReadStart) continue;
    ReadNode* r = detail::read_of_start(s);
    const detail::ReadOps* ops = r->ops();
    if (ops->value != v->ops) continue;
    if (!ops->invoke_many) return false;  // a plain read: of m or not, it does not say
    detail::ReadManyHeader* h = detail::many_of(r);
    for (std::uint32_t i = 0; i < h->k; ++i)
      if (h->slots()[i].mod == &m) {
        if (n == kMaxFound) return false;
        found[n++] = &h->slots()[i].link;
      }
  }
  for (int i = 0; i < n; ++i) move_reader(found[i], m, older, v, same);
  return true;
}

void Engine::move_reader(ReaderLink* r, ModBase& m, VersionBase* older, VersionBase* v, bool same) {
  // Moved oldest first onto v, which had no readers: v's list comes out ordered.
  detach(r);
  attach(r, v);
  if (!same) note_change(r, m, older, v, true);
}

void Engine::set_base(ModBase& m, VersionBase* fresh, bool (*assign)(VersionBase*, VersionBase*)) {
  // set() on a default that reads saw: make it a base version, then assign to it.
  if (assign && m.default_readers()) default_base(m, true, fresh->ops);
  VersionBase* last = nullptr;
  for (VersionBase* v = m.newest(); v; v = v->older()) last = v;
  if (VersionBase* base = last && last->is_base() ? last : nullptr) {
    // An equal value changes nothing. Otherwise the base takes the new value and, when the
    // values were swapped, fresh keeps the old one for the readers that saw it.
    if (!base->ops->equal(base, fresh)) {
      const bool swapped = assign(base, fresh);
      bool kept = false;
      for (ReaderLink* l : {base->readers, base->unordered_readers})
        for (ReaderLink* r = l; r; r = r->rnext) kept |= note_change(r, m, fresh, base, swapped);
      if (kept) {
        dead_versions_.push_back(fresh);
        return;
      }
    }
    destroy(fresh);
    return;
  }
  // A new base version: it precedes every computation write, so nobody saw "nothing" here
  // (such a read would have failed), and no reader is affected.
  fresh->stamp.link = static_cast<std::uintptr_t>(StampKind::Sentinel);
  fresh->stamp.label = static_cast<std::uint32_t>(bases_.size());
  fresh->link = last ? last->link : end_link(m, m.default_only());
  fresh->readers = nullptr;
  fresh->unordered_readers = nullptr;
  bases_.push_back(fresh);
  input_bytes_ += (fresh->ops->size + 7) & ~std::size_t{7};
  if (last) last->set_older(fresh);
  else m.set_newest(fresh);
}

bool Engine::unused(const ModBase& m) const noexcept {
  if (m.default_only()) return !m.default_readers();
  const VersionBase* v = m.newest();
  return !v || (v->is_base() && !v->older() && !v->readers && !v->unordered_readers);
}

void Engine::retire(ModBase& m) {
  require_mutator("retire");
  VersionBase* v = m.newest();
  if (!v) {
    if (m.default_readers()) throw UsageError("sac::Engine::retire: the modifiable is still read");
    m.head_ = 0;  // no version; a default, if any, goes too
    return;
  }
  if (!v->is_base() || v->older())
    throw UsageError("sac::Engine::retire: the modifiable has versions written by the computation");
  if (v->readers || v->unordered_readers) throw UsageError("sac::Engine::retire: the modifiable is still read");
  const std::uint32_t i = v->stamp.label;
  bases_[i] = bases_.back();
  bases_[i]->stamp.label = i;
  bases_.pop_back();
  m.head_ = 0;
  input_bytes_ -= (v->ops->size + 7) & ~std::size_t{7};
  destroy(v);
}

// ------------------------------------------------------------------ the trampoline

void Engine::flush() {
  // A write/alloc/make follows calls this body issued: run them first, so that events keep
  // program order.
  const std::size_t floor = tasks_.size();
  for (std::size_t i = issued_.size(); i-- > body_mark_;) tasks_.push_back(issued_[i]);
  issued_.resize(body_mark_);
  // The close below the floor belongs to the body that is still running: nothing flushed
  // here may be chained onto it.
  const std::size_t saved = close_floor_;
  close_floor_ = floor;
  drain(floor);
  close_floor_ = saved;
}

void Engine::drain(std::size_t floor) {
  while (tasks_.size() > floor) {
    const Task t = tasks_.back();
    tasks_.pop_back();
    execute(t);
  }
}

void Engine::exec_read(ReadNode* r) {
  order_.insert_after(now_, &r->start, StampKind::ReadStart);
  now_ = &r->start;
  ++stats_.events_created;
  ++stats_.live_events;
  const ModBase& m = *r->link.issued_mod;
  const VersionBase* v = visible_or_default(m, &r->start, r->ops()->value);
  if (!v) throw UsageError("sac::Engine::read: the modifiable was never written before this read");
  attach_seen(&r->link, m, v);
  push_close(&r->end, TaskKind::CloseRead, r);
  exec_body([&] { r->ops()->invoke(*this, r, v); });
}

void Engine::exec_read_many(ReadNode* r) {
  order_.insert_after(now_, &r->start, StampKind::ReadStart);
  now_ = &r->start;
  ++stats_.events_created;  // one event for all k modifiables
  ++stats_.live_events;
  push_close(&r->end, TaskKind::CloseRead, r);
  attach_and_invoke_many(r);
}

void Engine::attach_and_invoke_many(ReadNode* r, bool attached) {
  detail::ReadManyHeader* h = detail::many_of(r);
  const detail::VersionOps* ops = r->ops()->value;
  const VersionBase* vs[detail::kMaxReadMany];
  ReadSlot* slots = h->slots();
  for (std::uint32_t i = 0; i < h->k; ++i) {
    const VersionBase* v = visible_or_default(*slots[i].mod, &r->start, ops);
    if (!v) throw UsageError("sac::Engine::read_many: a modifiable has no value at the time of this read");
    if (!attached || !slots[i].link.rpprev) attach_seen(&slots[i].link, *slots[i].mod, v);
    vs[i] = v;
  }
  exec_body([&] { r->ops()->invoke_many(*this, r, vs); });
}

void Engine::throw_read_many_size() {
  throw UsageError("sac::Engine::read_many: reads 1 to 16 modifiables");
}

void Engine::push_close(Stamp* end, TaskKind kind, void* node) {
  // A call that was the last one issued by its parent closes right before the parent does:
  // chain it onto the parent's pending close (through the unlinked end stamp's link field)
  // instead of stacking one task per level, so a chain of a million tail reads needs one task.
  if (tasks_.size() > close_floor_ && (tasks_.back().kind == TaskKind::CloseRead ||
                                       tasks_.back().kind == TaskKind::CloseMemo)) {
    Task& top = tasks_.back();
    end->link = reinterpret_cast<std::uintptr_t>(top.node) |
                (top.kind == TaskKind::CloseMemo ? std::uintptr_t{1} : 0);
    top = Task{kind, 0, node};
    return;
  }
  end->link = 0;
  tasks_.push_back(Task{kind, 0, node});
}

void Engine::close_chain(TaskKind kind, void* node) {
  while (node) {
    Stamp* end = kind == TaskKind::CloseRead ? &static_cast<ReadNode*>(node)->end
                                             : &static_cast<MemoNode*>(node)->end;
    const std::uintptr_t next = end->link;
    order_.insert_after(now_, end, kind == TaskKind::CloseRead ? StampKind::ReadEnd : StampKind::MemoEnd);
    now_ = end;
    kind = (next & 1) ? TaskKind::CloseMemo : TaskKind::CloseRead;
    node = reinterpret_cast<void*>(next & ~std::uintptr_t{1});
  }
}

void Engine::execute(const Task& t) {
  switch (t.kind) {
    case TaskKind::ExecRead:
      exec_read(static_cast<ReadNode*>(t.node));
      break;
    case TaskKind::ExecReadMany:
      exec_read_many(static_cast<ReadNode*>(t.node));
      break;
    case TaskKind::ExecMemoRead: {
      auto* r = static_cast<ReadNode*>(t.node);
      if (window_end_) {
        if (ReadNode* hit = find_read_match(*r->link.issued_mod, r->link.ops_id, closure_of(r))) {
          destroy(r);
          memo_hit(&hit->start, &hit->end);
          break;
        }
        ++stats_.memo_misses;
      }
      exec_read(r);
      break;
    }
    case TaskKind::ExecMemo: {
      auto* n = static_cast<MemoNode*>(t.node);
      const std::size_t h = n->ops->hash(n);
      if (window_end_) {
        MemoNode* hit = find_memo_match(n->ops, h, reinterpret_cast<const MemoNode*>(n) + 1);
        if (hit && t.arg != detail::kAnyDistance && !within(now_, &hit->start, t.arg)) {
          hit = nullptr;
          ++stats_.memo_far;
        }
        if (hit) {
          destroy(n);
          memo_hit(&hit->start, &hit->end);
          break;
        }
        ++stats_.memo_misses;
      }
      link_memo(n, h);
      push_close(&n->end, TaskKind::CloseMemo, n);
      exec_body([&] { n->ops->invoke(*this, n); });
      break;
    }
    case TaskKind::CloseRead:
    case TaskKind::CloseMemo:
      close_chain(t.kind, t.node);
      break;
    case TaskKind::FinishRerun: {
      auto* r = static_cast<ReadNode*>(t.node);
      undo_between(now_, &r->end);  // what the old execution did and this one did not redo
      now_ = reruns_.back().now;
      window_end_ = reruns_.back().window_end;
      reruns_.pop_back();
      break;
    }
    case TaskKind::DrainUntil: {
      // Affected reads inside a reused stretch are brought up to date, in time order, before
      // execution continues after it.
      auto* end = static_cast<Stamp*>(t.node);
      if (!queue_.empty() && order_.less(&queue_.top()->start, end)) {
        QueueAux a;
        ReadNode* r = queue_.pop(&a);
        ++stats_.queue_pops;
        tasks_.push_back(t);  // drain on after this re-execution
        if (a.forced() || still_affected(r, a)) rerun(r, a.mod());
      } else {
        now_ = end;
      }
      break;
    }
  }
}

void Engine::discard_pending() noexcept {
  // Nodes of calls that were issued but never executed are not in the trace: free them here.
  auto discard = [this](const Task& t) {
    if (t.kind == TaskKind::ExecRead || t.kind == TaskKind::ExecMemoRead ||
        t.kind == TaskKind::ExecReadMany) {
      auto* r = static_cast<ReadNode*>(t.node);
      destroy(r);
    } else if (t.kind == TaskKind::ExecMemo) {
      auto* n = static_cast<MemoNode*>(t.node);
      destroy(n);
    }
  };
  for (const Task& t : tasks_) discard(t);
  for (const Task& t : issued_) discard(t);
  tasks_.clear();
  issued_.clear();
  reruns_.clear();
  body_mark_ = 0;
  close_floor_ = 0;
  pending_.clear();  // the allocations are in the trace; destroy_all frees them there
}

bool Engine::note_change(ReaderLink* l, const ModBase& m, const VersionBase* before, const VersionBase* after,
                         bool lazy) {
  ReadNode* r = owner_of(l);
  if (r->link.qpos != kNotQueued) {  // queued already (a multi-read with several changed slots)
    QueueAux& a = queue_.aux(r);
    if (a.forced()) return false;  // a plain read's always is: it re-runs
    if (!lazy) {
      a.force();
      return false;
    }
    const std::uint32_t slot = l->qpos;  // a listed read is a multi-read
    a.mark_again();
    for (std::uint32_t i = a.seen(); i != kSeenNone; i = seen_[i].next)
      if (seen_[i].slot == slot) {  // what it saw last is recorded
        seen_[i].now = after;
        return false;
      }
    seen_.push_back(Seen{before, after, slot, a.seen()});
    a.prepend(static_cast<std::uint32_t>(seen_.size() - 1));
    return true;
  }
  const std::uint32_t slot = detail::is_slot(l) ? l->qpos : 0;
  const auto f = r->ops()->affected;
  if (f && after && !f(r, slot, before, after)) return false;  // no `after`: a default, re-run
  // A plain read is not listed: its value changed and it re-runs; a record per change
  // would cost it more than it saves.
  QueueAux a = QueueAux::read_of(detail::is_slot(l) ? nullptr : &m);
  if (lazy && f) {
    seen_.push_back(Seen{before, after, slot, kSeenNone});
    a = QueueAux::listed(static_cast<std::uint32_t>(seen_.size() - 1));
  }
  queue_.push(r, a);
  ++stats_.queue_pushes;
  return !a.forced();
}

bool Engine::still_affected(ReadNode* r, const QueueAux& a) {
  // Queued by one change that affected it, and none since: it is, unless it can follow.
  if (!a.again() && !r->ops()->follow) return true;
  const auto f = r->ops()->affected;
  for (std::uint32_t i = a.seen(); i != kSeenNone; i = seen_[i].next) {
    const Seen& s = seen_[i];
    const VersionBase* now = s.now;
    if (now == s.v) continue;
    if (now->ops->equal(now, s.v)) continue;
    if (f && !f(r, s.slot, s.v, now)) continue;
    const ModBase* to = r->ops()->follow ? r->ops()->follow(*this, r, s.slot, s.v, now) : nullptr;
    if (!to) return true;
    // The slot reads `to` from now on, with no re-execution.
    ReadSlot& sl = detail::many_of(r)->slots()[s.slot];
    VersionBase* v = visible(*to, &r->start);
    if (!v) throw UsageError("sac::Engine::read_many: follow() named a modifiable with no value at the read's time");
    detach(&sl.link);
    attach_timed(&sl.link, v);
    sl.mod = to;
    ++stats_.reads_followed;
  }
  ++stats_.reads_unaffected;
  return false;
}

void Engine::rerun(ReadNode* r, const ModBase* mp) {
  reruns_.push_back(RerunContext{now_, window_end_});
  tasks_.push_back(Task{TaskKind::FinishRerun, 0, r});
  now_ = &r->start;
  window_end_ = &r->end;
  ++stats_.reads_reexecuted;
  ++stats_.last_reexecuted;
  // A read (each slot) that hangs on a version hangs on the one visible at its time: link_write
  // and undo move readers as versions come and go. Left where it is, it keeps its place
  // among the version's ordered readers, which a re-attachment would lose. One whose
  // version was undone with none before it hangs nowhere, and is attached here.
  if (!mp) {  // a multi-read
    attach_and_invoke_many(r, true);
    return;
  }
  const ModBase& m = *mp;
  const VersionBase* v = visible_or_default(m, &r->start, r->ops()->value);
  if (!v) throw UsageError("sac::Engine::read: the modifiable has no value at the time of this read");
  if (!r->link.rpprev) attach_seen(&r->link, m, v);
  exec_body([&] { r->ops()->invoke(*this, r, v); });
}

void Engine::propagate() {
  require_mutator("propagate");
  in_computation_ = true;
  window_end_ = nullptr;
  const std::uint64_t created0 = stats_.events_created;
  const std::uint64_t undone0 = stats_.events_undone;
  stats_.last_reexecuted = 0;
  try {
    while (!queue_.empty()) {
      QueueAux a;
      ReadNode* r = queue_.pop(&a);
      ++stats_.queue_pops;
      if (!a.forced() && !still_affected(r, a)) continue;
      rerun(r, a.mod());
      drain(0);
    }
  } catch (...) {
    poison();
    throw;
  }
  free_deferred();
  now_ = nullptr;
  in_computation_ = false;
  ++stats_.propagations;
  stats_.last_trace_distance =
      (stats_.events_created - created0) + (stats_.events_undone - undone0);
#ifdef SAC_DEBUG_CHECKS
  // The CMake option: every checker after every propagation, O(trace) each (the engine is
  // left as propagated: a failure is reported, not undone).
  check_invariants();
#endif
}

// ------------------------------------------------------------------ memoization

namespace {

// A matchable record's interval in the trace; an allocation's is its one stamp.
std::pair<Stamp*, Stamp*> interval(ReadNode* r) { return {&r->start, &r->end}; }
std::pair<Stamp*, Stamp*> interval(AllocNode* n) { return {&n->stamp, &n->stamp}; }
std::pair<Stamp*, Stamp*> interval(MemoNode* n) { return {&n->start, &n->end}; }

}  // namespace

template <class N, class Candidates, class Matches>
N* Engine::earliest_match(Candidates&& candidates, Matches&& matches) const {
  N* best = nullptr;
  candidates([&](N* n) {
    const auto [start, end] = interval(n);
    if (matches(n) && in_window(start, end) && (!best || order_.less(start, interval(best).first)))
      best = n;
  });
  return best;
}

ReadNode* Engine::find_read_match(const ModBase& m, std::uint32_t ops_id,
                                  const void* closure) const {
  const detail::ReadOps* ops = detail::read_ops_table[ops_id];
  return earliest_match<ReadNode>(
      [&](auto&& offer) {
        // Slots are offered no match: a multi-read is never memoized.
        auto offer_all = [&](ReaderLink* l) {
          for (; l; l = l->rnext)
            if (!detail::is_slot(l)) offer(owner_of(l));
        };
        for (VersionBase* v = m.newest(); v; v = v->older()) {
          offer_all(v->readers);
          offer_all(v->unordered_readers);
        }
        offer_all(m.default_readers());
      },
      [&](const ReadNode* r) { return r->link.ops_id == ops_id && ops->equal(r, closure); });
}

AllocNode* Engine::find_alloc_match(const detail::AllocOps* ops, std::size_t h,
                                    const void* key) const {
  return earliest_match<AllocNode>(
      [&](auto&& offer) { for (AllocNode* n = allocs_.bucket(h); n; n = n->hnext) offer(n); },
      [&](const AllocNode* n) { return n->ops == ops && ops->key_equal(n, key); });
}

MemoNode* Engine::find_memo_match(const detail::MemoOps* ops, std::size_t h,
                                  const void* closure) const {
  return earliest_match<MemoNode>(
      [&](auto&& offer) { for (MemoNode* n = memos_.bucket(h); n; n = n->hnext) offer(n); },
      [&](const MemoNode* n) { return n->ops == ops && ops->equal(n, closure); });
}

bool Engine::within(const Stamp* from, const Stamp* to, std::uint32_t k) const noexcept {
  const Stamp* s = from->next();
  for (std::uint32_t i = 0; s && i <= k; ++i, s = s->next())
    if (s == to) return true;
  return false;
}

void Engine::memo_hit(Stamp* start, Stamp* end) {
  ++stats_.memo_hits;
  undo_between(now_, start);
  tasks_.push_back(Task{TaskKind::DrainUntil, 0, end});
}

void Engine::reuse_alloc(AllocNode* n) {
  order_.erase(&n->stamp, now_);  // n lies in the window, usually a few stamps after now
  order_.insert_after(now_, &n->stamp, StampKind::Alloc);
  now_ = &n->stamp;
  ++stats_.alloc_reuses;
}

void Engine::link_alloc(AllocNode* n, std::size_t h) {
  order_.insert_after(now_, &n->stamp, StampKind::Alloc);
  now_ = &n->stamp;
  ++stats_.events_created;
  ++stats_.live_events;
  if (!n->ops->key_equal) return;
  if (window_end_) {
    allocs_.insert(n, h, [](const AllocNode* x) { return x->ops->hash(x); });
  } else {
    pending_.push_back(PendingAlloc{n, h});
  }
}

void Engine::index_pending_allocs() {
  if (pending_.empty()) return;
  allocs_.reserve(allocs_.size() + pending_.size(),
                  [](const AllocNode* x) { return x->ops->hash(x); });
  for (std::size_t i = 0; i < pending_.size(); ++i) {
    const PendingAlloc& p = pending_[i];
    allocs_.insert_reserved(p.node, p.hash);
  }
  pending_.clear();
}

void Engine::link_memo(MemoNode* n, std::size_t h) {
  order_.insert_after(now_, &n->start, StampKind::MemoStart);
  now_ = &n->start;
  ++stats_.events_created;
  ++stats_.live_events;
  memos_.insert(n, h, [](const MemoNode* x) { return x->ops->hash(x); });
}

// ------------------------------------------------------------------ undo

void Engine::undo_between(Stamp* a, Stamp* b) {
  if (a->next() == b) return;
  order_.erase_between(a, b, [this](Stamp* s) { undo(s); });
}

void Engine::undo(Stamp* s) {
  visit_record(s, [this]<StampKind K>(Kind<K>, auto* rec) {
    if constexpr (K == StampKind::ReadStart) {
      ReadNode* r = rec;
      ++stats_.events_undone;
      --stats_.live_events;
      if (r->many()) {
        detail::ReadManyHeader* h = detail::many_of(r);
        for (std::uint32_t i = 0; i < h->k; ++i) detach(&h->slots()[i].link);
      } else {
        detach(&r->link);
      }
      if (r->link.qpos != kNotQueued) {
        queue_.remove(r);
        ++stats_.queue_removes;
      }
    } else if constexpr (K == StampKind::ReadEnd || K == StampKind::MemoEnd) {
      destroy(rec);
    } else if constexpr (K == StampKind::Write) {
      VersionBase* v = rec;
      ++stats_.events_undone;
      --stats_.live_events;
      VersionBase* older = v->older();
      ModBase* m = v->mod();
      const bool defaulted = !older && (v->link & VersionBase::kDefaulted);
      unlink_version(m, v);
      if (v->readers || v->unordered_readers) {
        // Its readers see the default now when v was the oldest: on m itself if m has no
        // version left, else on the default made a base version. Either way they are cut
        // off when v held the default value too.
        const VersionBase* seen = older;
        if (defaulted)
          seen = m->default_only() ? v->ops->shared_default() : (older = default_base(*m, true, v->ops));
        const bool same = seen && v->ops->equal(v, seen);
        if (older) {
          // v's readers are all timed after older's: in order, they go first among older's
          // ordered readers. Mostly older is the re-executed write that replaces v and has
          // no readers yet: then v's ordered list becomes older's whole, with no reader
          // touched but the first (none more when the value is the same).
          ReaderLink* rest = older->readers;
          if (!rest && !older->unordered_readers) {
            // Both lists go over whole: those that re-execution attached stay unordered (a
            // cell that the steps of every class read has a thousand readers, and merging
            // them relinked every one: bench/RESULTS.md, "Clusters far below the box's
            // scale").
            if ((older->readers = v->readers)) older->readers->rpprev = &older->readers;
            if ((older->unordered_readers = v->unordered_readers))
              older->unordered_readers->rpprev = &older->unordered_readers;
            if (!same)
              for (ReaderLink* l : {older->readers, older->unordered_readers})
                for (ReaderLink* r = l; r; r = r->rnext) note_change(r, *m, v, seen, seen != nullptr);
          } else {
            for (ReaderLink* r = v->unordered_readers; r; r = r->rnext) order_scratch_.push_back(r);
            link_merged(&older->readers, v->readers, rest);
            if (!same)
              for (ReaderLink* r = older->readers; r != rest; r = r->rnext) note_change(r, *m, v, seen, seen != nullptr);
          }
        } else {
          for (ReaderLink* l : {v->readers, v->unordered_readers})
            for (ReaderLink* r = l; r;) {
              ReaderLink* nx = r->rnext;
              r->rpprev = nullptr;
              r->rnext = nullptr;
              if (defaulted) attach_default(r, *m);
              if (!same) note_change(r, *m, v, seen, seen != nullptr);
              r = nx;
            }
        }
      }
      // A queued read may have seen v, or see it (note_change): freed once propagate() ends.
      if (in_computation_ && !seen_.empty()) dead_versions_.push_back(v);
      else destroy(v);
    } else if constexpr (K == StampKind::Alloc) {
      AllocNode* n = rec;
      ++stats_.events_undone;
      --stats_.live_events;
      if (n->ops->key_equal) allocs_.erase(n, n->ops->hash(n));
      deferred_.push_back(n);  // objects may still be referenced until propagate() ends
    } else if constexpr (K == StampKind::MemoStart) {
      MemoNode* n = rec;
      ++stats_.events_undone;
      --stats_.live_events;
      memos_.erase(n, n->ops->hash(n));
    }
  });
}

void Engine::unlink_version(ModBase* m, VersionBase* v) {
  if (m->newest() == v) {
    if (VersionBase* o = v->older()) m->set_newest(o);
    else m->head_ = (v->link & VersionBase::kDefaulted) ? ModBase::kDefaultOnly : 0;  // it was the only one
    return;
  }
  VersionBase* newer = m->newest();
  while (newer->older() != v) newer = newer->older();
  newer->link = v->link;
}

void Engine::free_deferred() noexcept {
  for (AllocNode* n : deferred_) {
    destroy(n);
  }
  deferred_.clear();
  for (VersionBase* v : dead_versions_) destroy(v);
  dead_versions_.clear();
  seen_.clear();
}

void Engine::destroy_all() noexcept {
  discard_pending();
  // Tear-down without undo semantics: destroy every record once. Valid even when poisoned.
  for (Stamp* s = order_.base()->next(); s;) {
    Stamp* nx = s->next();
    visit_record(s, [this]<StampKind K>(Kind<K>, auto* rec) {
      if constexpr (K == StampKind::ReadStart || K == StampKind::MemoStart) {
        if (!rec->end.linked()) destroy(rec);  // its body threw: no end stamp
      } else if constexpr (K != StampKind::Sentinel && K != StampKind::User) {
        destroy(rec);
      }
    });
    s = nx;
  }
  free_deferred();
  for (VersionBase* v : bases_) {
    destroy(v);
  }
  bases_.clear();
  input_bytes_ = 0;
}

// ------------------------------------------------------------------ introspection

std::size_t Engine::trace_bytes() const {
  return record_bytes() + order_.memory_bytes() + queue_.memory_bytes() +
         allocs_.memory_bytes() + memos_.memory_bytes() +
         deferred_.capacity() * sizeof(AllocNode*) + dead_versions_.capacity() * sizeof(VersionBase*) +
         seen_.capacity() * sizeof(Seen);
}

MemoryBreakdown Engine::memory_breakdown() const {
  if (in_computation_) throw UsageError("sac::Engine::memory_breakdown: not inside the computation");
  MemoryBreakdown b;
  // A record of `size` bytes (its ops->size, i.e. sizeof) is a pool block of the size rounded
  // to the grain; the fixed `header` and the `key` come first, the rest is the payload.
  auto block_of = [](std::size_t size) {
    constexpr std::size_t g = detail::Pool::kGrain;
    return size < g ? g : (size + g - 1) & ~(g - 1);
  };
  auto add = [&](RecordBytes& kind, std::size_t size, std::size_t header, std::size_t key) {
    const std::size_t block = block_of(size);
    if (block > detail::Pool::kMaxSmall) b.pool_large += block;
    b.size_class_rounding += block - size;
    ++kind.count;
    kind.header += header;
    kind.key += key;
    kind.payload += block - header - key;
  };
  std::map<std::size_t, std::uint64_t> read_sizes;  // a few closure types: a few sizes
  // Each record once, at its first stamp (a read's or memo entry's end stamp is in the
  // same record).
  for (const Stamp* s = order_.base()->next(); s; s = s->next()) {
    visit_record(s, [&]<StampKind K>(Kind<K>, auto* rec) {
      if constexpr (K == StampKind::ReadStart) {
        const std::size_t size = read_size(rec);
        const std::size_t header =
            rec->many() ? detail::ReadManyHeader::closure_offset(detail::many_of(rec)->k) : sizeof(ReadNode);
        add(b.reads, size, header, 0);
        ++read_sizes[block_of(size)];
      } else if constexpr (K == StampKind::Write) {
        add(b.versions, rec->ops->size, sizeof(VersionBase), 0);
      } else if constexpr (K == StampKind::Alloc) {
        if (rec->ops->key_equal)
          add(b.keyed_allocs, rec->ops->size, sizeof(AllocNode),
              reinterpret_cast<const detail::KeyedAllocOps*>(rec->ops)->key_bytes);
        else
          add(b.plain_allocs, rec->ops->size, sizeof(AllocNode), 0);
      } else if constexpr (K == StampKind::MemoStart) {
        add(b.memos, rec->ops->size, sizeof(MemoNode), 0);
      }
    });
  }
  for (const VersionBase* v : bases_) add(b.inputs, v->ops->size, sizeof(VersionBase), 0);
  b.read_sizes.assign(read_sizes.begin(), read_sizes.end());
  b.unaccounted = static_cast<std::int64_t>(record_bytes()) - static_cast<std::int64_t>(b.records());
  b.order_groups = order_.group_count();
  b.order_bytes = order_.memory_bytes();
  b.queue_bytes = queue_.memory_bytes();
  b.alloc_table_bytes = allocs_.memory_bytes();
  b.memo_table_bytes = memos_.memory_bytes();
  b.deferred_bytes = deferred_.capacity() * sizeof(AllocNode*) + dead_versions_.capacity() * sizeof(VersionBase*) +
                     seen_.capacity() * sizeof(Seen);
  b.engine_vectors = bases_.capacity() * sizeof(VersionBase*) + tasks_.capacity() * sizeof(Task) +
                     reruns_.capacity() * sizeof(RerunContext) + issued_.capacity() * sizeof(Task) +
                     pending_.directory_bytes();
  b.pool_reserved = pool_.reserved_bytes();
  return b;
}

void Engine::check_invariants() const {
  if (in_computation_) throw UsageError("sac::Engine::check_invariants: not inside the computation");
  auto fail = [](const std::string& what) { throw InvariantError("Engine trace: " + what); };
  order_.check_invariants();
  queue_.check_invariants();
  if (!queue_.empty()) fail("queue not empty outside propagate()");
  if (!deferred_.empty()) fail("deferred frees left after propagate()");
  if (!dead_versions_.empty() || !seen_.empty()) fail("undone versions or seen lists left after propagate()");

  // Walk the trace: nesting, per-record checks, counts.
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
        if (!r->end.linked()) fail("read without end stamp");
        if (!order_.less(&r->start, &r->end)) fail("read end not after start");
        // Attachment to the version visible at its start is checked below, from the
        // version side (a read record does not name its modifiable; scanning the visible
        // version's readers here would also be quadratic in a modifiable's fan-out).
        if (r->link.qpos != kNotQueued) fail("read still queued");
        if (r->many()) {
          // A multi-read hangs on versions through its slots only; each slot is checked
          // below, with its modifiable, like a read.
          const detail::ReadManyHeader* h = detail::many_of(r);
          if (r->link.rpprev) fail("a multi-read's own link is attached");
          if (h->k == 0 || h->k > detail::kMaxReadMany) fail("a multi-read with a bad slot count");
          for (std::uint32_t i = 0; i < h->k; ++i) {
            const ReaderLink* l = &h->slots()[i].link;
            if (!detail::is_slot(l) || l->qpos != i || owner_of(l) != r) fail("a multi-read's slot is malformed");
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
          fail("read intervals not well nested");
        stack.pop_back();
      } else if constexpr (K == StampKind::Write) {
        const VersionBase* v = rec;
        ++events;
        mods.insert(v->mod());
        bool found = false;
        for (const VersionBase* x = v->mod()->newest(); x; x = x->older())
          if (x == v) found = true;
        if (!found) fail("write not in its modifiable's version list");
      } else if constexpr (K == StampKind::Alloc) {
        ++events;
        if (rec->ops->key_equal) ++nkeyed;
      } else if constexpr (K == StampKind::MemoStart) {
        const MemoNode* n = rec;
        ++events;
        ++nmemo;
        if (!n->end.linked() ||
            !order_.less(&n->start, &n->end))
          fail("memo entry without a proper end stamp");
        stack.push_back({&n->end, true});
      } else if constexpr (K == StampKind::MemoEnd) {
        if (stack.empty() || stack.back().close != s || !stack.back().is_memo)
          fail("memo intervals not well nested");
        stack.pop_back();
      } else {
        fail("unexpected stamp kind");
      }
    });
  }
  if (!stack.empty()) fail("unclosed intervals at the end of the trace");
  if (events != stats_.live_events) fail("live event count mismatch");
  if (nkeyed != allocs_.size()) fail("allocation table size mismatch");
  if (nmemo != memos_.size()) fail("memo table size mismatch");

  // Versions of every written or read modifiable: strictly decreasing time, base last,
  // readers between this version and the next newer one (so each reader hangs on the version
  // visible at its time), and every reader a live read of the trace, each exactly once.
  // A live read hangs on a computation's version, a base version or (below) a default with
  // no version; so these cover every read.
  for (const VersionBase* b : bases_) mods.insert(b->mod());
  std::size_t attached = 0;
  mods.for_each([&](const void* mod) {
    const auto* m = static_cast<const ModBase*>(mod);
    const VersionBase* newer = nullptr;
    for (const VersionBase* v = m->newest(); v; v = v->older()) {
      if (v->mod() != m) fail("version chain does not end at its modifiable");
      if (v->is_base()) {
        if (v->older()) fail("base version is not the oldest");
      } else {
        if (!v->stamp.linked()) fail("version with unlinked stamp");
        if (newer && !order_.less(&v->stamp, &newer->stamp)) fail("versions out of order");
      }
      for (int list = 0; list < 2; ++list) {
        const ReaderLink* const* back = list == 0 ? &v->readers : &v->unordered_readers;
        const Stamp* last_ordered = nullptr;  // the time of the last ordered reader seen
        for (const ReaderLink* r = *back; r; back = &r->rnext, r = r->rnext) {
          if (r->rpprev != back) fail("a version's reader list has a broken back link");
          // Membership first: only then may r be decoded (a slot's owner from its index).
          if (!reads.contains(r)) fail("a version's reader is not a live read of the trace");
          if (detail::is_slot(r) && reinterpret_cast<const ReadSlot*>(r)->mod != m)
            fail("a multi-read's slot hangs on another modifiable's version");
          const Stamp* t = &owner_of(r)->start;
          if (!v->is_base() && !order_.less(&v->stamp, t)) fail("reader before its version");
          if (newer && !order_.less(t, &newer->stamp)) fail("reader after the next version");
          if (r->unordered != list)
            fail("a version's reader is on the other list than its flag says");
          if (list == 0) {
            if (last_ordered && order_.less(last_ordered, t))
              fail("a version's ordered readers are not newest first");
            last_ordered = t;
          }
          ++attached;
        }
      }
      newer = v;
    }
  });
  // Reads of a default with no version hang on the modifiable; it has no version then.
  for (const ModBase* m : default_mods) {
    if (!m->default_only()) fail("a read hangs on the default of a modifiable that has versions");
    const ReaderLink* first = m->default_readers();
    if (!first || default_head(first) != m) fail("a modifiable's default readers do not start at its head");
    for (const ReaderLink* r = first; r; r = r->rnext) {
      if (r->rnext && r->rnext->rpprev != &r->rnext) fail("a default reader list has a broken back link");
      if (!reads.contains(r)) fail("a default reader is not a live read of the trace");
      if (detail::is_slot(r) && reinterpret_cast<const ReadSlot*>(r)->mod != m)
        fail("a multi-read's slot hangs on another modifiable's default");
      ++attached;
    }
  }
  if (attached != reads.size()) fail("read not attached to the version visible at its time");
  allocs_.check_invariants("allocation table", [](const AllocNode* n) { return n->ops->hash(n); },
                           [&](const AllocNode* n) {
                             if (!n->stamp.linked()) fail("allocation table holds an undone record");
                           });
  memos_.check_invariants("memo table", [](const MemoNode* n) { return n->ops->hash(n); },
                          [&](const MemoNode* n) {
                            if (!n->start.linked()) fail("memo table holds an undone record");
                          });
}

void Engine::dump_dot(std::ostream& os) const {
  // Trace tree: reads and memo entries are interior nodes, writes and allocations leaves.
  os << "digraph trace {\n  node [fontname=\"monospace\", fontsize=10];\n  root [label=\"run\"];\n";
  std::vector<std::pair<std::string, const Stamp*>> stack{{"root", nullptr}};
  std::unordered_map<const ModBase*, std::string> mod_names;
  auto mod_name = [&](const ModBase* m) {
    auto it = mod_names.find(m);
    if (it != mod_names.end()) return it->second;
    std::string n = "m" + std::to_string(mod_names.size());
    mod_names.emplace(m, n);
    os << "  " << n << " [shape=box, label=\"" << n << "\"];\n";
    return n;
  };
  // A read does not name its modifiable: find it from the versions' reader lists.
  std::unordered_multimap<const ReadNode*, const ModBase*> read_mod;  // a multi-read: k
  const auto note_list = [&](const ReaderLink* l, const ModBase* m) {
    for (; l; l = l->rnext) read_mod.emplace(owner_of(l), m);
  };
  const auto note_readers = [&](const VersionBase* v) {
    note_list(v->readers, v->mod());
    note_list(v->unordered_readers, v->mod());
  };
  for (const VersionBase* b : bases_) note_readers(b);
  for (const Stamp* s = order_.base()->next(); s; s = s->next()) {
    if (s->kind() == StampKind::Write) note_readers(detail::version_of(const_cast<Stamp*>(s)));
    if (s->kind() == StampKind::ReadStart) {
      ReadNode* r = detail::read_of_start(const_cast<Stamp*>(s));
      const auto note_default = [&](const ReaderLink* l) {
        if (const ModBase* m = default_head(l)) note_list(m->default_readers(), m);
      };
      if (r->many())
        for (std::uint32_t i = 0; i < detail::many_of(r)->k; ++i) note_default(&detail::many_of(r)->slots()[i].link);
      else
        note_default(&r->link);
    }
  }
  std::size_t id = 0;
  for (const Stamp* s = order_.base()->next(); s; s = s->next()) {
    std::string name = "e" + std::to_string(id++);
    const std::string& parent = stack.back().first;
    visit_record(s, [&]<StampKind K>(Kind<K>, auto* rec) {
      if constexpr (K == StampKind::ReadStart) {
        os << "  " << name << " [label=\"read\"];\n  " << parent << " -> " << name << ";\n";
        const auto [lo, hi] = read_mod.equal_range(rec);
        for (auto it = lo; it != hi; ++it)
          os << "  " << mod_name(it->second) << " -> " << name << " [style=dashed];\n";
        stack.push_back({name, &rec->end});
      } else if constexpr (K == StampKind::Write) {
        os << "  " << name << " [shape=diamond, label=\"write\"];\n  " << parent << " -> " << name
           << ";\n  " << name << " -> " << mod_name(rec->mod()) << " [style=dashed];\n";
      } else if constexpr (K == StampKind::Alloc) {
        os << "  " << name << " [shape=note, label=\"alloc\"];\n  " << parent << " -> " << name << ";\n";
      } else if constexpr (K == StampKind::MemoStart) {
        os << "  " << name << " [shape=octagon, label=\"memo\"];\n  " << parent << " -> " << name << ";\n";
        stack.push_back({name, &rec->end});
      }
    });
    while (stack.size() > 1 && stack.back().second == s) stack.pop_back();
  }
  os << "}\n";
}

}  // namespace sac
