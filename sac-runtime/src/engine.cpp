// engine.cpp — the engine's hot, non-template machinery.
//
// Purpose: versions (visibility, linking a write, moving readers), the trampoline, change
// propagation, memo matching and undo. They stay in one translation unit so that the
// compiler can inline across them without LTO; the cold code is elsewhere (the checker in
// engine_check.cpp, the introspection in engine_introspection.cpp, the stamp decoder in
// records.hpp).
// Invariants: those numbered in sac/engine.hpp (I1 ...), which every function here
// preserves between the engine's public calls.
// Complexity: see sac/engine.hpp.
// Paper: docs/DESIGN.md, "Change propagation".
#include "sac/engine.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "records.hpp"

namespace sac {

using detail::AllocNode;
using detail::Stamp;
using detail::StampKind;
using detail::attach;
using detail::attach_timed;
using detail::attach_unordered;
using detail::default_head;
using detail::detach;
using detail::kNotQueued;
using detail::Kind;
using detail::MemoNode;
using detail::ReaderLink;
using detail::ReadNode;
using detail::ReadSlot;
using detail::VersionBase;
using detail::owner_of;
using detail::visit_record;

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

const VersionBase* Engine::visible_or_default_slow(const ModBase& m, const Stamp* t,
                                                  const detail::VersionOps* ops) {
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
    readers->set_rpprev(&base->unordered_readers);
    for (ReaderLink* r = readers; r; r = r->rnext) r->set_unordered(true);
  }
  return base;
}

void Engine::link_write(ModBase& m, VersionBase* v) {
  // Readers of the default and a version: the default needs its own version now.
  if (m.default_readers()) default_base(m, true, v->ops());
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
    const bool same = v->ops()->equal(v, older);
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
    if (stop) stop->set_rpprev(&older->readers);
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
    y->set_rpprev(at);
    y->rnext = x;
    *at = y;
    if (x) x->set_rpprev(&y->rnext);
    y->set_unordered(false);
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
    x->set_rpprev(at);
    *at = x;
    at = &x->rnext;
    x->set_unordered(false);
    ++stats_.readers_relinked;
  }
  xs.clear();
  if (run) {  // what is left of the run is in order and linked: it goes in whole
    run->set_rpprev(at);
    *at = run;
    if (!tail) return;  // the run ends in null already
    for (; run->rnext; run = run->rnext) ++stats_.readers_relinked;
    at = &run->rnext;
  }
  *at = tail;
  if (tail) tail->set_rpprev(at);
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
    if (ops->value != v->ops()) continue;
    if (!ops->invoke_many) return false;  // a plain read: of m or not, it does not say
    detail::ReadManyHeader* h = detail::many_of(r);
    for (std::uint32_t i = 0; i < h->k(); ++i)
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
  if (assign && m.default_readers()) default_base(m, true, fresh->ops());
  VersionBase* last = nullptr;
  for (VersionBase* v = m.newest(); v; v = v->older()) last = v;
  if (VersionBase* base = last && last->is_base() ? last : nullptr) {
    // An equal value changes nothing. Otherwise the base takes the new value and, when the
    // values were swapped, fresh keeps the old one for the readers that saw it.
    if (!base->ops()->equal(base, fresh)) {
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
  fresh->stamp.reset(nullptr, StampKind::Sentinel);
  fresh->stamp.label = static_cast<std::uint32_t>(bases_.size());
  fresh->link = last ? last->link : end_link(m, m.default_only());
  fresh->readers = nullptr;
  fresh->unordered_readers = nullptr;
  bases_.push_back(fresh);
  input_bytes_ += (fresh->ops()->size + 7) & ~std::size_t{7};
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
  input_bytes_ -= (v->ops()->size + 7) & ~std::size_t{7};
  destroy(v);
}

// ------------------------------------------------------------------ the trampoline

void Engine::flush() {
  // A write/alloc/make follows calls this body issued: run them first, so that events keep
  // program order.
  const std::size_t floor = body_mark_;
  std::reverse(tasks_.begin() + static_cast<std::ptrdiff_t>(floor), tasks_.end());
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
  for (std::uint32_t i = 0; i < h->k(); ++i) {
    const VersionBase* v = visible_or_default(*slots[i].mod, &r->start, ops);
    if (!v) throw UsageError("sac::Engine::read_many: a modifiable has no value at the time of this read");
    if (!attached || !slots[i].link.attached()) attach_seen(&slots[i].link, *slots[i].mod, v);
    vs[i] = v;
  }
  exec_body([&] { r->ops()->invoke_many(*this, r, vs); });
}

void Engine::throw_read_many_size() {
  throw UsageError("sac::Engine::read_many: reads 1 to 16 modifiables");
}

void Engine::close_chain(TaskKind kind, void* node) {
  while (node) {
    Stamp* end = kind == TaskKind::CloseRead ? &static_cast<ReadNode*>(node)->end
                                             : &static_cast<MemoNode*>(node)->end;
    const std::uintptr_t next = end->link & ~Stamp::kAuxMask;
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
        if (ReadNode* hit = find_read_match(*r->link.issued_mod, r->ops_id(), closure_of(r))) {
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
      const detail::MemoOps* ops = n->ops();
      const std::size_t h = ops->hash(n);
      if (window_end_) {
        MemoNode* hit = find_memo_match(n->start.aux(), h, reinterpret_cast<const MemoNode*>(n) + 1);
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
      exec_body([&] { ops->invoke(*this, n); });
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
  tasks_.clear();
  reruns_.clear();
  body_mark_ = 0;
  close_floor_ = 0;
  pending_.clear();  // the allocations are in the trace; destroy_all frees them there
}

bool Engine::note_change(ReaderLink* l, const ModBase& m, const VersionBase* before, const VersionBase* after,
                         bool lazy) {
  ReadNode* r = owner_of(l);
  if (r->qpos() != kNotQueued) {  // queued already (a multi-read with several changed slots)
    QueueAux& a = queue_.aux(r);
    if (a.forced()) return false;  // a plain read's always is: it re-runs
    if (!lazy) {
      a.force();
      return false;
    }
    const std::uint32_t slot = l->tag();  // a listed read is a multi-read
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
  const std::uint32_t slot = detail::is_slot(l) ? l->tag() : 0;
  const auto f = r->ops()->affected;
  if (f && after && !f(*this, r, slot, before, after)) return false;  // no `after`: a default, re-run
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
    if (now->ops()->equal(now, s.v)) continue;
    if (f && !f(*this, r, s.slot, s.v, now)) continue;
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
  if (!r->link.attached()) attach_seen(&r->link, m, v);
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
      [&](const ReadNode* r) { return r->ops_id() == ops_id && ops->equal(r, closure); });
}

// A candidate's type is told by the ops number in its stamp, which is already loaded, not
// by its table.
AllocNode* Engine::find_alloc_match(std::uint16_t ops_id, std::size_t h, const void* key) const {
  const detail::AllocOps* ops = detail::alloc_ops_table[ops_id];
  return earliest_match<AllocNode>(
      [&](auto&& offer) { for (AllocNode* n = allocs_.bucket(h); n; n = n->hnext) offer(n); },
      [&](const AllocNode* n) { return n->stamp.aux() == ops_id && ops->key_equal(n, key); });
}

MemoNode* Engine::find_memo_match(std::uint16_t ops_id, std::size_t h, const void* closure) const {
  const detail::MemoOps* ops = detail::memo_ops_table[ops_id];
  return earliest_match<MemoNode>(
      [&](auto&& offer) { for (MemoNode* n = memos_.bucket(h); n; n = n->hnext) offer(n); },
      [&](const MemoNode* n) { return n->start.aux() == ops_id && ops->equal(n, closure); });
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

void Engine::index_pending_allocs() {
  if (pending_.empty()) return;
  allocs_.reserve(allocs_.size() + pending_.size(),
                  [](const AllocNode* x) { return x->ops()->hash(x); });
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
  memos_.insert(n, h, [](const MemoNode* x) { return x->ops()->hash(x); });
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
        for (std::uint32_t i = 0; i < h->k(); ++i) detach(&h->slots()[i].link);
      } else {
        detach(&r->link);
      }
      if (r->qpos() != kNotQueued) {
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
          seen = m->default_only() ? v->ops()->shared_default() : (older = default_base(*m, true, v->ops()));
        const bool same = seen && v->ops()->equal(v, seen);
        if (older) {
          // v's readers are all timed after older's: in order, they go first among older's
          // ordered readers. Mostly older is the re-executed write that replaces v and has
          // no readers yet: then v's ordered list becomes older's whole, with no reader
          // touched but the first (none more when the value is the same).
          ReaderLink* rest = older->readers;
          if (!rest && !older->unordered_readers) {
            // Both lists go over whole: those that re-execution attached stay unordered, as
            // merging them into order would relink every reader of a cell that many reads
            // share (docs/DESIGN.md, "Change propagation").
            if ((older->readers = v->readers)) older->readers->set_rpprev(&older->readers);
            if ((older->unordered_readers = v->unordered_readers))
              older->unordered_readers->set_rpprev(&older->unordered_readers);
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
              r->set_prev_raw(0);
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
      if (n->ops()->key_equal) allocs_.erase(n, n->ops()->hash(n));
      deferred_.push_back(n);  // objects may still be referenced until propagate() ends
    } else if constexpr (K == StampKind::MemoStart) {
      MemoNode* n = rec;
      ++stats_.events_undone;
      --stats_.live_events;
      memos_.erase(n, n->ops()->hash(n));
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

}  // namespace sac
