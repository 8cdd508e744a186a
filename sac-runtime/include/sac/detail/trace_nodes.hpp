// sac/detail/trace_nodes.hpp — the records the trace is made of.
//
// Purpose: the layout of reads, versions, allocations and memo entries. Every record embeds
// its Stamp(s) at a fixed offset so that a stamp met while walking the
// order list leads back to its record (container_of by kind). Records come from the engine's
// Pool; their type-specific behaviour (destroy, compare, hash, invoke) sits in a static ops
// table per instantiated type, found by a 16-bit number kept in bits no pointer uses, so a
// record costs no bytes for it and no vtable.
//
// Dense: every field a record needs and no other. A user-space address fits in 48 bits, so
// the top 16 bits of a stamp's link (Stamp::aux) and of a reader's back link carry the ops
// number, a read's queue position and a slot's index, and the back link's low 3 bits its
// flags. Layout (bytes, 64-bit): VersionBase 40 + value; ReadNode 48 + closure; a multi-read
// (ReadManyHeader) 48 + 24 per modifiable + closure; AllocNode 24 + key + object; MemoNode
// 40 + closure. A read or memo entry keeps no flags: it is dead once its start stamp is
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

/// The ops tables by number, one numbering per record kind, so that a record keeps its
/// table's 16-bit number in bits no pointer uses (Stamp::aux, ReaderLink's back link). A
/// table is numbered the first time a record of its type is made (its XOpsFor::id()) and
/// keeps its number for the life of the process. Entry 0 is never used.
inline constexpr std::uint32_t kMaxOpsTypes = std::uint32_t{1} << 16;
struct ReadOps;
struct AllocOps;
struct MemoOps;
extern const VersionOps* version_ops_table[kMaxOpsTypes];
extern const ReadOps* read_ops_table[kMaxOpsTypes];
extern const AllocOps* alloc_ops_table[kMaxOpsTypes];
extern const MemoOps* memo_ops_table[kMaxOpsTypes];
/// Give `ops` the next free number of its kind. Throw sac::UsageError beyond
/// kMaxOpsTypes − 1 types of a kind.
std::uint16_t register_version_ops(const VersionOps* ops);
std::uint16_t register_read_ops(const ReadOps* ops);
std::uint16_t register_alloc_ops(const AllocOps* ops);
std::uint16_t register_memo_ops(const MemoOps* ops);

/// One value of a modifiable, valid from its stamp until the next version's stamp.
/// A base version (set by the mutator) has kind Sentinel, is never in the order list and
/// precedes every computation time.
struct VersionBase {
  Stamp stamp;  // aux: version_ops_table's number of its ops
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

  const VersionOps* ops() const { return version_ops_table[stamp.aux()]; }
  void set_ops_id(std::uint16_t id) { stamp.set_aux(id); }
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
static_assert(sizeof(VersionBase) == 40);

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
  /// Null: every change does. The engine is there for its context only.
  bool (*affected)(const Engine&, const ReadNode*, std::uint32_t slot, const VersionBase* before,
                   const VersionBase* after) = nullptr;
  /// A multi-read whose closure has follow(): after a change of slot i from `seen` to `now`
  /// that affects it, the modifiable that holds what it used of `seen` at its time, which
  /// slot i then reads instead of re-running; null: re-run. Null: never.
  const ModBase* (*follow)(Engine&, ReadNode*, std::uint32_t slot, const VersionBase* seen,
                           const VersionBase* now) = nullptr;
};

/// An entry of a version's reader list (and of a modifiable's default readers): a plain
/// read's `link`, or one slot of a multi-read. Two words:
///   - rnext: the next reader of the same version (attached); for a plain read issued and
///     not yet run, the modifiable it will read (issued_mod); for a multi-read's own link,
///     which is never attached, its number of slots (many_k);
///   - back: what points at this entry (null when attached to no version), with
///       bit 0 kHeadLink (it points at a modifiable's head word: the first default reader),
///       bit 1 on its version's unordered_readers (VersionBase::readers; on a default's
///         list it means nothing),
///       bit 2 a multi-read's slot,
///     and in its top 16 bits the high half of a read's queue position, or a slot's index
///     in its multi-read.
struct ReaderLink {
  union {
    ReaderLink* rnext;
    const ModBase* issued_mod;
    std::uintptr_t many_k;
  };
  std::uintptr_t back;

  static constexpr std::uintptr_t kUnorderedBit = 2;
  static constexpr std::uintptr_t kSlotBit = 4;
  static constexpr int kTagShift = 48;
  static constexpr std::uintptr_t kTagMask = ~std::uintptr_t{0} << kTagShift;
  static constexpr std::uintptr_t kPrevMask = ~(kTagMask | kUnorderedBit | kSlotBit);  // kHeadLink kept

  /// The back link as stored: an address, | kHeadLink when it is a modifiable's head word.
  std::uintptr_t prev_raw() const { return back & kPrevMask; }
  ReaderLink** rpprev() const { return reinterpret_cast<ReaderLink**>(prev_raw()); }
  bool attached() const { return prev_raw() != 0; }
  void set_prev_raw(std::uintptr_t p) { back = (back & ~kPrevMask) | p; }
  void set_rpprev(ReaderLink** p) { set_prev_raw(reinterpret_cast<std::uintptr_t>(p)); }
  bool unordered() const { return (back & kUnorderedBit) != 0; }
  void set_unordered(bool u) { back = (back & ~kUnorderedBit) | (u ? kUnorderedBit : 0); }
  bool slot() const { return (back & kSlotBit) != 0; }
  std::uint16_t tag() const { return static_cast<std::uint16_t>(back >> kTagShift); }
  void set_tag(std::uint16_t t) { back = (back & ~kTagMask) | (std::uintptr_t{t} << kTagShift); }
};
static_assert(sizeof(ReaderLink) == 16);

/// A read. It does not name its modifiable: a live read hangs on a version of it (whose
/// chain ends at the modifiable), a queued read's modifiable waits with it in the queue, and
/// an issued read keeps it in `issued_mod` until it runs (the union's other member). Its ops
/// table is a number, in its end stamp's aux, and its state is its stamps'. Its queue
/// position is split between its start stamp's aux (low half) and its link's tag (high
/// half): kNotQueued when not queued. This keeps the record at 48 bytes.
/// A multi-read (Engine::read_many) is a ReadNode too, whose link is never attached: its
/// slots are (ReadManyHeader).
struct ReadNode {
  Stamp start;
  Stamp end;
  ReaderLink link;

  std::uint16_t ops_id() const { return end.aux(); }
  const ReadOps* ops() const { return read_ops_table[ops_id()]; }
  void set_ops_id(std::uint16_t id) { end.set_aux(id); }
  bool many() const;
  std::uint32_t qpos() const { return start.aux() | std::uint32_t{link.tag()} << 16; }
  void set_qpos(std::uint32_t q) {
    start.set_aux(static_cast<std::uint16_t>(q));
    link.set_tag(static_cast<std::uint16_t>(q >> 16));
  }
};
static_assert(sizeof(ReadNode) == 48);

/// One modifiable of a multi-read: hangs on the version of `mod` the multi-read sees.
struct ReadSlot {
  ReaderLink link;  // first: a ReaderLink of a slot is its ReadSlot; tag: its index
  const ModBase* mod;
};
static_assert(sizeof(ReadSlot) == 24);

/// A multi-read record: this header, then `k` ReadSlots, then the closure (at
/// closure_offset(k)). One pool block of ops->size + k * sizeof(ReadSlot) bytes; a slot
/// finds its header from its index, so it needs no owner pointer. k is kept in the
/// header's own link, which is never attached.
struct ReadManyHeader {
  ReadNode read;  // first: the header is its ReadNode's address

  std::uint32_t k() const { return static_cast<std::uint32_t>(read.link.many_k); }
  void set_k(std::uint32_t n) { read.link.many_k = n; }
  ReadSlot* slots() { return reinterpret_cast<ReadSlot*>(this + 1); }
  const ReadSlot* slots() const { return reinterpret_cast<const ReadSlot*>(this + 1); }
  static constexpr std::size_t closure_offset(std::size_t k) {
    return sizeof(ReadManyHeader) + k * sizeof(ReadSlot);
  }
};
static_assert(sizeof(ReadManyHeader) == 48);

inline ReadManyHeader* many_of(ReadNode* r) { return reinterpret_cast<ReadManyHeader*>(r); }
inline const ReadManyHeader* many_of(const ReadNode* r) {
  return reinterpret_cast<const ReadManyHeader*>(r);
}
inline bool is_slot(const ReaderLink* l) { return l->slot(); }
inline bool ReadNode::many() const { return ops()->invoke_many != nullptr; }
/// The read a reader list entry belongs to: the plain read, or a slot's multi-read.
inline ReadNode* owner_of(ReaderLink* l) {
  char* p = reinterpret_cast<char*>(l);
  if (is_slot(l)) return reinterpret_cast<ReadNode*>(p - sizeof(ReadManyHeader) - l->tag() * sizeof(ReadSlot));
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
  Stamp stamp;  // aux: alloc_ops_table's number of its ops
  AllocNode* hnext;

  const AllocOps* ops() const { return alloc_ops_table[stamp.aux()]; }
  void set_ops_id(std::uint16_t id) { stamp.set_aux(id); }
};
static_assert(sizeof(AllocNode) == 24);

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
  Stamp start;  // aux: memo_ops_table's number of its ops
  Stamp end;
  MemoNode* hnext;

  const MemoOps* ops() const { return memo_ops_table[start.aux()]; }
  void set_ops_id(std::uint16_t id) { start.set_aux(id); }
};
static_assert(sizeof(MemoNode) == 40);

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

/// Pushes r at *head, on the list `unordered` names (false: ordered, true: unordered).
inline void push_reader(ReaderLink* r, ReaderLink** head, bool unordered) {
  r->rnext = *head;
  if (*head) (*head)->set_rpprev(&r->rnext);
  *head = r;
  r->set_rpprev(head);
  r->set_unordered(unordered);
}
/// Hangs r at the head of v's ordered readers (the caller knows it is the newest).
inline void attach(ReaderLink* r, VersionBase* v) { push_reader(r, &v->readers, false); }
/// Hangs r on v's unordered readers.
inline void attach_unordered(ReaderLink* r, VersionBase* v) { push_reader(r, &v->unordered_readers, true); }
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
  if (first) first->set_rpprev(&r->rnext);
  *head = reinterpret_cast<std::uintptr_t>(r) | kDefaultOnlyMark;
  r->set_prev_raw(reinterpret_cast<std::uintptr_t>(head) | kHeadLink);
}
/// The modifiable whose default r hangs on, if r is the first of its default readers.
inline const ModBase* default_head(const ReaderLink* r) {
  const std::uintptr_t pp = r->prev_raw();
  return (pp & kHeadLink) ? reinterpret_cast<const ModBase*>(pp & ~kHeadLink) : nullptr;
}
/// Unhangs r from whatever list it is on (nothing if none).
inline void detach(ReaderLink* r) {
  const std::uintptr_t pp = r->prev_raw();
  if (!pp) return;
  if (pp & kHeadLink)
    *reinterpret_cast<std::uintptr_t*>(pp & ~kHeadLink) = reinterpret_cast<std::uintptr_t>(r->rnext) | kDefaultOnlyMark;
  else
    *reinterpret_cast<ReaderLink**>(pp) = r->rnext;
  if (r->rnext) r->rnext->set_prev_raw(pp);
  r->set_prev_raw(0);
  r->rnext = nullptr;
}

}  // namespace sac::detail
