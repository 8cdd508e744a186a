// trace_nodes.cpp — the process-wide numbering of ops tables (see trace_nodes.hpp).
//
// Purpose: give each ops table a 16-bit number of its kind, which its records keep in bits
// no pointer uses instead of an 8-byte pointer.
// Invariants: a table keeps its number for the life of the process; entry 0 is never used.
// Complexity: O(1) per new record type.
// Paper: docs/DESIGN.md, "The runtime".
#include "sac/detail/trace_nodes.hpp"

#include <atomic>
#include <string>

#include "sac/errors.hpp"

namespace sac::detail {

// Zero-initialised before any dynamic initialisation; only the entries in use are touched.
const VersionOps* version_ops_table[kMaxOpsTypes];
const ReadOps* read_ops_table[kMaxOpsTypes];
const AllocOps* alloc_ops_table[kMaxOpsTypes];
const MemoOps* memo_ops_table[kMaxOpsTypes];

namespace {

// Each table registers once (its XOpsFor::id()'s static), so numbers are never reused; the
// caller's static guard publishes the entry written here to other threads.
template <class Ops>
std::uint16_t register_in(const Ops** table, std::atomic<std::uint32_t>& next, const Ops* ops, const char* what) {
  const std::uint32_t i = next.fetch_add(1, std::memory_order_relaxed);
  if (i >= kMaxOpsTypes)
    throw UsageError("sac: more than " + std::to_string(kMaxOpsTypes - 1) + " " + what + " types");
  table[i] = ops;
  return static_cast<std::uint16_t>(i);
}

std::atomic<std::uint32_t> next_version{1}, next_read{1}, next_alloc{1}, next_memo{1};

}  // namespace

std::uint16_t register_version_ops(const VersionOps* ops) {
  return register_in(version_ops_table, next_version, ops, "modifiable value");
}
std::uint16_t register_read_ops(const ReadOps* ops) {
  return register_in(read_ops_table, next_read, ops, "read closure");
}
std::uint16_t register_alloc_ops(const AllocOps* ops) {
  return register_in(alloc_ops_table, next_alloc, ops, "allocation");
}
std::uint16_t register_memo_ops(const MemoOps* ops) {
  return register_in(memo_ops_table, next_memo, ops, "memo closure");
}

}  // namespace sac::detail
