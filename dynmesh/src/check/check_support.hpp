// check_support.hpp (private) — what the 2D and the 3D mesh checkers share: the recorder of
// defects, the summary of a failed report, the closed domain box, the vertex lookup and the
// compensated sum of areas or volumes.
//
// Purpose: mesh_check.cpp and tet_mesh_check.cpp check the same kind of contract in two
// dimensions; the bookkeeping around the geometry is one piece of code, so that both report
// alike ("<defect name>: <details>", counted all, listed up to max_problems) and decide "on
// the box" by the same rule.
// Invariants: DefectRecorder counts every defect and keeps the first max_problems messages,
// building a message only when it is kept; ClosedBox's upper sides are fl(o + L), as the
// contracts state; PointLookup::contains is exact (coordinates compared as doubles).
// Complexity: DefectRecorder::add O(1) plus the message; PointLookup O(n log n) to build when
// the vertices are out of order (O(1) otherwise), O(log n) per query; the rest O(d).
// Paper: Neumaier, "Rundungsfehleranalyse einiger Verfahren zur Summation endlicher Summen"
// (1974) for the compensated sum.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh::detail {

/// Collects defects into a report (problems, truncated, counts): counts all, keeps the first
/// max_problems messages. The message is built only when it is kept, so a badly broken large
/// mesh stays cheap to check. `defect_name(Defect)` names the kind.
template <class Report, class Defect>
class DefectRecorder {
 public:
  DefectRecorder(Report& report, std::size_t max_problems) : report_(report), max_(max_problems) {}

  template <class Describe>
  void add(Defect defect, Describe&& describe) {
    ++report_.counts[static_cast<std::size_t>(defect)];
    if (report_.problems.size() < max_) {
      report_.problems.push_back(std::string(defect_name(defect)) + ": " + describe());
    } else {
      report_.truncated = true;
    }
  }

 private:
  Report& report_;
  std::size_t max_;
};

/// "<subject> invalid: N problems (kind n, ...)", then the problems, one an indented line,
/// and how many more were found than listed.
template <class Defect, class Report>
std::string invalid_summary(std::string_view subject, const Report& report) {
  std::size_t total = 0;
  std::string kinds;
  for (std::size_t k = 0; k < report.counts.size(); ++k) {
    if (report.counts[k] == 0) continue;
    total += report.counts[k];
    if (!kinds.empty()) kinds += ", ";
    kinds += std::string(defect_name(static_cast<Defect>(k))) + " " + std::to_string(report.counts[k]);
  }
  std::string s = std::string(subject) + " invalid: " + std::to_string(total) + " problem" + (total == 1 ? "" : "s") +
                  " (" + kinds + ")";
  for (const std::string& p : report.problems) s += "\n  " + p;
  if (report.truncated) s += "\n  ... (" + std::to_string(total - report.problems.size()) + " more)";
  return s;
}

/// The closed domain [o, fl(o + L)]^d: its side planes computed once, as the contracts state.
template <std::size_t d>
struct ClosedBox {
  Point<d> lo, hi;

  explicit ClosedBox(const Box<d>& box) {
    for (std::size_t a = 0; a < d; ++a) {
      lo[a] = box.origin[a];
      hi[a] = box.origin[a] + box.side;
    }
  }

  bool contains(const Point<d>& p) const noexcept {
    for (std::size_t a = 0; a < d; ++a)
      if (!(p[a] >= lo[a] && p[a] <= hi[a])) return false;
    return true;
  }

  /// All the points on one side plane (x_a == lo[a] for all, or x_a == hi[a] for all): the
  /// only edges (2D) or faces (3D) that a single simplex may use alone.
  template <std::size_t n>
  bool on_one_side(const std::array<Point<d>, n>& points) const noexcept {
    for (std::size_t a = 0; a < d; ++a) {
      const auto all_at = [&](double plane) {
        return std::all_of(points.begin(), points.end(), [&](const Point<d>& p) { return p[a] == plane; });
      };
      if (all_at(lo[a]) || all_at(hi[a])) return true;
    }
    return false;
  }

  /// The 2^d corners; corner k takes the upper side on axis a when bit a of k is set.
  std::array<Point<d>, (std::size_t{1} << d)> corners() const noexcept {
    std::array<Point<d>, (std::size_t{1} << d)> out{};
    for (std::size_t k = 0; k < out.size(); ++k)
      for (std::size_t a = 0; a < d; ++a) out[k][a] = (k >> a) & 1 ? hi[a] : lo[a];
    return out;
  }
};

/// Is a point one of the vertices? A binary search under the canonical vertex order `less`;
/// vertices out of that order (a Canonical defect, already reported) are searched in a
/// sorted copy.
template <std::size_t d, class Less>
class PointLookup {
 public:
  PointLookup(const std::vector<Point<d>>& vertices, bool sorted, Less less) : less_(less) {
    if (!sorted) {
      copy_ = vertices;
      std::sort(copy_.begin(), copy_.end(), less_);
    }
    points_ = sorted ? &vertices : &copy_;
  }
  PointLookup(const PointLookup&) = delete;
  PointLookup& operator=(const PointLookup&) = delete;

  bool contains(const Point<d>& p) const {
    const auto it = std::lower_bound(points_->begin(), points_->end(), p, less_);
    return it != points_->end() && !less_(p, *it);
  }

 private:
  Less less_;
  std::vector<Point<d>> copy_;
  const std::vector<Point<d>>* points_ = nullptr;
};

// ---- the checks on vertices alone, the same in 2D and 3D ------------------------------------
//
// Defect is MeshDefect or TetMeshDefect: both name the kinds below alike.

/// Canonical: each vertex strictly after the previous one under `less` ("(x, y)" order in
/// 2D, "(x, y, z)" in 3D, named by `order`). Returns whether they all are.
template <class Defect, std::size_t d, class Recorder, class Less>
bool check_vertex_order(const std::vector<Point<d>>& vertices, Less less, std::string_view order, Recorder& record) {
  bool sorted = true;
  for (std::size_t i = 1; i < vertices.size(); ++i) {
    if (less(vertices[i - 1], vertices[i])) continue;
    sorted = false;
    record.add(Defect::Canonical, [&] {
      return "vertices " + std::to_string(i - 1) + " " + to_string(vertices[i - 1]) + " and " + std::to_string(i) + " " +
             to_string(vertices[i]) + " are not in strictly increasing " + std::string(order) + " order";
    });
  }
  return sorted;
}

/// OutsideBox for every vertex outside the closed box, MissingCorner for every corner of it
/// that is not a vertex. `describe_vertex(i)` names vertex i in messages.
template <class Defect, std::size_t d, class Recorder, class Less, class DescribeVertex>
void check_box(const std::vector<Point<d>>& vertices, const ClosedBox<d>& domain, const PointLookup<d, Less>& lookup,
               Recorder& record, DescribeVertex&& describe_vertex) {
  for (std::size_t i = 0; i < vertices.size(); ++i)
    if (!domain.contains(vertices[i]))
      record.add(Defect::OutsideBox, [&] { return describe_vertex(i) + " is outside the box"; });
  for (const Point<d>& c : domain.corners())
    if (!lookup.contains(c))
      record.add(Defect::MissingCorner, [&] { return "box corner " + to_string(c) + " is not a vertex"; });
}

/// MissingInput for every input point that is not a vertex.
template <class Defect, std::size_t d, class Recorder, class Less>
void check_inputs(std::span<const Point<d>> inputs, const PointLookup<d, Less>& lookup, Recorder& record) {
  for (std::size_t i = 0; i < inputs.size(); ++i)
    if (!lookup.contains(inputs[i]))
      record.add(Defect::MissingInput,
                 [&] { return "input point " + std::to_string(i) + " " + to_string(inputs[i]) + " is not a vertex"; });
}

/// Neumaier's compensated sum: a million terms of mixed sizes (a fine mesh's cells) add up
/// to the box's measure within a few ulps, so the checkers' 1e-9 tolerance is all slack.
class CompensatedSum {
 public:
  void add(double term) noexcept {
    const double sum = sum_ + term;
    compensation_ += std::abs(sum_) >= std::abs(term) ? (sum_ - sum) + term : (term - sum) + sum_;
    sum_ = sum;
  }
  double value() const noexcept { return sum_ + compensation_; }

 private:
  double sum_ = 0, compensation_ = 0;
};

}  // namespace dynmesh::detail
