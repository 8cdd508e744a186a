// sac/engine.hpp — the self-adjusting computation engine: the facade.
//
// Purpose: run an ordinary-looking program once from scratch while recording its trace, then
// after input changes bring every output to exactly what a from-scratch run would produce,
// re-executing only the affected reads (change propagation). The model is Acar's imperative
// self-adjusting computation, as a C++ library without a compiler:
//
//   rt.run(f)               run f(rt) from scratch, recording its trace.
//   rt.set(m, v)            change an input (outside the computation).
//   rt.propagate()          bring the trace and every output up to date with the inputs.
//   rt.read(m, body)        record a read of m over the interval of body(value); on change,
//                           body is re-run in its own interval.
//   rt.write(m, v)          add a version of m at the current time (cut off if equal).
//   rt.alloc<T>(key, a...)  keyed allocation: re-executions that allocate under the same key
//                           inside the re-execution window get the same object back.
//   rt.make<T>(a...)        unkeyed allocation, freed when its allocation is undone.
//   rt.memo(fn)             memoized call: an equal call of the old trace inside the window is
//                           reused (trace between is undone, affected reads inside it are
//                           propagated, execution jumps to its end).
//   rt.memo_near(k, fn)     memo(fn), reusing an old call only when at most k stamps ahead.
//   rt.memo_read(m, fn)     read(m, fn) memoized on (m, fn) with no extra record.
//   rt.read_many(ms, body)  k nested reads as one record and one interval: body(values);
//                           with body.affected(i, before, after), a read of a projection.
//   rt.current(m)           the value of m an enclosing read already depends on, unrecorded.
//   rt.peek(m)              the value of m visible now, unrecorded: a guess for a prefetch.
//   rt.stats()              event counts and trace distance (sac/stats.hpp).
//
// The class below lists that API first; the calls only some programs need (init,
// init_default, unused, retire, set_context, At, order) follow under "Advanced". Template
// bodies are in sac/detail/engine_impl.hpp, the machinery (records, ops tables, order list,
// queue, pool, trampoline) in sac/detail/, the non-template code in src/.
//
// Execution is trampolined, so deep recursion (a read chain a million long) never grows the
// C++ stack: read/memo_read/memo calls are recorded when issued and run after the issuing
// body returns, in issue order, each with its whole subtree — unless the body performs a
// write, alloc or make first, in which case the pending calls run right then. Either way the
// events happen in program order, exactly as if every call ran on the spot; a body simply
// must not expect a read's body to have run when read() returns.
// Bodies are stored in the trace and re-run later: they capture by value (or pointers to
// modifiables and keyed objects), never references to the stack. They may take
// (Engine&, const T&) or (const T&); memoized closures must be equality comparable and
// hashable (use sac::fn<f>(args...)).
//
// Invariants (check_invariants() checks each and names its number; built with the CMake
// option SAC_DEBUG_CHECKS, propagate() runs the check at its end and throws InvariantError on
// a violation):
//   I1. The order list, the queue and the memo and allocation tables each satisfy their own
//       invariants — because every "happens before" test and every match rests on them.
//   I2. The trace is well nested: every read's and memo entry's interval is closed, its end
//       after its start, and contains exactly the events its body created — because undoing
//       an interval must remove exactly what re-running its body recreates, and a memo hit
//       reuses exactly one call's events.
//   I3. A modifiable's versions are ordered newest first, strictly decreasing in time, and a
//       base version, if any, is the oldest — because visible() walks them from the newest and
//       stops at the first one not after the reader.
//   I4. Every live read (each slot of a multi-read) hangs on the version of its modifiable
//       visible at its start time, exactly once, or on the modifiable itself when it sees a
//       default and the modifiable has no version; a multi-read's own link hangs on nothing —
//       because a write finds the reads it affects among its older version's readers only,
//       never by a search of the trace.
//   I5. A version's ordered readers are newest first, its unordered ones in no order, and each
//       reader's flag names its list — because link_write takes the readers after a time as
//       all the unordered ones and a prefix of the ordered ones.
//   I6. Every live keyed allocation and memo entry is in its table, the tables hold nothing
//       undone, and stats().live_events counts the live events — because matching looks only
//       in the tables, and the statistics are part of the contract.
//   I7. Outside propagate() the queue is empty and nothing waits to be freed (undone
//       allocations, undone versions, seen lists) — because a read left queued would be an
//       output left stale, and a deferred record a leak between updates.
// Complexity: read/write/alloc O(1) amortized plus the version walk of the touched
// modifiable; a write inside propagate() also finds the older version's readers timed after
// it: by walking the trace up to the next version when that is at most 64 events away (a
// re-executed write), else by testing the older version's unordered readers (those a
// re-execution attached among older ones) and its ordered readers up to the first before
// the write, then folding the unordered ones it tested into order as far as a walk of as
// many ordered readers reaches;
// propagate() O(trace distance x log(queue size)) for monotone programs. A read of a
// projection is affected by what it sees when propagation reaches it, not by each change on
// the way: the queue keeps, per changed slot, the version it had seen (undone versions, and
// the old values set() replaced, are then freed when propagate() ends), so a change undone
// or redone before its time costs no re-execution.
// Paper: Acar, Ahmed, Blume, "Imperative self-adjusting computation" (POPL'08); Hammer, Acar,
// Chen, "CEAL" (PLDI'09); docs/DESIGN.md, "The runtime".
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <iosfwd>
#include <span>
#include <vector>

#include "sac/detail/intrusive_hash.hpp"
#include "sac/detail/ops.hpp"
#include "sac/detail/order_list.hpp"
#include "sac/detail/pool.hpp"
#include "sac/detail/segment_array.hpp"
#include "sac/detail/stamp_queue.hpp"
#include "sac/detail/trace_nodes.hpp"
#include "sac/detail/trampoline.hpp"
#include "sac/errors.hpp"
#include "sac/fn.hpp"
#include "sac/hash.hpp"
#include "sac/memory_breakdown.hpp"
#include "sac/mod.hpp"
#include "sac/stats.hpp"

namespace sac {

namespace detail {
class TraceChecker;  // src/engine_check.cpp: check_invariants()'s phases
}  // namespace detail

class Engine {
 public:
  Engine();
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  // ======================================================================================
  //   The API
  // ======================================================================================

  // ---------------------------------------------------------------- mutator
  // Outside the computation only (UsageError otherwise).

  /// Runs f(Engine&) (or f()) from scratch, appending its trace after earlier runs.
  template <class F>
  void run(F&& f);

  /// Sets the base (input) value of m; readers of the old value are affected unless equal.
  template <class T, class U>
  void set(Mod<T>& m, U&& value);

  /// Brings the trace and all outputs up to date with the changed inputs.
  void propagate();

  // ---------------------------------------------------------------- computation
  // Inside run() or propagate() only (UsageError otherwise). Bodies run later, in program
  // order (the trampoline, see the header): capture by value, never the stack.

  /// Runs body(value) (or body(Engine&, value)) on the version of m visible now, and records
  /// the read: when that value changes, propagate() undoes what body did and runs it again
  /// in the same place in time. body's events belong to the read.
  template <class T, class F>
  void read(const Mod<T>& m, F&& body);

  /// read(m, body), but a re-execution that issues an equal (m, body) finds the old read in
  /// its window and reuses it with its whole subtree instead of running body again. body
  /// must be equality comparable: use sac::fn<f>(args...).
  template <class T, class F>
  void memo_read(const Mod<T>& m, F&& body);

  /// Reads the k modifiables mods (1 <= k <= 16; repeats allowed) as one event: runs
  /// body(vals) (or body(Engine&, vals), or body(Engine&, vals, slots)) with vals a
  /// std::span<const T* const> of the k values visible now, vals[i] that of mods[i], and
  /// slots a ReadSlots<T> (sac/read_slots.hpp): the modifiables as the record holds them,
  /// valid while the read lives, for a closure that must know them without copying them.
  /// The same as k nested reads of mods in order with body innermost, but one record
  /// (48 + 24k bytes + closure), one interval
  /// and one event in the statistics: when any of the k visible values changes (cut-off
  /// writes excepted), propagate() re-runs body once, seeing all k current values. The
  /// pointers to vals are valid during the call only. Not memoized (no memo_read analogue).
  /// UsageError for k outside [1, 16]. O(k) plus the version walks of the k modifiables.
  ///
  /// A read of a projection: when body's closure has
  ///   bool affected(std::size_t i, const T& before, const T& after) const
  /// (or affected(const Engine& rt, i, before, after), rt for its context<T>() only),
  /// a change of the value mods[i] shows (a write, a set() or an undone write; before !=
  /// after) re-runs body only if affected() says so. false promises that body, run on after,
  /// would have the same effects as it had on before: the read then sees after without
  /// re-running. The closure states what body depends on in each value, typically in members
  /// body narrows as it runs (mutable: they are the read's own state, not part of its
  /// identity), and affected() must answer from them as they were when body last ran. It
  /// runs during propagate() and in set(), so it must not call the engine. O(1) per changed
  /// slot, plus affected().
  ///
  /// A read that can follow its values: when the closure also has
  ///   const Mod<T>* follow(std::size_t i, const T& seen, const T& now, const Engine::At& at) const,
  /// and a change of mods[i]'s value from `seen` (what body last ran on) to `now` affects
  /// body, propagate() first asks follow(), when it reaches the read. It may name another
  /// modifiable m whose value at the read's time (at.value(m), not null) holds everything
  /// body used of `seen`; slot i then reads m instead (body's span shows m's value from then
  /// on), and body is not re-run for this change. The closure changes its own state for
  /// slot i to m's terms before it returns m (as affected()'s, it is the read's own state).
  /// null: re-run. A change made by set() is asked too when T is swappable (set() keeps
  /// the old value until propagate() ends). Like affected(), it must not call the engine,
  /// at.value() apart.
  template <class T, class F>
  void read_many(std::span<const Mod<T>* const> mods, F&& body);
  /// read_many over a braced list of modifiables.
  template <class T, class F>
  void read_many(std::initializer_list<const Mod<T>*> mods, F&& body);

  /// The value of m visible now, recording nothing. Only for a value the running body
  /// already depends on: m was read by an enclosing read (plain or multi) of this body, and
  /// nothing wrote m since. The use is a nested read_many that extends an outer one's set
  /// (a search that finds it needs more cells): the outer values are looked up again, not
  /// copied into every closure. Any other use is a read change propagation cannot see.
  /// UsageError if m has no value now.
  template <class T>
  const T& current(const Mod<T>& m);

  /// The value of m visible now (a write this body just made included), or null when m has
  /// no version visible now (a modifiable made with init_default then has the value T{}).
  /// Records nothing and makes nothing, so it is a guess, never a dependency: a body may use
  /// it only to choose which modifiables to read, and its effects must depend on the values
  /// it reads. The use is a prefetch: a search runs on the values visible now to learn which
  /// cells it needs, then reads them all as one read_many. O(versions of m newer than now).
  template <class T>
  const T* peek(const Mod<T>& m);

  /// Adds a version of m holding value at the current time; readers later in the trace see
  /// it. A write equal to the value it replaces is cut off: its readers are not affected.
  template <class T, class U>
  void write(Mod<T>& m, U&& value);

  /// A T keyed by key: a re-execution that allocates under an equal key inside its window
  /// gets the same object back (and its modifiables with their versions), so the work that
  /// reads them is reused. On reuse `args` are ignored: the object is not rebuilt. Hence
  /// the rule: the constructor arguments must be a function of the key, or a reused object
  /// would differ from what a from-scratch run builds.
  template <class T, class K, class... A>
  T* alloc(const K& key, A&&... args);

  /// A T with no key: never reused; destroyed when the allocation is undone (its read or
  /// memo re-runs or is discarded). For objects no later re-execution needs to find.
  template <class T, class... A>
  T* make(A&&... args);

  /// Calls f(Engine&) (or f()) memoized: a re-execution that issues an equal f inside its
  /// window reuses the old call's trace (undoing what lies between and propagating the
  /// affected reads inside it) and continues after it. f must be equality comparable and
  /// hashable: use sac::fn<f>(args...).
  template <class F>
  void memo(F&& f);

  /// memo(f), but an old call is reused only when at most max_skip stamps of the old trace
  /// lie between now and its start (those are undone by the reuse); a call further ahead is
  /// run anew and left to be undone or reused in its place. For a call whose arguments do
  /// not say where it stands in a list: a change of its place then costs no re-execution of
  /// it, and an element moved far ahead is not reused at the price of all between
  /// (Stats::memo_far counts the calls refused so). O(max_skip) per match.
  template <class F>
  void memo_near(std::uint32_t max_skip, F&& f);

  /// The pointer set_context<T>() gave. UsageError if none was given, or one of another type.
  template <class T>
  T* context() const;

  // ---------------------------------------------------------------- statistics
  /// Event counts, trace distance and queue work since the engine was made (sac/stats.hpp).
  const Stats& stats() const { return stats_; }
  /// The number of events in the trace now.
  std::uint64_t live_events() const { return stats_.live_events; }
  /// Bytes held by the trace: records, closures, versions, tables, order-list groups, queue.
  std::size_t trace_bytes() const;
  /// Bytes of the base (input) versions set by the mutator; not part of the trace.
  std::size_t input_bytes() const { return input_bytes_; }
  /// Bytes of live trace records only (exactly equal for equal traces; no table slack).
  std::size_t record_bytes() const { return pool_.live_bytes() - input_bytes_; }
  /// trace_bytes() by record kind and side structure, and what it leaves out (base
  /// versions, pool slack); see sac/memory_breakdown.hpp. Outside the computation only.
  /// O(live events + base versions).
  MemoryBreakdown memory_breakdown() const;
  /// True inside run() or propagate().
  bool in_computation() const { return in_computation_; }
  /// True once a body threw: the engine then refuses every call but destruction.
  bool poisoned() const { return poisoned_; }

  /// Checks invariants I1-I7 (see the header); throws InvariantError naming the first
  /// violation. Outside the computation only. O(trace size).
  void check_invariants() const;

  /// Writes the trace as a Graphviz digraph (intended for small traces).
  void dump_dot(std::ostream& os) const;

  // ======================================================================================
  //   Advanced: for programs that name modifiables outside the trace, share a context, or
  //   follow a read's values (read_many), and for tests of the machinery.
  // ======================================================================================

  /// Gives a never-written m a base value, as set() before the first run would. Unlike
  /// set() it may also be called inside the computation: it serves modifiables that are
  /// named lazily outside the trace (a directory keyed by name), which every run, fresh or
  /// re-executing, would find with the same default. UsageError if m is already written.
  template <class T, class U>
  void init(Mod<T>& m, U&& value);

  /// Gives a never-written m the default T{}: what a read sees when no version of m
  /// precedes it. Costs no memory of its own: while m has no version, the reads that see
  /// the default hang on m itself; once m has a version too, the default becomes a base
  /// version (as init(m, T{}) would have made). So modifiables named by the thousands
  /// outside the trace (a directory's cells, the ends of lists) hold nothing for their
  /// defaults. May be called inside the computation, like init(). UsageError if m is
  /// already written. As for any modifiable, m must outlive the reads of it (unused()
  /// says when nothing refers to it).
  template <class T>
  void init_default(Mod<T>& m);

  /// True when nothing in the trace refers to m: it has no version written by the
  /// computation and no reader (it may then be retired).
  bool unused(const ModBase& m) const noexcept;

  /// Releases m's base version so that m's storage may be reused. m must have no readers
  /// and no versions written by the computation.
  void retire(ModBase& m);

  /// Gives the computation a context: a pointer its bodies reach through the Engine
  /// (context<T>()) instead of carrying it in every closure, for what is the same for the
  /// whole computation (a program object and its tables). One per engine; the mutator sets
  /// it, before run(), and it must not change while the trace depends on it.
  template <class T>
  void set_context(T* ctx) noexcept;

  /// The time of a read whose closure follow() is asked (read_many): the values there.
  class At {
   public:
    At(const Engine& rt, const detail::ReadNode* r) : rt_(&rt), r_(r) {}
    /// The value of m visible at the read's time; null when m has no version there.
    template <class T>
    const T* value(const Mod<T>& m) const;
    /// The engine, for its context (context<T>()) only.
    const Engine& engine() const noexcept { return *rt_; }

   private:
    const Engine* rt_;
    const detail::ReadNode* r_;
  };

  /// The order list of the trace's stamps (for tests and tools).
  const detail::OrderList& order() const { return order_; }

 private:
  // Test-only hook: tests/sac/engine_test.cpp defines it to corrupt one part of the trace
  // and see check_invariants() fail. Nothing else may define it.
  friend struct EngineTestAccess;
  friend class detail::TraceChecker;

  using Stamp = detail::Stamp;
  using StampKind = detail::StampKind;

  static constexpr std::uint32_t kSeenNone = 0xffffffffu;
  /// What a queued read waits with, in 8 bytes (a heap entry stays 16): a plain read, the
  /// modifiable it reads (ReadNode does not keep it); a multi-read, none (its slots name
  /// theirs) and, when it reads a projection, the head of its list in seen_ (note_change)
  /// and whether a slot changed again after it was queued (the list is then not what
  /// note_change() found affected when it queued it, and only then can popping find it
  /// unaffected). Forced: re-run it whatever it sees.
  class QueueAux {
   public:
    QueueAux() = default;
    static QueueAux read_of(const ModBase* m) { return QueueAux(reinterpret_cast<std::uintptr_t>(m)); }
    static QueueAux listed(std::uint32_t head) { return QueueAux((std::uintptr_t{head} << 32) | kListed); }
    const ModBase* mod() const { return (bits_ & kListed) ? nullptr : reinterpret_cast<const ModBase*>(bits_); }
    bool forced() const { return !(bits_ & kListed); }
    std::uint32_t seen() const { return static_cast<std::uint32_t>(bits_ >> 32); }
    bool again() const { return bits_ & kAgain; }
    void force() { bits_ = 0; }  // a multi-read's (a plain read is never listed)
    void prepend(std::uint32_t head) { bits_ = (std::uintptr_t{head} << 32) | (bits_ & 0xffffffffu); }
    void mark_again() { bits_ |= kAgain; }

   private:
    explicit QueueAux(std::uintptr_t b) : bits_(b) {}
    static constexpr std::uintptr_t kListed = 1, kAgain = 2;  // a ModBase* is 8-aligned
    std::uintptr_t bits_ = 0;
  };
  static_assert(sizeof(std::uintptr_t) == 8);
  using ReadQueue = detail::StampQueue<detail::ReadNode, detail::ReadQueueTraits, QueueAux>;
  /// A slot of a queued read whose value changed after its last execution, and the version
  /// it had seen then (or one equal to it in what the read depends on).
  struct Seen {
    const detail::VersionBase* v;
    // What the slot sees now: the version note_change() last moved it onto, or one equal to
    // it (a move to an equal value is not noted), so popping needs no walk of the versions.
    const detail::VersionBase* now;
    std::uint32_t slot;  // its index in the multi-read (only multi-reads are listed)
    std::uint32_t next;  // the read's next entry, or kSeenNone
  };

  // Work of the trampoline (sac/detail/trampoline.hpp).
  using TaskKind = detail::TaskKind;
  using Task = detail::Task;
  using RerunContext = detail::RerunContext;

  void require_mutator(const char* what) const;
  void require_computation(const char* what) const {
    if (!in_computation_) [[unlikely]]
      fail_not_in_computation(what);
  }
  [[noreturn]] void fail_not_in_computation(const char* what) const;
  void poison() noexcept;

  void* allocate(std::size_t n) { return pool_.allocate(n); }
  void deallocate(void* p, std::size_t n) noexcept { pool_.deallocate(p, n); }
  /// A record of type N from the pool; the memory goes back if the constructor throws.
  template <class N, class... A>
  N* construct(A&&... args);
  /// Destroys a record through its ops table and returns its memory.
  template <class Rec>
  void destroy(Rec* r) noexcept;
  /// The bytes of a read record: a multi-read's grow with its slots.
  static std::size_t read_size(const detail::ReadNode* r) {
    const detail::ReadOps* ops = r->ops();
    return ops->size + (ops->invoke_many ? detail::many_of(r)->k() * sizeof(detail::ReadSlot) : 0);
  }

  // Trace machinery (engine.cpp; the hot steps of a from-scratch run, exec_body, push_close
  // and link_alloc, inline in sac/detail/engine_impl.hpp).
  void issue(TaskKind k, void* node, std::uint32_t arg = 0) { tasks_.push_back(Task{k, arg, node}); }
  void flush_if_pending() {
    if (tasks_.size() > body_mark_) [[unlikely]]
      flush();
  }
  void flush();
  template <class Body>
  void exec_body(Body&& body);
  void drain(std::size_t floor);
  void execute(const Task& t);
  void exec_read(detail::ReadNode* r);
  void exec_read_many(detail::ReadNode* r);
  /// Hangs each slot of the multi-read r on what its modifiable shows at r's start and
  /// runs r's body on those values (first execution and re-execution alike).
  void attach_and_invoke_many(detail::ReadNode* r, bool attached = false);
  [[noreturn]] static void throw_read_many_size();
  void push_close(Stamp* end, TaskKind kind, void* node);
  void close_chain(TaskKind kind, void* node);
  void discard_pending() noexcept;
  void link_write(ModBase& m, detail::VersionBase* v);
  /// link_write's move of older's readers timed after v onto v, when a version newer than v
  /// follows it closely; false (nothing done) when the stretch between is too long to walk.
  bool move_readers_between(ModBase& m, detail::VersionBase* older, detail::VersionBase* v,
                            detail::VersionBase* newer, bool same);
  /// Hangs r, a reader of older timed after v, on v; queues it when the new value (`same`:
  /// equal to older's) affects it.
  void move_reader(detail::ReaderLink* r, ModBase& m, detail::VersionBase* older, detail::VersionBase* v, bool same);
  /// link_write's move of older's readers timed after v onto v (which has none): older's
  /// unordered readers, and its ordered ones up to the first before v. v's readers come out
  /// ordered. O(moved + older's unordered readers).
  void move_readers_after(ModBase& m, detail::VersionBase* older, detail::VersionBase* v, bool same);
  /// Moves readers in fold_scratch_ (unordered readers of older) to their places among
  /// older's ordered readers, as far as a walk of about as many of those reaches; the others
  /// stay unordered. Empties fold_scratch_.
  void fold_unordered(detail::VersionBase* older);
  /// Sorts xs newest first by their reads' start times.
  void sort_newest_first(std::vector<detail::ReaderLink*>& xs) const;
  /// Links `run` (a null-ended chain of readers, newest first) and the readers in
  /// order_scratch_ into one chain, newest first and all ordered, from *at on, followed by
  /// `tail` (a chain, or null); empties order_scratch_. O(order_scratch_ + the run up to the
  /// last of those), plus the run's length when tail is not null.
  void link_merged(detail::ReaderLink** at, detail::ReaderLink* run, detail::ReaderLink* tail);
  void unlink_version(ModBase* m, detail::VersionBase* v);  // v a version of m
  void link_alloc(detail::AllocNode* n, std::size_t h);
  void link_memo(detail::MemoNode* n, std::size_t h);
  /// Makes fresh m's base value: a new base version, or, with `assign`, moved into the base
  /// version m has (nothing happens when the values are equal, and readers the change
  /// affects are queued). assign(base, fresh) gives base fresh's value and returns true when
  /// it swapped them (fresh then holds the old value, which queued readers may keep as what
  /// they saw: note_change).
  void set_base(ModBase& m, detail::VersionBase* fresh, bool (*assign)(detail::VersionBase*, detail::VersionBase*));
  detail::ReadNode* find_read_match(const ModBase& m, std::uint32_t ops_id,
                                    const void* closure) const;
  detail::AllocNode* find_alloc_match(std::uint16_t ops_id, std::size_t h, const void* key) const;
  detail::MemoNode* find_memo_match(std::uint16_t ops_id, std::size_t h, const void* closure) const;
  /// The earliest record that candidates(offer) offers, matches accepts and the window
  /// holds; null if none (engine.cpp).
  template <class N, class Candidates, class Matches>
  N* earliest_match(Candidates&& candidates, Matches&& matches) const;
  void reuse_alloc(detail::AllocNode* n);
  void memo_hit(Stamp* start, Stamp* end);
  /// Is `to` at most k stamps after from's successor? O(k).
  bool within(const Stamp* from, const Stamp* to, std::uint32_t k) const noexcept;
  static void* closure_of(detail::ReadNode* r) { return static_cast<detail::ReadNode*>(r) + 1; }
  void undo_between(Stamp* a, Stamp* b);
  void undo(Stamp* s);
  /// Reader l of m saw `before` and now sees `after`, a different value. Queues its read
  /// for re-execution unless it is a read of a projection that says the change does not
  /// affect it (a multi-read waits with no modifiable: its slots name theirs). A read of a
  /// projection, with `lazy`, is listed: `before` stays alive until propagate() ends
  /// (undone versions are freed then), and the read is re-run only if what it sees when it
  /// is popped still differs from `before` (or a follow() fails): the trace before it is
  /// final by then, and a change undone or redone in between (a version undone and written
  /// again) costs no re-execution. A listed read already queued records `before` for a
  /// slot not yet recorded, and what the slot sees now. Without `lazy` (a value that will
  /// not stay alive: a default, a base value of a type set() cannot swap) and for a plain
  /// read, it is re-run whatever it sees. Returns whether it recorded `before`.
  bool note_change(detail::ReaderLink* l, const ModBase& m, const detail::VersionBase* before,
                   const detail::VersionBase* after, bool lazy);
  /// Does r, just popped, see anything other than what it saw when it last ran?
  bool still_affected(detail::ReadNode* r, const QueueAux& a);
  /// Re-executes r, a read of m (null for a multi-read), inside its own interval (an
  /// affected read just popped).
  void rerun(detail::ReadNode* r, const ModBase* m);
  void free_deferred() noexcept;
  void index_pending_allocs();
  void destroy_all() noexcept;

  detail::VersionBase* visible(const ModBase& m, const Stamp* t) const;
  /// What a read of m at t sees: the visible version; else, when m has a default
  /// (init_default), the type's shared default if m has no version (the read then hangs on
  /// m: attach_default), or m's default made into its base version; else null. `ops`: m's
  /// version type.
  const detail::VersionBase* visible_or_default(const ModBase& m, const Stamp* t, const detail::VersionOps* ops) {
    // At the trace's end (every from-scratch read) the newest version is the one visible.
    if (t->next() == nullptr)
      if (const detail::VersionBase* v = m.newest()) return v;
    return visible_or_default_slow(m, t, ops);
  }
  const detail::VersionBase* visible_or_default_slow(const ModBase& m, const Stamp* t,
                                                     const detail::VersionOps* ops);
  /// Hangs r on what it sees, v (from visible_or_default).
  static void attach_seen(detail::ReaderLink* r, const ModBase& m, const detail::VersionBase* v) {
    if (m.default_only()) attach_default(r, m);
    else detail::attach_timed(r, const_cast<detail::VersionBase*>(v));
  }
  /// m's default made into its base version, if m has a default (init_default) and no base
  /// version yet (m's default readers move onto it); else null. `defaulted`: whether m has
  /// a default.
  detail::VersionBase* default_base(ModBase& m, bool defaulted, const detail::VersionOps* ops);
  /// The oldest version's link for m: the modifiable, its end mark and its default flag.
  static std::uintptr_t end_link(const ModBase& m, bool defaulted) {
    return reinterpret_cast<std::uintptr_t>(&m) | detail::VersionBase::kEnd |
           (defaulted ? detail::VersionBase::kDefaulted : 0);
  }
  bool in_window(const Stamp* start, const Stamp* end) const {
    return order_.less(now_, start) && order_.less(end, window_end_);
  }
  /// Hangs r on m's default (m has a default and no version).
  static void attach_default(detail::ReaderLink* r, const ModBase& m) {
    ModBase& w = const_cast<ModBase&>(m);
    detail::push_default_reader(r, &w.head_, w.default_readers());
  }

  detail::Pool pool_;
  detail::OrderList order_;
  ReadQueue queue_{order_};
  detail::IntrusiveHash<detail::AllocNode> allocs_;
  detail::IntrusiveHash<detail::MemoNode> memos_;
  std::vector<detail::AllocNode*> deferred_;   // undone allocations, freed by propagate()
  std::vector<detail::VersionBase*> dead_versions_;  // undone versions, freed by propagate()
  std::vector<Seen> seen_;                      // the queued reads' lists (note_change)
  std::vector<detail::ReaderLink*> order_scratch_;  // readers being put in time order
  std::vector<detail::ReaderLink*> fold_scratch_;   // unordered readers being folded (fold_unordered)
  // Keyed allocations of the running run() with their hashes: nothing can look them up
  // before the run ends (there is no re-execution window), so they are indexed in one
  // presized pass at its end, reading this array sequentially and only storing into the
  // (cold) records, instead of through log n table doublings that reload every record.
  struct PendingAlloc {
    detail::AllocNode* node;
    std::size_t hash;
  };
  detail::SegmentArray<PendingAlloc> pending_;
  std::vector<detail::VersionBase*> bases_;    // base versions; index kept in stamp.label
  std::vector<Task> tasks_;                    // the trampoline's stack
  void* context_ = nullptr;             // set_context()
  const void* context_type_ = nullptr;  // its type's tag
  [[noreturn]] static void throw_bad_context();
  std::vector<RerunContext> reruns_;           // contexts saved by the running re-executions
  // The running body's issued calls are the tasks at and above this index, in issue order
  // until the body returns (or flushes) and they are reversed to run first to last.
  std::size_t body_mark_ = 0;
  std::size_t close_floor_ = 0;                // closes below this may not be chained onto

  Stamp* now_ = nullptr;          // events are inserted after this stamp
  Stamp* window_end_ = nullptr;   // end of the re-execution window; null when running fresh
  Stamp* tail_ = nullptr;         // last stamp of the last run()
  bool in_computation_ = false;
  bool poisoned_ = false;
  Stats stats_;
  std::size_t input_bytes_ = 0;
};

}  // namespace sac

// The template bodies (CDT-style: the declarations above, the definitions there).
#include "sac/detail/engine_impl.hpp"
