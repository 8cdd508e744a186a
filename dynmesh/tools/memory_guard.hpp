// dynmesh/tools/memory_guard.hpp — refuse a build that cannot fit in memory, before it starts.
//
// Purpose: a dynamic quadtree keeps its whole trace, kilobytes per point, so a
// few million points can exceed the machine; without a guard the run is killed by the OOM
// killer (or fails with bad_alloc) minutes into the build. The commands estimate the peak
// from the number of points the structure will hold (initial points plus those the edits
// insert) and a measured cost per point, compare it with the memory available, and stop at
// once with one line when it does not fit; `--force` skips the guard.
//   * The point counts come from counting lines (points_held), a
//     cheap scan that precedes the expensive parse; it may overcount (a malformed line is
//     counted, the parser reports it later), never undercount a valid regular file (a pipe
//     is not read ahead: it counts as empty).
//   * Available memory is the least of MemAvailable (/proc/meminfo) and what remains under
//     the finite soft limits RLIMIT_AS (`ulimit -v`, less the current VmSize) and RLIMIT_DATA
//     (`ulimit -d`, less the current VmData). Control-group limits are not read. Where
//     /proc/meminfo cannot be read (a container that hides or lacks /proc), the machine's
//     physical memory (sysconf(_SC_PHYS_PAGES): glibc asks sysinfo(2), not /proc) stands in
//     for MemAvailable, and the message names it, so that a build larger than the whole
//     machine is still refused at once rather than left to the OOM killer.
//   * A build the guard lets go on is held to what it found: the soft RLIMIT_DATA is lowered
//     to the current VmData plus the available amount (never raised). The estimate is per
//     point, and some inputs cost more than any constant foresees (points along a line in
//     3D cost about twice the 3D estimate), so a build can still
//     outgrow the machine; capped, it fails with std::bad_alloc, which the command reports
//     with the guard's figures (out_of_memory_message), instead of thrashing or being
//     killed, possibly with other processes, by the OOM killer. VmData follows the peak
//     resident set closely here (compare the largest VmData and VmHWM of /proc/PID/status,
//     sampled during `dynmesh quadtree FILE --cells o.cells --force`), so the cap stops a
//     build only when it is close to not fitting.
// Invariants: the guard throws only when the estimate exceeds a known available amount; when
// nothing can be read (no /proc and no physical memory size) it lets the run go on; without
// /proc/self/status (VmData) it does not cap the data size. --force skips both.
// Complexity: O(bytes of the point and edit files) for the line counts; O(1) otherwise.
// Paper: none.
#pragma once

#include <cinttypes>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "dynmesh/errors.hpp"
#include "dynmesh/io.hpp"

namespace dynmesh::tool {

/// The peak resident memory of a build per point it holds, and what --check adds on top.
struct MemoryCost {
  std::uint64_t bytes_per_point;
  std::uint64_t check_bytes_per_point;  // the from-scratch rebuild of --check (and stability)
};

// How each cost is calibrated: on x86-64 (-O2, glibc malloc), the peak RSS ("Maximum
// resident set size" of /usr/bin/time -v) of the command beside it, less that of a run on a
// handful of points (the program itself), over n; then a margin added, because the cost per
// point grows slowly with n and clustered points cost a little more than uniform ones. Under
// `ulimit -v` set to the estimate, the calibration runs complete. The inputs are uniform
// points written by python3 (random.random(), repr), n = 10^5 unless said otherwise.
//   /usr/bin/time -v dynmesh quadtree u2_100000.txt --cells o.cells [--check]
inline constexpr MemoryCost kQuadtree2dCost{10'500, 4'500};
//   /usr/bin/time -v dynmesh quadtree u3_100000.txt --dim 3 --cells o.cells [--check]
inline constexpr MemoryCost kOctree3dCost{20'500, 5'600};
//   /usr/bin/time -v dynmesh mesh u2_100000.txt --postprocess quadtree -o o [--check]
inline constexpr MemoryCost kQuadtreeMeshCost{92'000, 14'000};
// The octree's tetrahedral mesh (DynamicOctreeMesh, `dynmesh mesh` in 3D), calibrated as
// above on a smaller input (python3 random.Random(3), uniform in the unit cube, with
// deletions and their reinsertions as edits): the peak follows the tetrahedra per point (the
// trace, the index mesh and its text). --check's own cost is the static twin's tetrahedra
// held as coordinates and the checker's face lists.
//   /usr/bin/time -v dynmesh mesh u5e3.xyz --edits u5e3.edits -o o [--check]
inline constexpr MemoryCost kOctreeMeshCost{135'000, 250'000};
// The hpu meshes cost more per point as the angle bound rises (more Steiner points), and
// far more on points along curves than on uniform ones: the mesh grades away from each dense
// curve, so collinear and spiral points make several times the vertices (and trace) per
// point. Counting lines cannot tell the inputs apart, and an estimate below the peak lets a
// run be killed minutes in, so the guard takes the costliest input, at 20.7 and at 30
// degrees, interpolated linearly in the angle between them (the 20.7-degree cost below it:
// smaller bounds make smaller meshes), with a margin (hpu_mesh_cost, hpu_dynamic_cost).
// Calibrated with generate(D, n, 1) for each distribution D (the generators of
// `dynmesh stability --dist`, written with %.17g), less the program itself, as above;
// --check's own cost is the largest on any input. A uniform input is therefore
// overestimated severalfold: --force runs it.
//   The hpu mesh (HpuMesh, no trace):
//     dynmesh mesh P.txt -o o --min-angle A [--check]
//   The self-adjusting hpu mesh (DynamicMesh, Postprocess::Hpu: the program on cells and its
//   trace; --edits selects it), with a few edits:
//     dynmesh mesh P.txt --edits E -o o --min-angle A [--check]
inline constexpr double kHpuCostAngleLow = 20.7, kHpuCostAngleHigh = 30.0;
inline constexpr MemoryCost kHpuMeshCostLow{1'400, 600}, kHpuMeshCostHigh{2'600, 1'050};
inline constexpr MemoryCost kHpuDynamicCostLow{25'000, 6'500}, kHpuDynamicCostHigh{45'000, 12'500};

/// low at angle ≤ kHpuCostAngleLow, high at kHpuCostAngleHigh, linear in between.
inline MemoryCost hpu_cost_at(const MemoryCost& low, const MemoryCost& high, double angle_deg) {
  double t = (angle_deg - kHpuCostAngleLow) / (kHpuCostAngleHigh - kHpuCostAngleLow);
  t = !(t > 0) ? 0 : t > 1 ? 1 : t;  // (a NaN angle, refused later anyway, as the lowest)
  const auto mix = [t](std::uint64_t a, std::uint64_t b) {
    return static_cast<std::uint64_t>(static_cast<double>(a) + t * (static_cast<double>(b) - static_cast<double>(a)));
  };
  return {mix(low.bytes_per_point, high.bytes_per_point), mix(low.check_bytes_per_point, high.check_bytes_per_point)};
}
/// The hpu mesh without --edits (HpuMesh) at this angle bound.
inline MemoryCost hpu_mesh_cost(double angle_deg) { return hpu_cost_at(kHpuMeshCostLow, kHpuMeshCostHigh, angle_deg); }
/// The self-adjusting hpu mesh (DynamicMesh) at this angle bound.
inline MemoryCost hpu_dynamic_cost(double angle_deg) {
  return hpu_cost_at(kHpuDynamicCostLow, kHpuDynamicCostHigh, angle_deg);
}
// The program before any point: a few MB resident, more address space (libraries, a thread stack).
inline constexpr std::uint64_t kFixedBytes = std::uint64_t{32} << 20;

/// The estimated peak of a build holding `points` points (saturating, never wraps).
inline std::uint64_t estimated_bytes(const MemoryCost& cost, std::uint64_t points, bool check) {
  const std::uint64_t per_point = cost.bytes_per_point + (check ? cost.check_bytes_per_point : 0);
  const std::uint64_t max = std::numeric_limits<std::uint64_t>::max();
  if (points > (max - kFixedBytes) / per_point) return max;
  return kFixedBytes + points * per_point;
}

/// "27.1 GiB", "512 MiB", "3.0 KiB": three significant figures at most, binary units.
inline std::string human_bytes(std::uint64_t bytes) {
  static const char* const units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double v = static_cast<double>(bytes);
  std::size_t u = 0;
  while (v >= 1024 && u + 1 < std::size(units)) {
    v /= 1024;
    ++u;
  }
  char buf[32];
  if (u == 0)
    std::snprintf(buf, sizeof buf, "%" PRIu64 " bytes", bytes);
  else if (v < 100)
    std::snprintf(buf, sizeof buf, "%.1f %s", v, units[u]);
  else
    std::snprintf(buf, sizeof buf, "%.0f %s", v, units[u]);
  return buf;
}

struct AvailableMemory {
  std::uint64_t bytes = 0;
  std::string source;  // what limits it, for the message
};

namespace detail {

// The value in kB of "<key>:" in a /proc file (/proc/meminfo, /proc/self/status), in bytes.
inline std::optional<std::uint64_t> proc_kb(const char* path, const std::string& key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size(), key) != 0 || line.size() <= key.size() || line[key.size()] != ':') continue;
    unsigned long long kb = 0;
    if (std::sscanf(line.c_str() + key.size() + 1, "%llu", &kb) != 1) return std::nullopt;
    return static_cast<std::uint64_t>(kb) * 1024;
  }
  return std::nullopt;
}

// What remains under the soft limit `resource`, given `used` bytes already counted against
// it; nullopt when the limit is infinite.
inline std::optional<std::uint64_t> under_limit(int resource, std::optional<std::uint64_t> used) {
  struct ::rlimit limit;
  if (::getrlimit(resource, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return std::nullopt;
  const auto cap = static_cast<std::uint64_t>(limit.rlim_cur);
  const std::uint64_t in_use = used.value_or(0);
  return cap > in_use ? cap - in_use : 0;
}

// The machine's physical memory in bytes (sysconf, which glibc answers with sysinfo(2), no
// /proc needed); nullopt when unknown.
inline std::optional<std::uint64_t> physical_memory() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return std::nullopt;
  const auto p = static_cast<std::uint64_t>(pages), s = static_cast<std::uint64_t>(page);
  return p > std::numeric_limits<std::uint64_t>::max() / s ? std::numeric_limits<std::uint64_t>::max() : p * s;
}

}  // namespace detail

/// The memory a build may use now; nullopt when nothing is known (no /proc, no limits).
inline std::optional<AvailableMemory> available_memory() {
  std::optional<AvailableMemory> best;
  auto consider = [&best](std::optional<std::uint64_t> bytes, const char* source) {
    if (bytes && (!best || *bytes < best->bytes)) best = AvailableMemory{*bytes, source};
  };
  if (const auto mem_available = detail::proc_kb("/proc/meminfo", "MemAvailable"))
    consider(mem_available, "MemAvailable in /proc/meminfo");
  else  // no /proc/meminfo: the whole machine's memory, an upper bound on what is available
    consider(detail::physical_memory(), "the machine's physical memory; /proc/meminfo is unreadable");
  consider(detail::under_limit(RLIMIT_AS, detail::proc_kb("/proc/self/status", "VmSize")),
           "under the address-space limit, ulimit -v");
  consider(detail::under_limit(RLIMIT_DATA, detail::proc_kb("/proc/self/status", "VmData")),
           "under the data-size limit, ulimit -d");
  return best;
}

/// What guard_memory let go on, and the cap it set: for the out-of-memory message.
struct GuardedBuild {
  std::string what;
  std::uint64_t estimate = 0;
  AvailableMemory available;
};
inline std::optional<GuardedBuild>& guarded_build() {
  static std::optional<GuardedBuild> build;
  return build;
}

namespace detail {

// Lowers the soft RLIMIT_DATA to the current VmData plus `bytes` (saturating; never raised, so
// never above the hard limit, which bounds the soft one). False when VmData or the limit
// cannot be read or set.
inline bool cap_data_size(std::uint64_t bytes) {
  const std::optional<std::uint64_t> in_use = proc_kb("/proc/self/status", "VmData");
  struct ::rlimit limit;
  if (!in_use || ::getrlimit(RLIMIT_DATA, &limit) != 0) return false;
  const std::uint64_t cap = bytes > std::numeric_limits<std::uint64_t>::max() - *in_use
                                ? std::numeric_limits<std::uint64_t>::max()
                                : *in_use + bytes;
  if (limit.rlim_cur != RLIM_INFINITY && static_cast<std::uint64_t>(limit.rlim_cur) <= cap) return true;
  if (cap >= static_cast<std::uint64_t>(RLIM_INFINITY)) return true;
  limit.rlim_cur = static_cast<rlim_t>(cap);
  return ::setrlimit(RLIMIT_DATA, &limit) == 0;
}

}  // namespace detail

/// Throws Error "<what> needs about X, but only Y are available (...); pass --force to try
/// anyway" when `estimate` exceeds the available memory. `what` names the build, e.g.
/// "building the quadtree of 2000000 points". Otherwise caps the data size at what is
/// available (see the header) and notes the build for out_of_memory_message().
inline void guard_memory(const std::string& what, std::uint64_t estimate) {
  const std::optional<AvailableMemory> available = available_memory();
  if (!available) return;
  if (estimate > available->bytes)
    throw Error(what + " needs about " + human_bytes(estimate) + ", but only " + human_bytes(available->bytes) +
                " are available (" + available->source + "); pass --force to try anyway");
  if (detail::cap_data_size(available->bytes)) guarded_build() = GuardedBuild{what, estimate, *available};
}

/// The one line a command prints for std::bad_alloc: after guard_memory let the build go
/// on, with its figures (the build outgrew its estimate); otherwise plainly.
inline std::string out_of_memory_message() {
  const std::optional<GuardedBuild>& b = guarded_build();
  if (!b)
    return "out of memory (std::bad_alloc); the run stopped before writing its outputs";
  return "out of memory: " + b->what + " was estimated at about " + human_bytes(b->estimate) +
         " and allowed the " + human_bytes(b->available.bytes) + " available (" + b->available.source +
         "), but needed more; it stopped before writing its outputs. The estimate is per point, and points "
         "along a line or a curve can need up to twice it; pass --force to run without the cap";
}

namespace detail {

// Calls on_line(first) for every line that is neither blank nor a '#' comment, with `first`
// its first character after leading blanks (a UTF-8 byte order mark at the start is skipped).
// A file that cannot be read counts nothing: its reader reports the error later. Nor does
// anything but a regular file: a pipe (/dev/stdin, <(...)) read here would be empty for the
// reader.
template <class OnLine>
void scan_data_lines(const std::string& path, OnLine on_line) {
  struct ::stat st;
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return;
  std::vector<char> buf(std::size_t{1} << 20);
  bool at_start = true;        // still in the leading blanks of a line
  std::size_t bom_left = 3;    // bytes of a possible byte order mark still to match
  static constexpr unsigned char kBom[3] = {0xef, 0xbb, 0xbf};
  std::size_t got = 0;
  while ((got = std::fread(buf.data(), 1, buf.size(), file)) > 0) {
    for (std::size_t i = 0; i < got; ++i) {
      const char c = buf[i];
      if (bom_left > 0) {
        if (static_cast<unsigned char>(c) == kBom[3 - bom_left]) {
          --bom_left;
          continue;
        }
        bom_left = 0;
      }
      if (c == '\n') {
        at_start = true;
      } else if (at_start && c != ' ' && c != '\t' && c != '\r') {
        at_start = false;
        if (c != '#') on_line(c);
      }
    }
  }
  std::fclose(file);
}

}  // namespace detail

/// The number of points a point file holds, counted from its lines (a .node header excluded).
inline std::uint64_t count_point_lines(const std::string& path, bool node_format) {
  std::uint64_t lines = 0;
  detail::scan_data_lines(path, [&lines](char) { ++lines; });
  return node_format && lines > 0 ? lines - 1 : lines;
}

/// The number of insertions ('+' lines) of an edit script.
inline std::uint64_t count_insert_lines(const std::string& path) {
  std::uint64_t inserts = 0;
  detail::scan_data_lines(path, [&inserts](char first) { inserts += first == '+'; });
  return inserts;
}

/// The most points a structure built on `points_path` and edited by `edits_path` (empty: no
/// edits) holds at once: the initial points and every point the edits insert.
inline std::uint64_t points_held(const std::string& points_path, const std::string& edits_path) {
  return count_point_lines(points_path, format_for_path(points_path) == PointFormat::Node) +
         (edits_path.empty() ? 0 : count_insert_lines(edits_path));
}

}  // namespace dynmesh::tool
