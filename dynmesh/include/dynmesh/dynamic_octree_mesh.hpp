// dynmesh/dynamic_octree_mesh.hpp — a tetrahedral mesh of a changing 3D point set, with
// every dihedral angle bounded, kept up to date by self-adjusting computation.
//
// Purpose: the public 3D dynamic meshing API. QuadTreeRefine (the octree T*) and the octree
// postprocess (detail/octree_mesh_rules.hpp) run as one program on sac-runtime, in one trace;
// after each insert / erase / batch, one propagate() carries the change through the tree into
// the tetrahedra, and the tetrahedra it removed and added are reported as the change feed
// (last_change()). The mesh is always exactly the static twin's (OctreeMesh) mesh of the
// current point set, bit for bit.
//
// Invariants (check_invariants()): the engine's; the octree program's (T* as the quadtree
// contract states it); T' satisfies its rules; the live tetrahedra satisfy the mesh contract
// (require_valid_tet_mesh: positive, matched faces, the box's volume, every input a vertex,
// dihedral angles within [kOctreeMinDihedral, kOctreeMaxDihedral]). Built with the CMake
// option SAC_DEBUG_CHECKS, every update ends with the structures' checks.
// Failure atomicity: every mutator validates its whole input first; a call that throws
// InputError leaves the mesh, the ids and the engine as they were.
// Determinism: the mesh depends only on the point set and the box.
// Complexity: construction O(n lg n + |T'|) expected; each single-point update O(lg L/s)
// expected trace distance; tetrahedra() O(t log t).
// Paper: Acar & Hudson, "Optimal-time dynamic mesh refinement", Sections 2.2, 4 and 5.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <sac/memory_breakdown.hpp>
#include <sac/stats.hpp>

#include "dynmesh/box.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/octree_mesh.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/tet_mesh.hpp"

namespace dynmesh {

namespace detail {
struct OctreeMeshState;
}

class DynamicOctreeMesh {
 public:
  /// Meshes `points` in `box` from scratch; ids are 0..n−1 in input order. InputError as
  /// DynamicQuadtree<3> reports it, plus Resolution for points the mesh cannot resolve in
  /// double precision.
  /// `tree`: the octree's options (DynamicQuadtreeOptions; a distributed mesh's ranks split
  /// every cell coarser than their partition level).
  explicit DynamicOctreeMesh(const Box<3>& box, std::span<const Point<3>> points = {},
                             const DynamicQuadtreeOptions& tree = {});
  ~DynamicOctreeMesh();
  DynamicOctreeMesh(DynamicOctreeMesh&&) noexcept;
  DynamicOctreeMesh& operator=(DynamicOctreeMesh&&) noexcept;

  PointId insert(const Point<3>& p);
  void erase(PointId id);
  void erase(const Point<3>& p);
  /// Applies the edits in order with one propagation; validated as a whole first. On error
  /// nothing changes and the InputError's point_indices() holds the failing edit's index.
  std::vector<PointId> apply(std::span<const Edit<3>> edits);

  const Box<3>& box() const noexcept;
  std::size_t size() const noexcept;
  bool contains(PointId id) const noexcept;
  std::optional<PointId> find(const Point<3>& p) const noexcept;
  const Point<3>& point(PointId id) const;
  std::vector<std::pair<PointId, Point<3>>> points() const;

  /// The live tetrahedra, canonical and sorted.
  std::vector<Tetrahedron> tetrahedra() const;
  std::size_t num_tetrahedra() const noexcept;
  /// The canonical mesh (docs/FORMATS.md).
  TetMesh mesh() const;
  /// The tetrahedra removed and added by the last update (empty after construction).
  const TetMeshChange& last_change() const noexcept;
  /// The leaves of the refined tree T', sorted.
  std::vector<Leaf<3>> refined_leaves() const;
  /// Is c split in the octree T* (with the tree options' splits)?
  bool is_split(const CellId<3>& c) const noexcept;

  /// The last update's trace distance and time (seconds: relinking, the propagation and the
  /// change feed; not the input's validation).
  const UpdateStats& last_update() const noexcept;
  const sac::Stats& engine_stats() const noexcept;
  /// The engine's trace by record kind (bench --breakdown); the rest of trace_bytes() is the
  /// program's state outside the trace.
  sac::MemoryBreakdown memory_breakdown() const;
  std::size_t trace_bytes() const;
  std::size_t record_bytes() const;
  std::uint64_t live_events() const;
  void compact();

  void check_invariants() const;

 private:
  std::unique_ptr<detail::OctreeMeshState> s_;
};

}  // namespace dynmesh
