// trace_nodes.cpp — the process-wide numbering of read ops tables (see trace_nodes.hpp).
//
// Purpose: give each read ops table a number, so that a read stores 4 bytes for its ops.
// Invariants: a table keeps its number for the life of the process; entry 0 is never used.
// Complexity: O(1) per new read type.
// Paper: docs/DESIGN.md, "The runtime".
#include "sac/detail/trace_nodes.hpp"

#include <atomic>
#include <string>

#include "sac/errors.hpp"

namespace sac::detail {

// Zero-initialised before any dynamic initialisation; only the entries in use are touched.
const ReadOps* read_ops_table[kMaxReadTypes];

std::uint32_t register_read_ops(const ReadOps* ops) {
  // Each table registers once (ReadOpsFor::id's static), so numbers are never reused; the
  // caller's static guard publishes the entry written here to other threads.
  static std::atomic<std::uint32_t> next{1};
  const std::uint32_t i = next.fetch_add(1, std::memory_order_relaxed);
  if (i >= kMaxReadTypes)
    throw UsageError("sac: more than " + std::to_string(kMaxReadTypes - 1) + " read closure types");
  read_ops_table[i] = ops;
  return i;
}

}  // namespace sac::detail
