// dynamic_test_support.hpp — helpers shared by the tests of the self-adjusting quadtree:
// the build-speed switch, the oracle comparison and the "nothing changed" snapshot.
#pragma once

#include "../sanitized.hpp"
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <map>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace dynmesh_test {

/// Built with AddressSanitizer (CI runs it at -O0) or without optimization: tests scale their
/// sizes down. (Optimization, not NDEBUG: the RelWithDebInfo build of the brief sets its
/// flags to "-O2 -g", without -DNDEBUG.)
using test_support::kSanitized;
/// Built with SAC_DEBUG_CHECKS: every update checks the whole tree and trace, so loops of
/// many updates scale down further.
using test_support::kDebugChecks;
#ifdef __OPTIMIZE__
constexpr bool kSlowBuild = kSanitized;
#else
constexpr bool kSlowBuild = true;
#endif

/// The expected point set: id → coordinates.
template <std::size_t d>
using PointMap = std::map<dynmesh::PointId, dynmesh::Point<d>>;

template <std::size_t d>
std::vector<dynmesh::Point<d>> coordinates(const PointMap<d>& m) {
  std::vector<dynmesh::Point<d>> out;
  out.reserve(m.size());
  for (const auto& [id, p] : m) out.push_back(p);
  return out;
}

/// The leaves of the static oracle T* for these points in this box.
template <std::size_t d>
std::vector<dynmesh::Leaf<d>> oracle_leaves(const dynmesh::Box<d>& box, std::span<const dynmesh::Point<d>> pts) {
  const auto t = dynmesh::StaticQuadtree<d>::from_points(box, pts);
  return {t.leaves().begin(), t.leaves().end()};
}

template <std::size_t d>
std::string leaf_string(const dynmesh::Leaf<d>& l) {
  return dynmesh::to_string(l.cell) + "#" + std::to_string(l.npoints);
}

/// Exact equality of two sorted leaf lists; on failure, the sizes and up to 8 leaves that
/// only one side has.
template <std::size_t d>
testing::AssertionResult same_leaves(const std::vector<dynmesh::Leaf<d>>& got,
                                     const std::vector<dynmesh::Leaf<d>>& want) {
  if (got == want) return testing::AssertionSuccess();
  std::vector<dynmesh::Leaf<d>> only_got, only_want;
  auto g = got, w = want;
  std::sort(g.begin(), g.end());
  std::sort(w.begin(), w.end());
  std::set_difference(g.begin(), g.end(), w.begin(), w.end(), std::back_inserter(only_got));
  std::set_difference(w.begin(), w.end(), g.begin(), g.end(), std::back_inserter(only_want));
  std::ostringstream os;
  os << "leaves differ: got " << got.size() << ", want " << want.size();
  if (only_got.empty() && only_want.empty()) os << " (same leaves, different order)";
  os << "\n  only in got (" << only_got.size() << "):";
  for (std::size_t i = 0; i < only_got.size() && i < 8; ++i) os << ' ' << leaf_string<d>(only_got[i]);
  os << "\n  only in want (" << only_want.size() << "):";
  for (std::size_t i = 0; i < only_want.size() && i < 8; ++i) os << ' ' << leaf_string<d>(only_want[i]);
  return testing::AssertionFailure() << os.str();
}

template <std::size_t d>
testing::AssertionResult invariants_hold(const dynmesh::DynamicQuadtree<d>& tree) {
  try {
    tree.check_invariants();
  } catch (const std::exception& e) {
    return testing::AssertionFailure() << "check_invariants: " << e.what();
  }
  return testing::AssertionSuccess();
}

/// The leaves with the coordinates (not the ids) of their points, each leaf's points sorted:
/// comparable between trees whose ids differ.
template <std::size_t d>
std::vector<std::pair<dynmesh::CellId<d>, std::vector<dynmesh::Point<d>>>> leaves_by_coordinates(
    const dynmesh::DynamicQuadtree<d>& tree) {
  std::vector<std::pair<dynmesh::CellId<d>, std::vector<dynmesh::Point<d>>>> out;
  for (const auto& lp : tree.leaves_with_points()) {
    std::vector<dynmesh::Point<d>> pts;
    for (const auto id : lp.points) pts.push_back(tree.point(id));
    std::sort(pts.begin(), pts.end());
    out.emplace_back(lp.cell, std::move(pts));
  }
  return out;
}

/// Everything a failed call must leave as it was.
template <std::size_t d>
struct Snapshot {
  std::vector<dynmesh::Leaf<d>> leaves;
  std::vector<std::pair<dynmesh::PointId, dynmesh::Point<d>>> points;
  std::vector<dynmesh::Position<d>> positions;
  std::size_t size = 0;
  std::uint64_t live_events = 0;
  std::size_t record_bytes = 0;
};

template <std::size_t d>
Snapshot<d> snapshot(const dynmesh::DynamicQuadtree<d>& tree) {
  return {tree.leaves(), tree.points(), tree.positions(), tree.size(), tree.live_events(), tree.record_bytes()};
}

template <std::size_t d>
testing::AssertionResult unchanged(const dynmesh::DynamicQuadtree<d>& tree, const Snapshot<d>& before) {
  const Snapshot<d> now = snapshot(tree);
  if (now.size != before.size)
    return testing::AssertionFailure() << "size changed: " << before.size << " -> " << now.size;
  if (now.points != before.points) return testing::AssertionFailure() << "points() changed";
  if (now.positions != before.positions) return testing::AssertionFailure() << "positions() changed";
  if (auto r = same_leaves<d>(now.leaves, before.leaves); !r) return r;
  if (now.live_events != before.live_events)
    return testing::AssertionFailure() << "live_events changed: " << before.live_events << " -> " << now.live_events;
  if (now.record_bytes != before.record_bytes)
    return testing::AssertionFailure() << "record_bytes changed: " << before.record_bytes << " -> "
                                       << now.record_bytes;
  return testing::AssertionSuccess();
}

}  // namespace dynmesh_test
