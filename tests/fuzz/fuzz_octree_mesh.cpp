// fuzz_octree_mesh — libFuzzer target: DynamicOctreeMesh (3D) against its static twin
// OctreeMesh under fuzzed runs of insert, erase and batch operations, valid and invalid (see
// differential.hpp for the driver and the contract it predicts).
//
// Properties, after the construction and every operation: the mesh (canonical, mesh()) and
// the tetrahedra equal the twin's, and so do the leaves of the refined tree T'; the mesh
// passes check_tet_mesh with the proved dihedral bounds and every present point a vertex;
// the twin and the structure pass check_invariants(); the change feed is empty after
// construction and replays exactly; a refused operation changes nothing (mesh, points, ids,
// the feed, live trace events and bytes).
// Complexity: per operation O((n + t) log t) (the static twin and the mesh checker).
#include "differential.hpp"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dynmesh/dynamic_octree_mesh.hpp"
#include "dynmesh/octree_mesh.hpp"
#include "dynmesh/tet_mesh.hpp"
#include "dynmesh/tet_mesh_check.hpp"

namespace {

using namespace dynmesh_fuzz;

struct Twin {
  Twin(const Box<3>& box, std::span<const Point<3>> points) {
    const OctreeMesh m(box, points);
    m.check_invariants();
    tetrahedra = m.tetrahedra();
    mesh = m.mesh();
    leaves = m.refined_leaves();
  }
  std::vector<Tetrahedron> tetrahedra;
  TetMesh mesh;
  std::vector<Leaf<3>> leaves;
};

struct OctreeMeshTraits {
  using Subject = DynamicOctreeMesh;
  using Oracle = Twin;
  static constexpr std::size_t kMaxWork = 400000;  // tetrahedra compared
  struct Snapshot {  // what compare() does not see
    TetMeshChange change;
    std::uint64_t live_events = 0;
    std::size_t record_bytes = 0;
  };

  Subject make(const Box<3>& box, std::span<const Point<3>> points) const { return Subject(box, points); }
  Oracle oracle(const Box<3>& box, std::span<const Point<3>> points) const { return Oracle(box, points); }

  std::size_t compare(const Subject& dyn, const Oracle& twin, std::span<const Point<3>> points, const Point<3>&,
                      bool updated) {
    const TetMesh mesh = dyn.mesh();
    check(mesh == twin.mesh, "mesh() differs from the static twin's");
    const std::vector<Tetrahedron> tets = tetrahedra_of(mesh);
    check(tets == twin.tetrahedra, "the tetrahedra differ from the static twin's");
    if (!updated)
      check(dyn.tetrahedra() == tets && dyn.num_tetrahedra() == tets.size(),
            "tetrahedra() or num_tetrahedra() disagree with mesh()");
    check(dyn.refined_leaves() == twin.leaves, "the refined tree T' differs from the static twin's");
    TetMeshCheckOptions options;
    options.min_dihedral_deg = kOctreeMinDihedral;
    options.max_dihedral_deg = kOctreeMaxDihedral;
    const TetMeshReport report = check_tet_mesh(mesh, dyn.box(), points, options);
    if (!report.ok()) fail("check_tet_mesh: " + report.summary());
    feed_.step(tets, dyn.last_change(), updated);
    return tets.size();
  }

  std::string describe(const Subject& dyn) const {
    return std::to_string(dyn.num_tetrahedra()) + " tetrahedra, " + std::to_string(dyn.refined_leaves().size()) +
           " leaves of T'";
  }
  Snapshot snapshot(const Subject& dyn) const { return {dyn.last_change(), dyn.live_events(), dyn.record_bytes()}; }
  bool same(const Snapshot& a, const Snapshot& b) const {
    return a.change == b.change && a.live_events == b.live_events && a.record_bytes == b.record_bytes;
  }

 private:
  FeedReplay<Tetrahedron> feed_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  Differential<3, OctreeMeshTraits>(in).run();
  return 0;
}
