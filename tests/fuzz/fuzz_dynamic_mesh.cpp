// fuzz_dynamic_mesh — libFuzzer target: DynamicMesh (2D) against its static twin under
// fuzzed runs of insert, erase and batch operations, valid and invalid (see differential.hpp
// for the driver and the contract it predicts). The first byte picks the postprocess: even,
// Postprocess::Quadtree against QuadtreeMesh; odd, Postprocess::Hpu against HpuMesh, at
// 20.7, 25 or 30 degrees (the byte's next bits).
//
// Properties, after the construction and every operation: the mesh (canonical, mesh()) and
// the triangles equal the twin's, and (quadtree) so do the leaves of the refined tree T';
// the mesh passes check_mesh with the bound (kQuadtreeMinAngle, or hpu's angle with the
// Delaunay test) and every present point a vertex; the twin and the structure pass
// check_invariants(); the change feed is empty after construction and replays exactly (the
// triangles before an update, less its removed, plus its added, are the triangles after
// it); a refused operation changes nothing (mesh, T', points, ids, the feed, live trace
// events and bytes).
// Complexity: per operation O((n + t) log t) (the static twin and the mesh checker).
#include "differential.hpp"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dynmesh/dynamic_mesh.hpp"
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/mesh_check.hpp"
#include "dynmesh/quadtree_mesh.hpp"

namespace {

using namespace dynmesh_fuzz;

/// The hpu run's angle bound (set from the input's first byte before the run).
double g_angle = kHpuDefaultMinAngle;

/// The static twin of either postprocess, as the driver needs it.
template <Postprocess P>
struct Twin {
  Twin(const Box<2>& box, std::span<const Point<2>> points) {
    if constexpr (P == Postprocess::Hpu) {
      const HpuMesh m(box, points, g_angle);
      m.check_invariants();
      triangles = m.triangles();
      mesh = m.mesh();
    } else {
      const QuadtreeMesh m(box, points);
      m.check_invariants();
      triangles = m.triangles();
      mesh = m.mesh();
      leaves = m.refined_leaves();
    }
  }
  std::vector<Triangle> triangles;
  Mesh mesh;
  std::vector<Leaf<2>> leaves;  // T' (quadtree only)
};

template <Postprocess P>
struct MeshTraits {
  using Subject = DynamicMesh;
  using Oracle = Twin<P>;
  static constexpr std::size_t kMaxWork = 20000;  // triangles compared
  struct Snapshot {  // what compare() does not see
    MeshChange change;
    std::uint64_t live_events = 0;
    std::size_t record_bytes = 0;
  };

  Subject make(const Box<2>& box, std::span<const Point<2>> points) const {
    MeshOptions options;
    options.postprocess = P;
    options.min_angle = g_angle;
    return Subject(box, points, options);
  }
  Oracle oracle(const Box<2>& box, std::span<const Point<2>> points) const { return Oracle(box, points); }

  std::size_t compare(const Subject& dyn, const Oracle& twin, std::span<const Point<2>> points, const Point<2>&,
                      bool updated) {
    const Mesh mesh = dyn.mesh();
    check(mesh == twin.mesh, "mesh() differs from the static twin's");
    const std::vector<Triangle> triangles = triangles_of(mesh);
    check(triangles == twin.triangles, "the triangles differ from the static twin's");
    if (!updated) check(dyn.triangles() == triangles && dyn.num_triangles() == triangles.size(),
                        "triangles() or num_triangles() disagree with mesh()");
    if constexpr (P == Postprocess::Quadtree)
      check(dyn.refined_leaves() == twin.leaves, "the refined tree T' differs from the static twin's");
    MeshCheckOptions options;
    options.min_angle_deg = P == Postprocess::Hpu ? g_angle : kQuadtreeMinAngle;
    options.delaunay = P == Postprocess::Hpu;
    const MeshReport report = check_mesh(mesh, dyn.box(), points, options);
    if (!report.ok()) fail("check_mesh: " + report.summary());
    feed_.step(triangles, dyn.last_change(), updated);
    return triangles.size();
  }

  std::string describe(const Subject& dyn) const {
    return std::to_string(dyn.num_triangles()) + " triangles, " + std::to_string(dyn.refined_leaves().size()) +
           " leaves of T'";
  }
  Snapshot snapshot(const Subject& dyn) const { return {dyn.last_change(), dyn.live_events(), dyn.record_bytes()}; }
  bool same(const Snapshot& a, const Snapshot& b) const {
    return a.change == b.change && a.live_events == b.live_events && a.record_bytes == b.record_bytes;
  }

 private:
  FeedReplay<Triangle> feed_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const std::uint8_t pick = in.ConsumeIntegral<std::uint8_t>();
  if (pick % 2 == 0) {
    Differential<2, MeshTraits<Postprocess::Quadtree>>(in).run();
  } else {
    constexpr double kAngles[] = {kHpuDefaultMinAngle, 25.0, 30.0, kHpuDefaultMinAngle};
    g_angle = kAngles[(pick >> 1) % 4];
    Differential<2, MeshTraits<Postprocess::Hpu>>(in).run();
  }
  return 0;
}
