// Builds against the installed sac and dynmesh packages and uses one thing from each.
#include <algorithm>
#include <array>
#include <vector>

#include <dynmesh/dynamic_quadtree.hpp>
#include <dynmesh/static_quadtree.hpp>
#include <sac/sac.hpp>

int main() {
  sac::Engine rt;
  sac::Mod<int> in, out;
  rt.set(in, 1);
  rt.run([&](sac::Engine& rt2) { rt2.read(in, [po = &out](sac::Engine& rt3, int v) { rt3.write(*po, v + 1); }); });
  rt.set(in, 41);
  rt.propagate();
  if (out.get() != 42) return 1;

  const std::vector<dynmesh::Point<2>> pts{{{0.0, 0.0}}, {{1.0, 1.0}}};
  const auto box = dynmesh::derive_box<2>(pts);
  const auto tree = dynmesh::StaticQuadtree<2>::from_points(box, pts);
  if (tree.leaves().empty()) return 1;
  // The dynamic tree after an insertion equals the static tree of the new set.
  dynmesh::DynamicQuadtree<2> dyn(box, pts);
  dyn.insert({0.5, 0.25});
  const std::vector<dynmesh::Point<2>> now{{{0.0, 0.0}}, {{1.0, 1.0}}, {{0.5, 0.25}}};
  const auto fresh = dynmesh::StaticQuadtree<2>::from_points(box, now);
  const auto leaves = dyn.leaves();
  return std::equal(leaves.begin(), leaves.end(), fresh.leaves().begin(), fresh.leaves().end()) ? 0 : 1;
}
