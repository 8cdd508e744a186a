// sac/stats.hpp — counters kept by the engine.
//
// Purpose: what change propagation did, for tests ("a single insertion re-executes O(1)
// reads") and for the stability experiments (trace distance per update).
// Trace distance of a propagation = events created + events undone during it (docs/DESIGN.md, "Trace distance").
// An event is one trace record: a read, a write, an allocation or a memo entry.
// Invariants: live_events == events created - events undone (over the engine's life).
// Complexity: all O(1) to read.
// Paper: docs/DESIGN.md, "Trace distance".
#pragma once

#include <cstdint>
#include <ostream>

namespace sac {

struct Stats {
  std::uint64_t events_created = 0;
  std::uint64_t events_undone = 0;
  std::uint64_t reads_reexecuted = 0;
  /// Lookups of memo(), memo_near() and memo_read() calls during change propagation (none
  /// from scratch) that reused an old call or read, and those that ran anew.
  std::uint64_t memo_hits = 0;
  std::uint64_t memo_misses = 0;
  /// memo_near calls whose equal old call lay too far ahead (counted in memo_misses too).
  std::uint64_t memo_far = 0;
  std::uint64_t alloc_reuses = 0;
  std::uint64_t queue_pushes = 0;
  std::uint64_t queue_pops = 0;
  std::uint64_t queue_removes = 0;
  /// Reads of a projection popped and not re-executed: at their time, each changed slot
  /// showed what the read had seen when it last ran (a change undone, or redone to an equal
  /// value, before propagation reached it), or follow() moved it (reads_followed).
  std::uint64_t reads_unaffected = 0;
  /// Slots of multi-reads moved to another modifiable by their closure's follow() instead of
  /// re-running (Engine::read_many).
  std::uint64_t reads_followed = 0;
  /// Readers whose time a re-executed write tested, to find those that see it now: the
  /// version's unordered readers, its ordered ones up to the first before the write, and
  /// those the fold of the unordered ones into order walked (Engine::link_write).
  std::uint64_t readers_tested = 0;
  /// Readers passed one by one (relinked in time order, or walked to a run's end) when a
  /// version's readers moved onto another: an undone version's onto the version before it,
  /// or the readers after a re-executed write onto it. A list that moves whole costs none.
  std::uint64_t readers_relinked = 0;
  std::uint64_t propagations = 0;
  std::uint64_t live_events = 0;
  /// Trace distance (created + undone) of the last propagate().
  std::uint64_t last_trace_distance = 0;
  /// Reads re-executed by the last propagate().
  std::uint64_t last_reexecuted = 0;

  friend std::ostream& operator<<(std::ostream& os, const Stats& s) {
    return os << "created=" << s.events_created << " undone=" << s.events_undone
              << " reexecuted=" << s.reads_reexecuted << " memo_hits=" << s.memo_hits
              << " memo_misses=" << s.memo_misses << " memo_far=" << s.memo_far << " alloc_reuses=" << s.alloc_reuses
              << " queue_pushes=" << s.queue_pushes << " queue_pops=" << s.queue_pops
              << " queue_removes=" << s.queue_removes << " unaffected=" << s.reads_unaffected
              << " followed=" << s.reads_followed << " readers_tested=" << s.readers_tested
              << " readers_relinked=" << s.readers_relinked << " live_events=" << s.live_events
              << " last_trace_distance=" << s.last_trace_distance;
  }
};

}  // namespace sac
