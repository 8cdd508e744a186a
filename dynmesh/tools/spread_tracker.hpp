// dynmesh/tools/spread_tracker.hpp — log2(L/s) of a changing point set, exact after every
// update (private to the tool).
//
// Purpose: `stability` reports the spread of the point set after each update
// (docs/FORMATS.md, "`dynmesh stability`", asks for the spread "at that time"), for the updates UpdateDriver makes and for those of an
// edit file alike, without rerunning a closest-pair computation per update:
//   * insertion of p: s ← min(s, distance from p to its nearest present point);
//   * deletion of p: s can only change if p is an end of a closest pair, i.e. if p's
//     nearest-neighbour distance equals s; only then s is recomputed with
//     closest_pair_distance (expected O(n)).
// The nearest-neighbour distance is a brute-force scan of the present points: O(n) per
// update, but outside the timed propagation, and a few milliseconds even at n = 10^6.
// Distances are computed exactly as closest_pair_distance computes them (square root of
// the sum of squared differences, in axis order), so the tracked s is bit-identical to a
// recomputation.
//
// Invariants: present() holds exactly the points reported to it (the structure's, when the
// caller reports every successful update), with their ids; spread_s() equals
// closest_pair_distance(present points).
// Complexity: inserted() O(n); erased_at() O(n), plus an expected O(n) recomputation when a
// closest pair loses an end; find() O(n).
// Paper: Acar & Hudson, Section 1 (spread L/s).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/io.hpp"

namespace dynmesh::tool {

template <std::size_t d>
class SpreadTracker {
 public:
  /// Starts from the points present (a structure's points()) in a box of side `side`.
  SpreadTracker(std::vector<std::pair<PointId, Point<d>>> present, double side)
      : present_(std::move(present)), side_(side) {
    const std::vector<Point<d>> pts = coordinates();
    s_ = closest_pair_distance<d>(pts);
  }

  /// p was inserted with this id.
  void inserted(PointId id, const Point<d>& p) {
    s_ = std::min(s_, nearest(p, present_.size()));
    present_.emplace_back(id, p);
  }

  /// present()[k] was erased. The last present point takes its place.
  void erased_at(std::size_t k) {
    const Point<d> p = present_[k].second;
    const bool in_closest_pair = nearest(p, k) == s_;
    present_[k] = present_.back();
    present_.pop_back();
    if (in_closest_pair) {
      const std::vector<Point<d>> pts = coordinates();
      s_ = closest_pair_distance<d>(pts);
    }
  }

  /// The index in present() of the point with exactly these coordinates.
  std::optional<std::size_t> find(const Point<d>& p) const {
    for (std::size_t k = 0; k < present_.size(); ++k)
      if (present_[k].second == p) return k;
    return std::nullopt;
  }

  /// log2(L / s) of the present points (+inf if s = 0, −inf with fewer than two points).
  double log2_spread() const {
    if (present_.size() < 2) return -std::numeric_limits<double>::infinity();
    if (s_ == 0) return std::numeric_limits<double>::infinity();
    return std::log2(side_ / s_);
  }
  double spread_s() const noexcept { return s_; }
  const std::vector<std::pair<PointId, Point<d>>>& present() const noexcept { return present_; }
  std::vector<Point<d>> coordinates() const {
    std::vector<Point<d>> pts;
    pts.reserve(present_.size());
    for (const auto& entry : present_) pts.push_back(entry.second);
    return pts;
  }

 private:
  static double distance(const Point<d>& a, const Point<d>& b) {
    double s = 0;
    for (std::size_t k = 0; k < d; ++k) s += (a[k] - b[k]) * (a[k] - b[k]);
    return std::sqrt(s);
  }

  // Distance from p to the nearest present point other than present_[skip].
  double nearest(const Point<d>& p, std::size_t skip) const {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < present_.size(); ++i)
      if (i != skip) best = std::min(best, distance(p, present_[i].second));
    return best;
  }

  std::vector<std::pair<PointId, Point<d>>> present_;
  double side_;
  double s_ = std::numeric_limits<double>::infinity();
};

}  // namespace dynmesh::tool
