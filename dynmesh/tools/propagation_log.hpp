// dynmesh/tools/propagation_log.hpp — the figures of a run's propagations (private to the
// tool).
//
// Purpose: `demo` and `mesh --edits --stats` report the same figures of their propagations,
// measured the same way: the time of each (UpdateStats::seconds, the wall time of the
// propagation as the structure measures it, which UpdateDriver hands on), its trace distance,
// and for a mesh the triangles (tetrahedra in 3D) it changed (removed + added: the sizes of
// the change feed).
// PropagationLog records them one propagation at a time and gives count, means, medians and
// maxima; format_propagation_stats writes the lines `mesh --stats` adds after the quality
// report, in that report's style (format_stats in mesh_io.hpp).
// Invariants: the three series have one entry per recorded propagation, in order; every
// figure of an empty log is 0.
// Complexity: record() O(1) amortized; a mean or maximum O(k), a median O(k) expected
// (nth_element on a copy), for k propagations.
// Paper: none.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "dynmesh/dynamic_quadtree.hpp"

namespace dynmesh::tool {

/// The median of v (the mean of the two middle values for an even count; 0 when empty).
template <class T>
double median(std::vector<T> v) {
  if (v.empty()) return 0.0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double hi = static_cast<double>(v[mid]);
  if (v.size() % 2) return hi;
  const double lo = static_cast<double>(*std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
  return (lo + hi) / 2;
}

/// The mean of v (0 when empty).
template <class T>
double mean(const std::vector<T>& v) {
  double s = 0;
  for (const T& x : v) s += static_cast<double>(x);
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

/// The largest element of v (0 when empty).
template <class T>
double maximum(const std::vector<T>& v) {
  return v.empty() ? 0.0 : static_cast<double>(*std::max_element(v.begin(), v.end()));
}

class PropagationLog {
 public:
  /// One propagation of a mesh: its last_update() and last_change() (a MeshChange or a
  /// TetMeshChange).
  template <class Change>
  void record(const UpdateStats& stats, const Change& change) {
    seconds_.push_back(stats.seconds);
    distances_.push_back(stats.trace_distance);
    changed_.push_back(change.removed.size() + change.added.size());
  }

  std::size_t count() const noexcept { return seconds_.size(); }
  const std::vector<double>& seconds() const noexcept { return seconds_; }
  const std::vector<std::uint64_t>& distances() const noexcept { return distances_; }
  const std::vector<std::size_t>& changed() const noexcept { return changed_; }

 private:
  std::vector<double> seconds_;
  std::vector<std::uint64_t> distances_;
  std::vector<std::size_t> changed_;
};

/// The lines `mesh --edits --stats` prints after the quality report: a blank line, then
///   Propagation statistics:
///
///     Propagations: 12    Edits: 12
///
///     Mean time:      1.23e-05 s    |  Median time:    1.1e-05 s
///     Maximum time:   4.5e-05 s     |  Mean trace distance: 1234.5
///     Mean triangles changed: 23.4 (removed + added)
/// (only the first two lines when there was no propagation; `cells` names what changed:
/// "triangles", or "tetrahedra" in 3D). Numbers have six significant digits at most.
inline std::string format_propagation_stats(const PropagationLog& log, std::size_t edits,
                                            const char* cells = "triangles") {
  auto number = [](double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", x);
    return std::string(buf);
  };
  auto pad = [](std::string s, std::size_t width) {
    if (s.size() < width) s.append(width - s.size(), ' ');
    return s;
  };
  std::string out = "\nPropagation statistics:\n\n";
  out += "  Propagations: " + std::to_string(log.count()) + "    Edits: " + std::to_string(edits) + "\n";
  if (log.count() == 0) return out;
  out += "\n";
  out += "  " + pad("Mean time:", 16) + pad(number(mean(log.seconds())) + " s", 14) + "|  " + pad("Median time:", 16) +
         number(median(log.seconds())) + " s\n";
  out += "  " + pad("Maximum time:", 16) + pad(number(maximum(log.seconds())) + " s", 14) +
         "|  Mean trace distance: " + number(mean(log.distances())) + "\n";
  out += std::string("  Mean ") + cells + " changed: " + number(mean(log.changed())) + " (removed + added)\n";
  return out;
}

}  // namespace dynmesh::tool
