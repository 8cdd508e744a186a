// dynmesh/dynamic_mesh.hpp — a quality triangle mesh of a changing point set, kept up to date
// by self-adjusting computation.
//
// Purpose: the public dynamic meshing API. The mesh runs as a program on sac-runtime, in one
// trace (quadtree: QuadTreeRefine and the postprocess; hpu: the refinement on its own cell
// store, with no quadtree); after each insert / erase / batch, one propagate() carries the
// change into the mesh, and the triangles it removed and added
// are reported as the change feed (last_change()). The mesh is always exactly the static
// twin's mesh of the current point set: HpuMesh for Postprocess::Hpu (the default; the
// program is src/hpu/hpu_cells_program.hpp, which answers every question from the cells of a
// vertex store, src/hpu/cell_store.hpp, and reads the inputs and their side midpoints from a
// list the mutator keeps, src/hpu/hpu_inputs.hpp), QuadtreeMesh for Postprocess::Quadtree.
//
// Invariants (check_invariants()): the engine's invariants; quadtree: the quadtree program's
// invariants (DynamicQuadtree) and the refined tree T' satisfies its rules; hpu: the change
// feed's blocks, the input list and the cell store's base values; the live triangles tile
// the box, every present point is a vertex, and no angle is below the bound (hpu: Delaunay too, by exact
// predicates). Built with the CMake option SAC_DEBUG_CHECKS, every insert, erase and apply
// ends with the structures' checks (not the O(n lg n) mesh contract).
// Failure atomicity: every mutator call validates its whole input first; a call that throws
// InputError leaves the mesh, the ids and the engine as they were. (hpu: the validation is
// the quadtree mesh's resolution rule plus the side midpoints; a refinement that still ran
// out of double precision would throw from inside the propagation, which leaves the engine
// unusable; no test or fuzz run has reached that.)
// Determinism: the mesh depends only on the point set and the box.
// Complexity: construction O(n lg n + |T'|) expected; each single-point update O(lg L/s)
// expected trace distance; triangles() O(t log t).
// Paper: Acar & Hudson, "Optimal-time dynamic mesh refinement", Sections 2, 4 and 5;
// Bern, Eppstein & Gilbert (1994) for the quadtree mesh.
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
#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/quadtree_mesh.hpp"

namespace dynmesh {

/// Hpu: DynHPU's off-center Delaunay mesh (the default; hpu_mesh.hpp). Quadtree: the
/// quadtree's own triangulation (quadtree_mesh.hpp, angles ≥ 18.4°).
enum class Postprocess { Quadtree, Hpu };

struct MeshOptions {
  Postprocess postprocess = Postprocess::Hpu;
  /// The hpu mesh's angle bound in degrees, 1 to 30 (InputError(Malformed) otherwise).
  /// Ignored by the quadtree mesh, whose bound is fixed.
  double min_angle = kHpuDefaultMinAngle;
  /// The quadtree mesh's tree (DynamicQuadtreeOptions: a distributed mesh's ranks split
  /// every cell coarser than their partition level). The hpu mesh takes the defaults only
  /// (std::invalid_argument otherwise).
  DynamicQuadtreeOptions tree{};
};

namespace detail {
class MeshState;
}

class DynamicMesh {
 public:
  /// Meshes `points` in `box` from scratch; ids are 0..n−1 in input order. InputError as
  /// DynamicQuadtree<2> reports it, plus Resolution for points the mesh cannot resolve in
  /// double precision (see mesh_resolution_level in detail/quadtree_mesh_rules.hpp).
  explicit DynamicMesh(const Box<2>& box, std::span<const Point<2>> points = {}, MeshOptions options = {});
  ~DynamicMesh();
  DynamicMesh(DynamicMesh&&) noexcept;
  DynamicMesh& operator=(DynamicMesh&&) noexcept;

  PointId insert(const Point<2>& p);
  void erase(PointId id);
  void erase(const Point<2>& p);
  /// Applies the edits in order with one propagation; validated as a whole first. On error
  /// nothing changes and the InputError's point_indices() holds the failing edit's index.
  std::vector<PointId> apply(std::span<const Edit<2>> edits);

  const Box<2>& box() const noexcept;
  const MeshOptions& options() const noexcept;
  std::size_t size() const noexcept;
  bool contains(PointId id) const noexcept;
  std::optional<PointId> find(const Point<2>& p) const noexcept;
  const Point<2>& point(PointId id) const;
  std::vector<std::pair<PointId, Point<2>>> points() const;

  /// The live triangles, canonical and sorted.
  std::vector<Triangle> triangles() const;
  std::size_t num_triangles() const noexcept;
  /// The canonical mesh (FORMATS.md).
  Mesh mesh() const;
  /// The triangles removed and added by the last update (empty after construction).
  const MeshChange& last_change() const noexcept;
  /// The leaves of the refined tree T', sorted (quadtree; empty with hpu, which refines
  /// no tree).
  std::vector<Leaf<2>> refined_leaves() const;
  /// Is c split in the quadtree T* (with the tree options' splits)? Always false with hpu.
  bool is_split(const CellId<2>& c) const noexcept;

  /// The last update's trace distance and time (seconds: relinking, the propagation and
  /// the change feed; not the input's validation).
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
  std::unique_ptr<detail::MeshState> s_;
};

}  // namespace dynmesh
