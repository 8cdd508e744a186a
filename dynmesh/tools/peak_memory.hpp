// dynmesh/tools/peak_memory.hpp — this process's peak resident memory, and a reset of it, so
// that a phase of a run can be measured on its own (private to the tools).
//
// Purpose: `dynmesh-mpi --stats` reports each rank's peak resident memory over the run, and
// with its hidden --measure-writing over the writing of the output alone (docs/DISTRIBUTED.md,
// "Writing the output"): the writer must not hold what it lists, and the run's peak is the
// trees'. The reset restarts the kernel's own count, which an outside measure of the
// process's peak (getrusage, /usr/bin/time) reads too.
// Reads VmHWM from /proc/self/status; resets it by writing "5" to /proc/self/clear_refs
// (Linux 4.0 and later). Either may be unavailable (no /proc, a kernel that refuses): the
// peak is then -1 and the reset reports false.
// Complexity: one small file read or write.
// Paper: none.
#pragma once

#include <cstddef>
#include <cstdio>
#include <cstring>

namespace dynmesh::tool {

/// A "Vm...:" figure of /proc/self/status (its key with the colon) in MiB, or -1.
inline double status_mib(const char* key) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return -1;
  char line[256];
  double mib = -1;
  const std::size_t n = std::strlen(key);
  while (std::fgets(line, sizeof line, f)) {
    long kib = 0;
    if (std::strncmp(line, key, n) == 0 && std::sscanf(line + n, "%ld", &kib) == 1) {
      mib = static_cast<double>(kib) / 1024.0;
      break;
    }
  }
  std::fclose(f);
  return mib;
}

/// The peak resident set (VmHWM) in MiB, or -1 when /proc does not say.
inline double peak_rss_mib() { return status_mib("VmHWM:"); }
/// The resident set now (VmRSS) in MiB, or -1.
inline double rss_mib() { return status_mib("VmRSS:"); }

/// Resets the peak to the present resident set; false when the kernel does not allow it.
inline bool reset_peak_rss() {
  std::FILE* f = std::fopen("/proc/self/clear_refs", "w");
  if (!f) return false;
  const bool ok = std::fputs("5", f) >= 0;
  return std::fclose(f) == 0 && ok;
}

}  // namespace dynmesh::tool
