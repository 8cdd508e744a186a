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
#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/errors.hpp"
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

/// One random update of a differential test, drawn with `rng` and applied to `dyn` (a
/// DynamicMesh or DynamicOctreeMesh): 1 in 8 a batch of up to 4 insertions (drawn from
/// `absent`) and deletions (of `present` points), else a single insertion or deletion. The
/// expected sets follow. A point the mesh cannot resolve is refused (Resolution) and leaves
/// the sets as they were; any other refusal fails the test.
template <std::size_t d, class Dyn>
void random_update(Dyn& dyn, PointMap<d>& present, std::vector<dynmesh::Point<d>>& absent, dynmesh::Rng& rng) {
  using namespace dynmesh;
  const std::uint64_t what = rng.below(8);
  if (what == 0) {
    std::vector<Edit<d>> edits;
    std::vector<PointId> gone;
    std::vector<Point<d>> coming;
    std::vector<std::size_t> taken;
    for (std::uint64_t k = 1 + rng.below(4); k-- > 0;) {
      if (!absent.empty() && (rng.below(2) == 0 || present.size() <= gone.size())) {
        const std::size_t i = rng.below(absent.size());
        if (std::find(taken.begin(), taken.end(), i) != taken.end()) continue;
        taken.push_back(i);
        edits.push_back({EditOp::Insert, absent[i]});
        coming.push_back(absent[i]);
      } else if (present.size() > gone.size()) {
        auto it = present.begin();
        std::advance(it, static_cast<std::ptrdiff_t>(rng.below(present.size())));
        if (std::find(gone.begin(), gone.end(), it->first) != gone.end()) continue;
        edits.push_back({EditOp::Delete, it->second});
        gone.push_back(it->first);
      }
    }
    std::vector<PointId> ids;
    try {
      ids = dyn.apply(edits);
    } catch (const InputError& e) {
      ASSERT_EQ(e.kind(), InputError::Kind::Resolution) << e.what();
      return;
    }
    std::sort(taken.rbegin(), taken.rend());
    for (const std::size_t i : taken) absent.erase(absent.begin() + static_cast<std::ptrdiff_t>(i));
    for (PointId id : gone) {
      absent.push_back(present.at(id));
      present.erase(id);
    }
    for (std::size_t k = 0; k < ids.size(); ++k) present[ids[k]] = coming[k];
  } else if (what < 5 && !absent.empty()) {
    const std::size_t i = rng.below(absent.size());
    try {
      present[dyn.insert(absent[i])] = absent[i];
    } catch (const InputError& e) {
      ASSERT_EQ(e.kind(), InputError::Kind::Resolution) << e.what();
      return;
    }
    absent.erase(absent.begin() + static_cast<std::ptrdiff_t>(i));
  } else if (!present.empty()) {
    auto it = present.begin();
    std::advance(it, static_cast<std::ptrdiff_t>(rng.below(present.size())));
    dyn.erase(it->first);
    absent.push_back(it->second);
    present.erase(it);
  }
}

}  // namespace dynmesh_test
