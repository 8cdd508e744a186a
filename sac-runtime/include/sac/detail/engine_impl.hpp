// sac/detail/engine_impl.hpp — the template bodies of sac::Engine.
//
// Purpose: the definitions of the member templates declared in sac/engine.hpp, which
// includes this file at its end (include sac/engine.hpp, never this file): the facade
// stays readable as a list of declarations, and every body the compiler must see to
// instantiate is here, exactly as if it were written in the class.
// Invariants: those of sac/engine.hpp (I1-I7); each body leaves them as it found them.
// Complexity: see each declaration in sac/engine.hpp.
// Paper: docs/DESIGN.md, "The runtime".
#pragma once

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <new>
#include <span>
#include <type_traits>
#include <utility>

#include "sac/engine.hpp"

namespace sac {
// ------------------------------------------------------------------ records

template <class N, class... A>
N* Engine::construct(A&&... args) {
  static_assert(alignof(N) <= detail::Pool::kGrain, "record over-aligned");
  void* mem = allocate(sizeof(N));
  try {
    return new (mem) N(std::forward<A>(args)...);
  } catch (...) {
    deallocate(mem, sizeof(N));
    throw;
  }
}

template <class Rec>
void Engine::destroy(Rec* r) noexcept {
  if constexpr (std::is_base_of_v<detail::ReadNode, Rec>) {
    const std::size_t n = read_size(r);
    r->ops()->destroy(r);
    deallocate(r, n);
  } else {
    const auto* ops = r->ops();
    ops->destroy(r);
    deallocate(r, ops->size);
  }
}

// ------------------------------------------------------------------ the API


template <class T, class U>
void Engine::set(Mod<T>& m, U&& value) {
  require_mutator("set");
  using V = detail::Version<T>;
  V* v = construct<V>(std::forward<U>(value));
  v->set_ops_id(detail::VersionOpsFor<T>::id());
  // set_base compares the values first (VersionOps::equal): this only moves.
  set_base(m, v, [](detail::VersionBase* old_base, detail::VersionBase* fresh) {
    auto* o = static_cast<V*>(old_base);
    auto* f = static_cast<V*>(fresh);
    if constexpr (std::is_swappable_v<T>) {
      using std::swap;
      swap(o->value, f->value);
      return true;
    } else {
      o->value.~T();
      new (&o->value) T(std::move(f->value));
      return false;
    }
  });
}

template <class T, class U>
void Engine::init(Mod<T>& m, U&& value) {
  if (m.written()) throw UsageError("sac::Engine::init: the modifiable is already written");
  using V = detail::Version<T>;
  V* v = construct<V>(std::forward<U>(value));
  v->set_ops_id(detail::VersionOpsFor<T>::id());
  set_base(m, v, nullptr);  // no base yet, so nothing to compare with
}

template <class T>
void Engine::init_default(Mod<T>& m) {
  static_assert(std::is_default_constructible_v<T>, "init_default needs a default-constructible T");
  if (m.written()) throw UsageError("sac::Engine::init_default: the modifiable is already written");
  m.head_ = ModBase::kDefaultOnly;
}

template <class F>
void Engine::run(F&& f) {
  require_mutator("run");
  in_computation_ = true;
  now_ = tail_;
  window_end_ = nullptr;
  try {
    exec_body([&] { detail::call_thunk(f, *this); });
    drain(0);
  } catch (...) {
    poison();
    throw;
  }
  index_pending_allocs();
  order_.trim();
  tail_ = now_;
  now_ = nullptr;
  in_computation_ = false;
}

template <class T, class F>
void Engine::read(const Mod<T>& m, F&& body) {
  using Fn = std::decay_t<F>;
  using N = detail::ReadNodeT<Fn>;
  require_computation("read");
  N* r = construct<N>(std::forward<F>(body));
  r->link.issued_mod = &m;
  r->set_ops_id(detail::ReadOpsFor<T, Fn>::id());
  r->set_qpos(detail::kNotQueued);
  issue(TaskKind::ExecRead, r);
}

template <class T, class F>
void Engine::read_many(std::span<const Mod<T>* const> mods, F&& body) {
  using Fn = std::decay_t<F>;
  using H = detail::ReadManyHeader;
  static_assert(alignof(Fn) <= detail::Pool::kGrain, "closure over-aligned");
  require_computation("read_many");
  const std::size_t k = mods.size();
  if (k == 0 || k > detail::kMaxReadMany) [[unlikely]]
    throw_read_many_size();
  const std::size_t bytes = H::closure_offset(k) + sizeof(Fn);
  char* mem = static_cast<char*>(allocate(bytes));
  try {
    new (mem + H::closure_offset(k)) Fn(std::forward<F>(body));
  } catch (...) {
    deallocate(mem, bytes);
    throw;
  }
  H* h = new (mem) H{};
  h->set_k(static_cast<std::uint32_t>(k));
  h->read.set_ops_id(detail::ReadManyOpsFor<T, Fn>::id());
  h->read.set_qpos(detail::kNotQueued);
  detail::ReadSlot* slots = h->slots();
  for (std::size_t i = 0; i < k; ++i) {
    detail::ReadSlot* sl = new (&slots[i]) detail::ReadSlot{};
    sl->link.back = detail::ReaderLink::kSlotBit;
    sl->link.set_tag(static_cast<std::uint16_t>(i));
    sl->mod = mods[i];
  }
  issue(TaskKind::ExecReadMany, &h->read);
}

template <class T>
const T& Engine::current(const Mod<T>& m) {
  require_computation("current");
  flush_if_pending();  // calls issued earlier in this body come first in program order
  const detail::VersionBase* v = visible_or_default(m, now_, &detail::VersionOpsFor<T>::ops);
  if (!v) throw UsageError("sac::Engine::current: the modifiable has no value now");
  return static_cast<const detail::Version<T>*>(v)->value;
}

template <class T>
const T* Engine::peek(const Mod<T>& m) {
  require_computation("peek");
  flush_if_pending();  // as current(): calls issued earlier in this body come first
  const detail::VersionBase* v = visible(m, now_);
  return v ? &static_cast<const detail::Version<T>*>(v)->value : nullptr;
}

template <class T, class F>
void Engine::memo_read(const Mod<T>& m, F&& body) {
  using Fn = std::decay_t<F>;
  static_assert(std::equality_comparable<Fn>,
                "memo_read needs an equality-comparable closure: use sac::fn<f>(args...)");
  read(m, std::forward<F>(body));
  tasks_.back().kind = TaskKind::ExecMemoRead;  // matched against the old trace when run
}

template <class T, class U>
void Engine::write(Mod<T>& m, U&& value) {
  using V = detail::Version<T>;
  require_computation("write");
  flush_if_pending();
  V* v = construct<V>(std::forward<U>(value));
  v->set_ops_id(detail::VersionOpsFor<T>::id());
  link_write(m, v);
}

template <class T, class K, class... A>
T* Engine::alloc(const K& key, A&&... args) {
  static_assert(Hashable<K> && std::equality_comparable<K>,
                "alloc keys must be hashable (sac::Hash) and equality comparable");
  using N = detail::AllocNodeT<T, K>;
  require_computation("alloc");
  flush_if_pending();
  const std::uint16_t ops_id = detail::AllocOpsFor<T, K>::id();
  const std::size_t h = Hash<K>{}(key);
  if (window_end_) {
    if (detail::AllocNode* hit = find_alloc_match(ops_id, h, &key)) {
      reuse_alloc(hit);
      return &static_cast<N*>(hit)->object;
    }
  }
  N* n = construct<N>(key, std::forward<A>(args)...);
  n->set_ops_id(ops_id);
  link_alloc(n, h);
  return &n->object;
}

template <class T, class... A>
T* Engine::make(A&&... args) {
  using N = detail::PlainAllocNodeT<T>;
  require_computation("make");
  flush_if_pending();
  N* n = construct<N>(std::forward<A>(args)...);
  n->set_ops_id(detail::PlainAllocOpsFor<T>::id());
  link_alloc(n, 0);
  return &n->object;
}

template <class F>
void Engine::memo(F&& f) {
  memo_near(detail::kAnyDistance, std::forward<F>(f));
}

template <class F>
void Engine::memo_near(std::uint32_t max_skip, F&& f) {
  using Fn = std::decay_t<F>;
  using N = detail::MemoNodeT<Fn>;
  static_assert(std::equality_comparable<Fn> && Hashable<Fn>,
                "memo needs an equality-comparable, hashable closure: use sac::fn<f>(args...)");
  require_computation("memo");
  N* n = construct<N>(std::forward<F>(f));
  n->set_ops_id(detail::MemoOpsFor<Fn>::id());
  issue(TaskKind::ExecMemo, n, max_skip);
}
template <class T, class F>
void Engine::read_many(std::initializer_list<const Mod<T>*> mods, F&& body) {
  read_many(std::span<const Mod<T>* const>(mods.begin(), mods.size()), std::forward<F>(body));
}

// ------------------------------------------------------------------ context

template <class T>
void Engine::set_context(T* ctx) noexcept {
  context_ = ctx;
  context_type_ = &detail::kTypeTag<T>;
}

template <class T>
T* Engine::context() const {
  if (context_type_ != &detail::kTypeTag<T>) throw_bad_context();
  return static_cast<T*>(context_);
}

template <class T>
const T* Engine::At::value(const Mod<T>& m) const {
  const detail::VersionBase* v = rt_->visible(m, &r_->start);
  return v ? &static_cast<const detail::Version<T>*>(v)->value : nullptr;
}

// ------------------------------------------------------------------ the trampoline

// Inline: every from-scratch allocation and read passes here, and a call's register saves
// cost as much as their bodies.
inline void Engine::link_alloc(detail::AllocNode* n, std::size_t h) {
  order_.insert_after(now_, &n->stamp, detail::StampKind::Alloc);
  now_ = &n->stamp;
  ++stats_.events_created;
  ++stats_.live_events;
  if (!n->ops()->key_equal) return;
  if (window_end_) {
    allocs_.insert(n, h, [](const detail::AllocNode* x) { return x->ops()->hash(x); });
  } else {
    pending_.push_back(PendingAlloc{n, h});
  }
}

inline void Engine::push_close(detail::Stamp* end, TaskKind kind, void* node) {
  // A call that was the last one issued by its parent closes right before the parent does:
  // chain it onto the parent's pending close (through the unlinked end stamp's link field)
  // instead of stacking one task per level, so a chain of a million tail reads needs one task.
  if (tasks_.size() > close_floor_ && (tasks_.back().kind == TaskKind::CloseRead ||
                                       tasks_.back().kind == TaskKind::CloseMemo)) {
    Task& top = tasks_.back();
    end->link = (end->link & detail::Stamp::kAuxMask) | reinterpret_cast<std::uintptr_t>(top.node) |
                (top.kind == TaskKind::CloseMemo ? std::uintptr_t{1} : 0);
    top = Task{kind, 0, node};
    return;
  }
  end->link &= detail::Stamp::kAuxMask;
  tasks_.push_back(Task{kind, 0, node});
}

template <class Body>
void Engine::exec_body(Body&& body) {
  // Calls issued by this body are pushed on the trampoline's stack above body_mark_, and
  // reversed once it returns so that they run in issue order. One call, the usual case,
  // needs nothing: it is already where it runs next.
  const std::size_t saved = body_mark_;
  body_mark_ = tasks_.size();
  body();
  if (tasks_.size() - body_mark_ > 1)
    std::reverse(tasks_.begin() + static_cast<std::ptrdiff_t>(body_mark_), tasks_.end());
  body_mark_ = saved;
}

}  // namespace sac
