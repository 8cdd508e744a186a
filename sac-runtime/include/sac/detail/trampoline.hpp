// sac/detail/trampoline.hpp — the units of work of the Engine's trampoline.
//
// Purpose: read/memo_read/memo calls are pushed as Tasks on an explicit stack
// (Engine::tasks_) when issued, and run after the issuing body returns, so that deep
// recursion never grows the C++ stack; closing an interval, re-executing a read and jumping
// over a reused stretch are Tasks on the same stack. A body's calls lie above
// Engine::body_mark_ in issue order until it returns, and are then reversed in place, so a
// body's one tail call is never copied.
// Invariants: an Exec* task carries a record that is not in the trace yet; a Close* task's
// record has its start stamp linked and not its end, whose link field chains the records to
// close right after it (low bit set: a memo entry; 0 ends the chain); Engine::reruns_ holds
// one RerunContext per FinishRerun on the stack.
// Complexity: a task is 16 bytes; push and pop O(1).
// Paper: docs/DESIGN.md, "The runtime".
#pragma once

#include <cstdint>

#include "sac/detail/order_list.hpp"

namespace sac::detail {

enum class TaskKind : std::uint8_t {
  ExecRead,      // link a new read, attach it and run its body
  ExecMemoRead,  // ExecRead, unless an equal read in the window is reused
  ExecReadMany,  // link a new multi-read, attach its slots and run its body
  ExecMemo,      // link a new memo entry and run it, unless an equal one is reused
  CloseRead,     // link the end stamp of a read (and of the closes chained onto it)
  CloseMemo,     // the same for a memo entry
  FinishRerun,   // undo what the re-execution did not redo; restore the saved context
  DrainUntil     // re-execute the affected reads before a stamp, then continue after it
};

/// An ExecMemo task's arg: how many stamps of the old trace a reused call may lie ahead of
/// now (Engine::memo_near); kAnyDistance for memo().
inline constexpr std::uint32_t kAnyDistance = ~std::uint32_t{0};

struct Task {
  TaskKind kind;
  std::uint32_t arg;  // ExecMemo: the bound above; 0 otherwise (in the padding: 16 bytes)
  void* node;         // the record, or for DrainUntil the stamp to drain up to
};

/// The insertion point and window a re-execution replaces, restored when it finishes.
struct RerunContext {
  Stamp* now;
  Stamp* window_end;
};

}  // namespace sac::detail
