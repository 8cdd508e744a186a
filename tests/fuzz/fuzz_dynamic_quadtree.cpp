// fuzz_dynamic_quadtree — libFuzzer target: DynamicQuadtree<2> and <3> against the static
// oracle (StaticQuadtree::from_points) under fuzzed runs of insert, erase and batch
// operations, valid and invalid (see differential.hpp for the driver and the contract it
// predicts).
//
// Input: one decision picks the dimension; the rest drives differential.hpp.
// Properties, after the construction and every operation: the leaves equal the oracle's,
// with the same split count; each leaf lists exactly the ids of the points in it; locate()
// and neighbours() of a fresh probe point agree with the oracle (InputError outside the
// box); check_invariants() passes; a refused operation changes nothing (points, ids,
// positions, leaves, live trace events and bytes, directory slots).
// Complexity: per operation O(n lg n + |T*|) (the static build and the checkers).
#include "differential.hpp"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dynmesh/cell.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace {

using namespace dynmesh_fuzz;

template <std::size_t d>
struct TreeTraits {
  using Subject = DynamicQuadtree<d>;
  using Oracle = StaticQuadtree<d>;
  static constexpr std::size_t kMaxWork = 40000;  // leaves compared
  struct Snapshot {  // what compare() does not see
    std::vector<Position<d>> positions;
    std::uint64_t live_events = 0;
    std::size_t record_bytes = 0;
    std::size_t directory = 0;
  };

  Subject make(const Box<d>& box, std::span<const Point<d>> points) const { return Subject(box, points); }
  Oracle oracle(const Box<d>& box, std::span<const Point<d>> points) const {
    return Oracle::from_points(box, points);
  }

  std::size_t compare(const Subject& tree, const Oracle& want, std::span<const Point<d>>, const Point<d>& probe,
                      bool) const {
    const std::vector<Leaf<d>> leaves = tree.leaves();
    check(std::equal(leaves.begin(), leaves.end(), want.leaves().begin(), want.leaves().end()),
          "the leaves differ from the static oracle's");
    check(tree.num_split() == want.num_split() && tree.num_leaves() == leaves.size(),
          "the split count differs from the static oracle's");
    const auto with_points = tree.leaves_with_points();
    check(with_points.size() == leaves.size(), "leaves_with_points() and leaves() differ in size");
    for (std::size_t i = 0; i < leaves.size(); ++i) {
      check(with_points[i].cell == leaves[i].cell && with_points[i].points.size() == leaves[i].npoints,
            "leaves_with_points() disagrees with leaves()");
      for (const PointId id : with_points[i].points) {
        const auto q = try_locate<d>(tree.box(), tree.point(id));
        check(q && contains(leaves[i].cell, *q), "a leaf lists a point that lies elsewhere");
      }
    }
    // A probe: locate() and neighbours() as the oracle answers them.
    const auto q = try_locate<d>(tree.box(), probe);
    if (!q || !finite<d>(probe)) {
      bool refused = false;
      try {
        (void)tree.locate(probe);
      } catch (const InputError&) {
        refused = true;
      }
      check(refused, "locate() accepted a point outside the box");
      return leaves.size();
    }
    const CellId<d> leaf = tree.locate(probe);
    check(leaf == want.locate(*q), "locate() differs from the static oracle's");
    check(tree.neighbours(leaf) == want.neighbours(leaf), "neighbours() differ from the static oracle's");
    return leaves.size();
  }

  std::string describe(const Subject& tree) const { return std::to_string(tree.num_leaves()) + " leaves"; }
  Snapshot snapshot(const Subject& tree) const {
    return {tree.positions(), tree.live_events(), tree.record_bytes(), tree.directory_size()};
  }
  bool same(const Snapshot& a, const Snapshot& b) const {
    return a.positions == b.positions && a.live_events == b.live_events && a.record_bytes == b.record_bytes &&
           a.directory == b.directory;
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  if (in.ConsumeBool())
    Differential<3, TreeTraits<3>>(in).run();
  else
    Differential<2, TreeTraits<2>>(in).run();
  return 0;
}
