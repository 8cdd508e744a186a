// sac/memory_breakdown.hpp — where the bytes of a live trace go, by record kind.
//
// Purpose: Engine::memory_breakdown() walks the live trace and sorts Engine::trace_bytes()
// into the records that make it (reads and their closures, versions and their values, memo
// entries and their closures, keyed and unkeyed allocations) and the engine's side
// structures (order-list groups, the queue, the two hash tables), so that work on memory
// starts from measurements rather than guesses. It also reports what trace_bytes() leaves
// out: the base versions set by the mutator (input_bytes()), the engine's own vectors, and
// the pool's reserved but unused chunk bytes.
//
// Bytes are pool bytes: a record's size rounded up to the pool's 8-byte size class. Every
// record is 8-aligned, so the rounding adds nothing (size_class_rounding says so); padding
// inside a record counts with the part it follows (a Version<std::uint8_t> is a 40-byte
// header and an 8-byte value).
//
// Invariants (outside the computation): unaccounted == 0, so records() ==
// Engine::record_bytes() and trace() == Engine::trace_bytes() exactly; inputs.bytes() ==
// Engine::input_bytes(). Two engines whose traces are equal have equal record kinds (the
// side structures are capacities and may differ with their history).
// Complexity: Engine::memory_breakdown() is O(live events + base versions).
// Paper: docs/DESIGN.md, "The runtime".
#pragma once

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <utility>
#include <vector>

namespace sac {

/// Count and bytes of one kind of record.
struct RecordBytes {
  std::uint64_t count = 0;
  std::size_t header = 0;   // the fixed record: stamps, links, ops pointer
  std::size_t key = 0;      // keyed allocations only: the key and the padding after it
  std::size_t payload = 0;  // the closure, value or object, with the record's tail padding

  std::size_t bytes() const { return header + key + payload; }
  bool operator==(const RecordBytes&) const = default;
};

struct MemoryBreakdown {
  // ---- the live trace's records (Engine::record_bytes())
  RecordBytes reads;         // read() and memo_read(): ReadNode + the body's closure
  RecordBytes versions;      // writes by the computation: VersionBase + the value
  RecordBytes memos;         // memo(): MemoNode + the memoized closure
  RecordBytes keyed_allocs;  // alloc(key, ...): AllocNode + key + object
  RecordBytes plain_allocs;  // make(...): AllocNode + object
  /// The reads by record size (ReadNode and closure, as a pool block): (bytes, count),
  /// ascending. Each closure type has one size, so this shows which bodies cost most.
  std::vector<std::pair<std::size_t, std::uint64_t>> read_sizes;
  /// record_bytes() minus the records above: pool blocks that are not live trace records
  /// (0 outside the computation; nonzero would be a leak or a miscount).
  std::int64_t unaccounted = 0;

  // ---- the engine's side structures (capacities, as trace_bytes() counts them)
  std::size_t order_groups = 0;       // order-list groups in use
  std::size_t order_bytes = 0;        // the order list's group array
  std::size_t queue_bytes = 0;        // the propagation queue's heap array
  std::size_t alloc_table_bytes = 0;  // the keyed-allocation table's bucket array
  std::size_t memo_table_bytes = 0;   // the memo table's bucket array
  std::size_t deferred_bytes = 0;     // the list of undone allocations awaiting their free

  // ---- not in trace_bytes()
  RecordBytes inputs;               // base versions set by the mutator (input_bytes())
  std::size_t engine_vectors = 0;   // the base-version index and the trampoline's stacks
  std::size_t pool_reserved = 0;    // bytes of the pool's chunks
  std::size_t pool_large = 0;       // live blocks over Pool::kMaxSmall, from operator new
  std::size_t size_class_rounding = 0;  // bytes the 8-byte size classes add (in the payloads)

  std::size_t records() const {
    return reads.bytes() + versions.bytes() + memos.bytes() + keyed_allocs.bytes() +
           plain_allocs.bytes();
  }
  std::size_t side_structures() const {
    return order_bytes + queue_bytes + alloc_table_bytes + memo_table_bytes + deferred_bytes;
  }
  /// == Engine::trace_bytes() when unaccounted == 0.
  std::size_t trace() const { return records() + side_structures(); }
  /// Chunk bytes holding no live block: the free lists, abandoned chunk tails and the
  /// uncarved rest of the current chunk.
  std::size_t pool_unused() const {
    const std::size_t small = records() + inputs.bytes() - pool_large;
    return pool_reserved > small ? pool_reserved - small : 0;
  }

  /// f(name, count, bytes) for each part of trace(), in a fixed order: the bytes sum to
  /// trace(). Side structures have count 0 but the order-list groups (groups in use).
  template <class F>
  void for_each_part(F&& f) const {
    f("read records", reads.count, reads.header);
    f("read closures", reads.count, reads.payload);
    f("version records", versions.count, versions.header);
    f("version values", versions.count, versions.payload);
    f("memo records", memos.count, memos.header);
    f("memo closures", memos.count, memos.payload);
    f("keyed alloc records", keyed_allocs.count, keyed_allocs.header);
    f("keyed alloc keys", keyed_allocs.count, keyed_allocs.key);
    f("keyed alloc objects", keyed_allocs.count, keyed_allocs.payload);
    f("unkeyed alloc records", plain_allocs.count, plain_allocs.header);
    f("unkeyed alloc objects", plain_allocs.count, plain_allocs.payload);
    f("order-list groups", static_cast<std::uint64_t>(order_groups), order_bytes);
    f("queue", std::uint64_t{0}, queue_bytes);
    f("allocation table", std::uint64_t{0}, alloc_table_bytes);
    f("memo table", std::uint64_t{0}, memo_table_bytes);
    f("deferred frees", std::uint64_t{0}, deferred_bytes);
  }

  friend std::ostream& operator<<(std::ostream& os, const MemoryBreakdown& b) {
    b.for_each_part([&](const char* name, std::uint64_t count, std::size_t bytes) {
      os << name << ": " << count << " / " << bytes << " B\n";
    });
    os << "trace: " << b.trace() << " B (unaccounted " << b.unaccounted << ")\n"
              << "inputs (base versions): " << b.inputs.count << " / " << b.inputs.bytes() << " B\n"
              << "engine vectors: " << b.engine_vectors << " B\n"
              << "pool: reserved " << b.pool_reserved << " B, unused " << b.pool_unused()
              << " B, large blocks " << b.pool_large << " B, size-class rounding "
              << b.size_class_rounding << " B\n";
    os << "read blocks (bytes x count):";
    for (const auto& [bytes, count] : b.read_sizes) os << ' ' << bytes << 'x' << count;
    return os << '\n';
  }
};

}  // namespace sac
