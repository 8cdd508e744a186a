// sac/detail/ops.hpp — the static ops tables of the trace records, one per instantiated type.
//
// Purpose: a record stores one pointer to its type's ops (destroy, compare, hash, invoke, size;
// see trace_nodes.hpp), or for a read its number, instead of a vtable; the Engine's
// templates fill it from the tables here. Also the StampQueue traits of a read and the calls
// of a body with or without the Engine.
// Invariants: ops.size == sizeof(the record type); a table's equal/key_equal/hash are only
// called on records that carry that same table, so the casts are exact; an ops table with
// key_equal set is the `ops` member of a KeyedAllocOps.
// Complexity: every entry O(1) plus the user's operator==, Hash and body.
// Paper: docs/DESIGN.md, "The runtime".
#pragma once

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <new>
#include <span>
#include <type_traits>

#include "sac/detail/order_list.hpp"
#include "sac/detail/trace_nodes.hpp"
#include "sac/hash.hpp"
#include "sac/read_slots.hpp"

namespace sac::detail {

/// The most modifiables one Engine::read_many may read.
inline constexpr std::size_t kMaxReadMany = 16;

/// A per-type object whose address names the type (Engine::context's check).
template <class T>
inline char kTypeTag = 0;  // not const: distinct objects, never merged

struct ReadQueueTraits {
  static const Stamp* stamp(const ReadNode* r) { return &r->start; }
  static std::uint32_t pos(const ReadNode* r) { return r->qpos(); }
  static void set_pos(ReadNode* r, std::uint32_t p) { r->set_qpos(p); }
};

template <class F, class T>
void call_body(F& f, Engine& rt, const T& v) {
  if constexpr (std::is_invocable_v<F&, Engine&, const T&>) f(rt, v);
  else f(v);
}

template <class F>
void call_thunk(F& f, Engine& rt) {
  if constexpr (std::is_invocable_v<F&, Engine&>) f(rt);
  else f();
}

template <class T>
struct VersionOpsFor {
  static void destroy(VersionBase* v) noexcept { static_cast<Version<T>*>(v)->~Version<T>(); }
  static bool equal(const VersionBase* a, const VersionBase* b) {
    if constexpr (std::equality_comparable<T>)
      return static_cast<const Version<T>*>(a)->value == static_cast<const Version<T>*>(b)->value;
    else
      return false;  // no cut-off without operator==
  }
  static VersionBase* make_default(void* mem);
  static const VersionBase* shared_default();
  static constexpr VersionOps ops{&destroy, &equal,
                                  std::is_default_constructible_v<T> ? &make_default : nullptr,
                                  std::is_default_constructible_v<T> ? &shared_default : nullptr,
                                  sizeof(Version<T>)};
  static std::uint16_t id() {
    static const std::uint16_t i = register_version_ops(&ops);
    return i;
  }
};

template <class T>
VersionBase* VersionOpsFor<T>::make_default(void* mem) {
  if constexpr (std::is_default_constructible_v<T>) {
    auto* v = new (mem) Version<T>();
    v->set_ops_id(id());
    return v;
  } else {
    return nullptr;
  }
}

template <class T>
const VersionBase* VersionOpsFor<T>::shared_default() {
  if constexpr (std::is_default_constructible_v<T>) {
    struct Holder {
      Version<T> v;
      Holder() { v.set_ops_id(id()); }
    };
    static const Holder h;
    return &h.v;
  } else {
    return nullptr;
  }
}

template <class T, class F>
struct ReadOpsFor {
  static void invoke(Engine& rt, ReadNode* r, const VersionBase* v) {
    call_body(static_cast<ReadNodeT<F>*>(r)->fn, rt, static_cast<const Version<T>*>(v)->value);
  }
  static void destroy(ReadNode* r) noexcept { static_cast<ReadNodeT<F>*>(r)->~ReadNodeT<F>(); }
  static bool equal(const ReadNode* r, const void* c) {
    if constexpr (std::equality_comparable<F>)
      return static_cast<const ReadNodeT<F>*>(r)->fn == *static_cast<const F*>(c);
    else
      return false;  // plain read() with a lambda: never matched
  }
  static constexpr ReadOps ops{&invoke, &destroy,
                               std::equality_comparable<F> ? &equal : nullptr,
                               &VersionOpsFor<T>::ops, sizeof(ReadNodeT<F>)};
  /// ops' number in read_ops_table (numbered on first use: a function-local static, so no
  /// read made during static initialisation can see it unnumbered).
  static std::uint16_t id() {
    static const std::uint16_t i = register_read_ops(&ops);
    return i;
  }
};

/// Does closure F of a multi-read of T values narrow what it depends on (Engine::read_many)?
/// Its affected() may also take the engine first, for the engine's context (a closure that
/// reaches its program through Engine::context rather than holding a pointer to it).
template <class F, class T>
concept ProjectedReadWithEngine = requires(const F& f, const Engine& rt, std::size_t i, const T& a, const T& b) {
  { f.affected(rt, i, a, b) } -> std::convertible_to<bool>;
};
template <class F, class T>
concept ProjectedRead = ProjectedReadWithEngine<F, T> || requires(const F& f, std::size_t i, const T& a, const T& b) {
  { f.affected(i, a, b) } -> std::convertible_to<bool>;
};

/// Can closure F of a multi-read of T values move a slot to another modifiable rather than
/// re-run (Engine::read_many)? E is the Engine, complete where this is asked.
template <class F, class T, class E>
concept FollowingRead = requires(const F& f, std::size_t i, const T& a, const T& b, const typename E::At& at) {
  { f.follow(i, a, b, at) } -> std::convertible_to<const ModBase*>;
};

/// A multi-read of k modifiables of type T with closure F (ReadManyHeader): the body gets
/// (Engine&,) std::span<const T* const> of the k values, in the order of the modifiables,
/// and, when it takes them, the modifiables (ReadSlots<T>).
template <class T, class F>
struct ReadManyOpsFor {
  static F* closure(ReadNode* r) {
    return std::launder(reinterpret_cast<F*>(reinterpret_cast<char*>(r) +
                                             ReadManyHeader::closure_offset(many_of(r)->k())));
  }
  static void invoke_many(Engine& rt, ReadNode* r, const VersionBase* const* vs) {
    const std::uint32_t k = many_of(r)->k();
    const T* vals[kMaxReadMany];
    for (std::uint32_t i = 0; i < k; ++i) vals[i] = &static_cast<const Version<T>*>(vs[i])->value;
    const std::span<const T* const> span(vals, k);
    F& f = *closure(r);
    if constexpr (std::is_invocable_v<F&, Engine&, std::span<const T* const>, ReadSlots<T>>)
      f(rt, span, ReadSlots<T>(many_of(r)->slots()));
    else if constexpr (std::is_invocable_v<F&, Engine&, std::span<const T* const>>)
      f(rt, span);
    else
      f(span);
  }
  static void destroy(ReadNode* r) noexcept {
    closure(r)->~F();
    ReadSlot* s = many_of(r)->slots();
    for (std::uint32_t i = 0; i < many_of(r)->k(); ++i) s[i].~ReadSlot();
    many_of(r)->~ReadManyHeader();
  }
  static bool affected(const Engine& rt, const ReadNode* r, std::uint32_t i, const VersionBase* before,
                       const VersionBase* after) {
    const T& b = static_cast<const Version<T>*>(before)->value;
    const T& a = static_cast<const Version<T>*>(after)->value;
    if constexpr (ProjectedReadWithEngine<F, T>)
      return closure(const_cast<ReadNode*>(r))->affected(rt, i, b, a);
    else if constexpr (ProjectedRead<F, T>)
      return closure(const_cast<ReadNode*>(r))->affected(i, b, a);
    else
      return true;
  }
  template <class E>
  static const ModBase* follow(E& e, ReadNode* r, std::uint32_t i, const VersionBase* seen, const VersionBase* now) {
    if constexpr (FollowingRead<F, T, E>)
      return closure(r)->follow(i, static_cast<const Version<T>*>(seen)->value,
                                static_cast<const Version<T>*>(now)->value, typename E::At(e, r));
    else
      return nullptr;
  }
  static constexpr ReadOps ops{nullptr,
                               &destroy,
                               nullptr,
                               &VersionOpsFor<T>::ops,
                               static_cast<std::uint32_t>(sizeof(ReadManyHeader) + sizeof(F)),
                               &invoke_many,
                               ProjectedRead<F, T> ? &affected : nullptr,
                               FollowingRead<F, T, Engine> ? &follow<Engine> : nullptr};
  static std::uint16_t id() {
    static const std::uint16_t i = register_read_ops(&ops);
    return i;
  }
};

/// A keyed allocation's ops table with the bytes of its key (and the padding before the
/// object), for Engine::memory_breakdown(): ops is the first member of this standard-layout
/// struct, so a record's ops pointer leads back here. Every ops table with key_equal set
/// lives in one (AllocOpsFor).
struct KeyedAllocOps {
  AllocOps ops;
  std::uint32_t key_bytes;
};

template <class T, class K>
struct AllocOpsFor {
  using N = AllocNodeT<T, K>;
  static void destroy(AllocNode* n) noexcept { static_cast<N*>(n)->~N(); }
  static bool key_equal(const AllocNode* n, const void* k) {
    return static_cast<const N*>(n)->key == *static_cast<const K*>(k);
  }
  static std::size_t hash(const AllocNode* n) { return Hash<K>{}(static_cast<const N*>(n)->key); }
  // The key follows the 24-byte AllocNode; the object follows the key at its alignment.
  static constexpr std::size_t kObjectOffset =
      (sizeof(AllocNode) + sizeof(K) + alignof(T) - 1) / alignof(T) * alignof(T);
  static constexpr KeyedAllocOps keyed{{&destroy, &key_equal, &hash, sizeof(N)},
                                       static_cast<std::uint32_t>(kObjectOffset - sizeof(AllocNode))};
  static constexpr const AllocOps& ops = keyed.ops;
  static std::uint16_t id() {
    static const std::uint16_t i = register_alloc_ops(&ops);
    return i;
  }
};

template <class T>
struct PlainAllocOpsFor {
  using N = PlainAllocNodeT<T>;
  static void destroy(AllocNode* n) noexcept { static_cast<N*>(n)->~N(); }
  static constexpr AllocOps ops{&destroy, nullptr, nullptr, sizeof(N)};
  static std::uint16_t id() {
    static const std::uint16_t i = register_alloc_ops(&ops);
    return i;
  }
};

template <class F>
struct MemoOpsFor {
  using N = MemoNodeT<F>;
  static void destroy(MemoNode* n) noexcept { static_cast<N*>(n)->~N(); }
  static bool equal(const MemoNode* n, const void* c) {
    return static_cast<const N*>(n)->fn == *static_cast<const F*>(c);
  }
  static void invoke(Engine& rt, MemoNode* n) { call_thunk(static_cast<N*>(n)->fn, rt); }
  static std::size_t hash(const MemoNode* n) { return Hash<F>{}(static_cast<const N*>(n)->fn); }
  static constexpr MemoOps ops{&invoke, &destroy, &equal, &hash, sizeof(N)};
  static std::uint16_t id() {
    static const std::uint16_t i = register_memo_ops(&ops);
    return i;
  }
};

}  // namespace sac::detail
