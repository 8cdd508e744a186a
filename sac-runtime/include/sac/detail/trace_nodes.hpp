// sac/detail/trace_nodes.hpp — the records the trace is made of.
//
// Purpose: the layout of reads, versions, allocations and memo entries. Every record embeds
// its Stamp(s) at a fixed offset so that a stamp met while walking the
// order list leads back to its record (container_of by kind). Records come from the engine's
// Pool; their type-specific behaviour (destroy, compare, hash, invoke) sits in a static ops
// table per instantiated type, so a record costs one pointer for it and no vtable — a read,
// the commonest record, only a 32-bit number (read_ops_table).
//
// Layout (bytes, 64-bit): VersionBase 40 + value; ReadNode 56 + closure; a multi-read
// (ReadManyHeader) 64 + 32 per modifiable + closure; AllocNode 32 + key + object; MemoNode 48
// + closure. A read or memo entry keeps no flags: it is dead once its start stamp is
// unlinked, and closed once its end stamp is linked. The reader-list operations (attach,
// detach, ...) are free functions at the end.
// Invariants: sac/engine.hpp, I1-I7 (Engine::check_invariants() checks them).
// Complexity: every function here O(1).
// Paper: docs/DESIGN.md, "Modifiables, reads and versions".
#pragma once

#include <cstddef>
#include <cstdint>

#include "sac/detail/order_list.hpp"

namespace sac {
class Engine;
class ModBase;
}  // namespace sac

namespace sac::detail {

struct VersionBase;
struct ReaderLink;
struct ReadNode;
struct AllocNode;
struct MemoNode;

struct VersionOps {
  void (*destroy)(VersionBase*) noexcept;
  bool (*equal)(const VersionBase*, const VersionBase*);
  /// Builds a Version<T> holding T{} (ops set) in `mem` of `size` bytes: the base version
  /// of a modifiable with a default (Engine::init_default), made once the modifiable has
  /// both a reader of the default and a version. Null when T has no default constructor.
  VersionBase* (*make_default)(void* mem);
  /// One process-wide Version<T> holding T{}, in no modifiable: what a read of a default
  /// that has no base version is handed (its body sees the value only). Null as above.
  const VersionBase* (*shared_default)();
  std::uint32_t size;
};

/// One value of a modifiable, valid from its stamp until the next version's stamp.
/// A base version (set by the mutator) has kind Sentinel, is never in the order list and
/// precedes every computation time.
struct VersionBase {
  Stamp stamp;
  const VersionOps* ops;
  // The next older version; after the oldest, the modifiable | kEnd (| kDefaulted when
  // Engine::init_default() gave it a default).
  std::uintptr_t link;
  // The reads (or multi-read slots) that see this version, in two lists: `readers`,
  // newest first (every from-scratch read, and those Engine::link_write or an undo put in
  // order), and `unordered_readers`, in no order (attached by a re-execution among older
  // ones). So the readers after a time are the unordered ones and a prefix of the others.
  ReaderLink* readers;
  ReaderLink* unordered_readers;

  static constexpr std::uintptr_t kEnd = 1;
  static constexpr std::uintptr_t kDefaulted = 2;

  bool is_base() const { return stamp.kind() == StampKind::Sentinel; }
  VersionBase* older() const {
    return (link & kEnd) ? nullptr : reinterpret_cast<VersionBase*>(link);
  }
  /// The oldest version of the chain this one is in (short: versions are few).
  const VersionBase* oldest() const {
    const VersionBase* v = this;
    while (!(v->link & kEnd)) v = reinterpret_cast<const VersionBase*>(v->link);
    return v;
  }
  /// The owning modifiable, found at the end of the chain of older versions; this saves a
  /// pointer in every version.
  ModBase* mod() const { return reinterpret_cast<ModBase*>(oldest()->link & ~(kEnd | kDefaulted)); }
  void set_older(VersionBase* o) { link = reinterpret_cast<std::uintptr_t>(o); }
};

template <class T>
struct Version : VersionBase {
  T value;
  template <class... A>
  explicit Version(A&&... a) : VersionBase{}, value(static_cast<A&&>(a)...) {}
};

struct ReadOps {
  void (*invoke)(Engine&, ReadNode*, const VersionBase*);  // null for a multi-read
  void (*destroy)(ReadNode*) noexcept;
  bool (*equal)(const ReadNode*, const void* closure);  // null: not memoizable
  const VersionOps* value;  // the ops of the versions it reads
  /// A plain read: sizeof the record. A multi-read: the record without its slots, which
  /// add sizeof(ReadSlot) each (Engine::read_size).
  std::uint32_t size;
  /// A multi-read's body, given the k versions it sees in slot order; null for a plain read.
  void (*invoke_many)(Engine&, ReadNode*, const VersionBase* const*) = nullptr;
  /// A read of a projection (Engine::read_many with a closure that has affected()): does
  /// replacing the value slot i sees, `before`, by `after` change what the body depends on?
  /// Null: every change does.
  bool (*affected)(const ReadNode*, std::uint32_t slot, const VersionBase* before, const VersionBase* after) = nullptr;
  /// A multi-read whose closure has follow(): after a change of slot i from `seen` to `now`
  /// that affects it, the modifiable that holds what it used of `seen` at its time, which
  /// slot i then reads instead of re-running; null: re-run. Null: never.
  const ModBase* (*follow)(Engine&, ReadNode*, std::uint32_t slot, const VersionBase* seen,
                           const VersionBase* now) = nullptr;
};

/// The read ops tables by number, so that a read stores 4 bytes for its ops instead of 8.
/// A table is numbered the first time a read of its type is made (ReadOpsFor::id()) and
/// keeps its number for the life of the process. Entry 0 is never used.
inline constexpr std::uint32_t kMaxReadTypes = std::uint32_t{1} << 16;
extern const ReadOps* read_ops_table[kMaxReadTypes];
/// Gives `ops` the next free number. Throws sac::UsageError beyond kMaxReadTypes − 1 types.
std::uint32_t register_read_ops(const ReadOps* ops);

/// An entry of a version's reader list (and of a modifiable's default readers): a plain
/// read's `link`, or one slot of a multi-read. ops_id tells which: a read's ops number is
/// never 0 (read_ops_table), a slot's ops_id is kSlotOps and its qpos field its index.
/// `unordered` says which of its version's two lists it is on (VersionBase::readers);
/// on a default's list it means nothing.
struct ReaderLink {
  union {
    ReaderLink* rnext;           // attached: the next reader of the same version
    const ModBase* issued_mod;   // a plain read issued, not yet run: the modifiable it will read
  };
  ReaderLink** rpprev;       // null when attached to no version
  std::uint16_t ops_id;      // read: read_ops_table's index of its ops; slot: kSlotOps
  std::uint16_t unordered;   // 1: on its version's unordered_readers
  std::uint32_t qpos;        // read: its index in the queue; slot: its index in its multi-read
};
static_assert(sizeof(ReaderLink) == 24);
inline constexpr std::uint16_t kSlotOps = 0;

/// A read. It does not name its modifiable: a live read hangs on a version of it (whose
/// chain ends at the modifiable), a queued read's modifiable waits with it in the queue, and
/// an issued read keeps it in `issued_mod` until it runs (the union's other member). Its ops
/// table is a number, and its state is its stamps'. This keeps the record at 56 bytes.
/// A multi-read (Engine::read_many) is a ReadNode too, whose link is never attached: its
/// slots are (ReadManyHeader).
struct ReadNode {
  Stamp start;
  Stamp end;
  ReaderLink link;

  const ReadOps* ops() const { return read_ops_table[link.ops_id]; }
  bool many() const { return ops()->invoke_many != nullptr; }
};
static_assert(sizeof(ReadNode) == 56);

/// One modifiable of a multi-read: hangs on the version of `mod` the multi-read sees.
struct ReadSlot {
  ReaderLink link;  // first: a ReaderLink of a slot is its ReadSlot
  const ModBase* mod;
};
static_assert(sizeof(ReadSlot) == 32);

/// A multi-read record: this header, then `k` ReadSlots, then the closure (at
/// closure_offset(k)). One pool block of ops->size + k * sizeof(ReadSlot) bytes; a slot
/// finds its header from its index, so it needs no owner pointer.
struct ReadManyHeader {
  ReadNode read;  // first: the header is its ReadNode's address
  std::uint32_t k;
  std::uint32_t pad_;

  ReadSlot* slots() { return reinterpret_cast<ReadSlot*>(this + 1); }
  const ReadSlot* slots() const { return reinterpret_cast<const ReadSlot*>(this + 1); }
  static constexpr std::size_t closure_offset(std::size_t k) {
    return sizeof(ReadManyHeader) + k * sizeof(ReadSlot);
  }
};
static_assert(sizeof(ReadManyHeader) == 64);

inline ReadManyHeader* many_of(ReadNode* r) { return reinterpret_cast<ReadManyHeader*>(r); }
inline const ReadManyHeader* many_of(const ReadNode* r) {
  return reinterpret_cast<const ReadManyHeader*>(r);
}
inline bool is_slot(const ReaderLink* l) { return l->ops_id == kSlotOps; }
/// The read a reader list entry belongs to: the plain read, or a slot's multi-read.
inline ReadNode* owner_of(ReaderLink* l) {
  char* p = reinterpret_cast<char*>(l);
  if (is_slot(l)) return reinterpret_cast<ReadNode*>(p - sizeof(ReadManyHeader) - l->qpos * sizeof(ReadSlot));
  return reinterpret_cast<ReadNode*>(p - offsetof(ReadNode, link));
}
inline const ReadNode* owner_of(const ReaderLink* l) { return owner_of(const_cast<ReaderLink*>(l)); }

template <class F>
struct ReadNodeT : ReadNode {
  F fn;
  template <class G>
  explicit ReadNodeT(G&& g) : ReadNode{}, fn(static_cast<G&&>(g)) {}
};

struct AllocOps {
  void (*destroy)(AllocNode*) noexcept;
  bool (*key_equal)(const AllocNode*, const void* key);  // null: unkeyed
  std::size_t (*hash)(const AllocNode*);
  std::uint32_t size;
};

struct AllocNode {
  Stamp stamp;
  const AllocOps* ops;
  AllocNode* hnext;
};

template <class T, class K>
struct AllocNodeT : AllocNode {
  K key;
  T object;
  template <class... A>
  AllocNodeT(const K& k, A&&... a) : AllocNode{}, key(k), object(static_cast<A&&>(a)...) {}
};

template <class T>
struct PlainAllocNodeT : AllocNode {
  T object;
  template <class... A>
  explicit PlainAllocNodeT(A&&... a) : AllocNode{}, object(static_cast<A&&>(a)...) {}
};

struct MemoOps {
  void (*invoke)(Engine&, MemoNode*);
  void (*destroy)(MemoNode*) noexcept;
  bool (*equal)(const MemoNode*, const void* closure);
  std::size_t (*hash)(const MemoNode*);
  std::uint32_t size;
};

struct MemoNode {
  Stamp start;
  Stamp end;
  MemoNode* hnext;
  const MemoOps* ops;
};
static_assert(sizeof(MemoNode) == 48);

template <class F>
struct MemoNodeT : MemoNode {
  F fn;
  template <class G>
  explicit MemoNodeT(G&& g) : MemoNode{}, fn(static_cast<G&&>(g)) {}
};

inline ReadNode* read_of_start(Stamp* s) { return reinterpret_cast<ReadNode*>(s); }
inline ReadNode* read_of_end(Stamp* s) {
  return reinterpret_cast<ReadNode*>(reinterpret_cast<char*>(s) - offsetof(ReadNode, end));
}
inline VersionBase* version_of(Stamp* s) { return reinterpret_cast<VersionBase*>(s); }
inline AllocNode* alloc_of(Stamp* s) { return reinterpret_cast<AllocNode*>(s); }
inline MemoNode* memo_of_start(Stamp* s) { return reinterpret_cast<MemoNode*>(s); }
inline MemoNode* memo_of_end(Stamp* s) {
  return reinterpret_cast<MemoNode*>(reinterpret_cast<char*>(s) - offsetof(MemoNode, end));
}

// ------------------------------------------------------------------ reader lists
// A version's readers are two doubly linked lists (VersionBase::readers, newest first, and
// VersionBase::unordered_readers); a modifiable with a default and no version keeps the
// reads of its default in a third, headed by the modifiable's own head word. Each entry's
// rpprev points at what points at it, so detaching is O(1) without knowing the list.

/// The first of a modifiable's default readers has this bit in its rpprev, which then
/// points at the modifiable's head word (whose default mark a plain store would lose).
inline constexpr std::uintptr_t kHeadLink = 1;
/// The mark of a modifiable's head word that holds its first default reader
/// (ModBase::kDefaultOnly).
inline constexpr std::uintptr_t kDefaultOnlyMark = 2;

/// Pushes r at *head, on the list `unordered` names (0: ordered, 1: unordered).
inline void push_reader(ReaderLink* r, ReaderLink** head, std::uint16_t unordered) {
  r->rnext = *head;
  if (*head) (*head)->rpprev = &r->rnext;
  *head = r;
  r->rpprev = head;
  r->unordered = unordered;
}
/// Hangs r at the head of v's ordered readers (the caller knows it is the newest).
inline void attach(ReaderLink* r, VersionBase* v) { push_reader(r, &v->readers, 0); }
/// Hangs r on v's unordered readers.
inline void attach_unordered(ReaderLink* r, VersionBase* v) { push_reader(r, &v->unordered_readers, 1); }
/// Hangs r, a read at its start's time, on v: at the head of v's ordered readers when it is
/// at the trace's end (every from-scratch read) or v has none, else on v's unordered
/// readers. Testing r against the head's time instead would cost a cache miss per read that
/// re-execution adds, and most of them land among older readers anyway; Engine::link_write
/// folds the unordered readers it tests into order.
inline void attach_timed(ReaderLink* r, VersionBase* v) {
  if (!v->readers || owner_of(r)->start.next() == nullptr) attach(r, v);
  else attach_unordered(r, v);
}
/// Pushes r first on the default readers whose head word is *head and whose first is
/// `first` (the modifiable has a default and no version).
inline void push_default_reader(ReaderLink* r, std::uintptr_t* head, ReaderLink* first) {
  r->rnext = first;
  if (first) first->rpprev = &r->rnext;
  *head = reinterpret_cast<std::uintptr_t>(r) | kDefaultOnlyMark;
  r->rpprev = reinterpret_cast<ReaderLink**>(reinterpret_cast<std::uintptr_t>(head) | kHeadLink);
}
/// The modifiable whose default r hangs on, if r is the first of its default readers.
inline const ModBase* default_head(const ReaderLink* r) {
  const auto pp = reinterpret_cast<std::uintptr_t>(r->rpprev);
  return (pp & kHeadLink) ? reinterpret_cast<const ModBase*>(pp & ~kHeadLink) : nullptr;
}
/// Unhangs r from whatever list it is on (nothing if none).
inline void detach(ReaderLink* r) {
  if (!r->rpprev) return;
  const auto pp = reinterpret_cast<std::uintptr_t>(r->rpprev);
  if (pp & kHeadLink)
    *reinterpret_cast<std::uintptr_t*>(pp & ~kHeadLink) = reinterpret_cast<std::uintptr_t>(r->rnext) | kDefaultOnlyMark;
  else
    *r->rpprev = r->rnext;
  if (r->rnext) r->rnext->rpprev = r->rpprev;
  r->rpprev = nullptr;
  r->rnext = nullptr;
}

}  // namespace sac::detail
