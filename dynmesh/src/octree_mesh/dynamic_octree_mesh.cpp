// dynamic_octree_mesh.cpp — DynamicOctreeMesh: QuadtreeCore<3> running QuadTreeRefine and the
// octree mesh's program in one trace, the mesh's own input rule, and the change feed.
#include "dynmesh/dynamic_octree_mesh.hpp"

#include <algorithm>
#include <chrono>
#include <span>
#include <string>
#include <utility>

#include "dynmesh/detail/octree_mesh_rules.hpp"
#include "dynmesh/tet_mesh_check.hpp"
#include "mesh/mesh_input_rules.hpp"
#include "mesh/tet_numbering.hpp"
#include "octree_mesh/octree_mesh_program.hpp"
#include "quadtree/quadtree_core.hpp"

namespace dynmesh {
namespace detail {
namespace {

/// The box, validated before the grid computes with it (its resolution level takes ilogb of
/// the side): `log` is built before `core` validates.
const Box<3>& validated(const Box<3>& box) {
  validate_box(box);
  return box;
}

}  // namespace

struct OctreeMeshState {
  explicit OctreeMeshState(const Box<3>& box) : log(OctreeGrid(validated(box))), core(box) {
    program.dir = &core.dir;
    program.input = &core.head;
    program.log = &log;
  }
  ~OctreeMeshState() { log.closing = true; }  // before core (and its engine) goes

  OctreeFeed log;
  CellCounts<3> counts;
  TetMeshChange change;
  OctreeMeshProgram program{};
  QuadtreeCore<3> core;

  /// The whole batch against the octree's and the mesh's input rules. Changes nothing.
  void validate(std::span<const Edit<3>> edits, const std::string& noun) const {
    core.validate(edits, noun, MeshChecks<3>{log.grid, counts});
  }
  std::vector<PointId> update(std::span<const Edit<3>> edits) {
    auto ids = core.update(edits);
    count_edits<3>(log.grid, core.box, edits, counts);
    log.take_change(change);
    return ids;
  }
  std::vector<Position<3>> positions() const {
    std::vector<Position<3>> out;
    for (const auto* n = core.first; n; n = n->succ) out.push_back(n->q);
    return out;
  }
  std::vector<Point<3>> present() const {
    std::vector<Point<3>> out;
    for (const auto* n = core.first; n; n = n->succ) out.push_back(n->point);
    return out;
  }
};

/// T* as the quadtree's contract states it, and T''s rules.
void check_trees_of(const DynamicOctreeMesh& mesh, const OctreeMeshState& s) {
  const std::vector<Position<3>> qs = s.positions();
  std::vector<Leaf<3>> tree;
  s.core.for_each_leaf_of([&](const CellId<3>& c) { return s.core.is_split(c); },
                          [&](const CellId<3>& c) {
                            std::uint32_t k = 0;
                            for (const auto* p = s.core.points_in(c); p; p = p->next.get()) ++k;
                            tree.push_back(Leaf<3>{c, k});
                          });
  std::sort(tree.begin(), tree.end());
  require_valid_tree<3>(qs, tree, s.core.program.split_below);
  require_refined_tree(mesh.refined_leaves(), qs);
}

/// Applies validated edits with one propagation. Built with SAC_DEBUG_CHECKS, the
/// structures' checkers then run.
std::vector<PointId> checked_update(const DynamicOctreeMesh& mesh, OctreeMeshState& s, std::span<const Edit<3>> edits) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<PointId> ids = s.update(edits);
  s.core.last.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
#ifdef SAC_DEBUG_CHECKS
  s.core.check_own_invariants();
  check_trees_of(mesh, s);
#else
  (void)mesh;
#endif
  return ids;
}

}  // namespace detail

DynamicOctreeMesh::DynamicOctreeMesh(const Box<3>& box, std::span<const Point<3>> points,
                                     const DynamicQuadtreeOptions& tree)
    : s_(std::make_unique<detail::OctreeMeshState>(box)) {
  s_->core.program.split_below = detail::checked_split_below(tree.split_below);
  const std::vector<Edit<3>> edits = detail::inserts_of<3>(points);
  s_->validate(edits, "point");
  validate_mesh_box(box);
  auto* program = &s_->program;
  s_->core.build(points, [program](sac::Engine& rt) { detail::OctreeMeshProgram::main(rt, program); });
  detail::count_edits<3>(s_->log.grid, s_->core.box, edits, s_->counts);
  s_->log.settle();
}

DynamicOctreeMesh::~DynamicOctreeMesh() = default;
DynamicOctreeMesh::DynamicOctreeMesh(DynamicOctreeMesh&&) noexcept = default;
DynamicOctreeMesh& DynamicOctreeMesh::operator=(DynamicOctreeMesh&&) noexcept = default;

PointId DynamicOctreeMesh::insert(const Point<3>& p) {
  const Edit<3> e{EditOp::Insert, p};
  s_->validate({&e, 1}, "");
  return detail::checked_update(*this, *s_, {&e, 1}).front();
}

void DynamicOctreeMesh::erase(PointId id) {
  const Edit<3> e = s_->core.erase_edit(id);
  s_->validate({&e, 1}, "");
  detail::checked_update(*this, *s_, {&e, 1});
}

void DynamicOctreeMesh::erase(const Point<3>& p) {
  const Edit<3> e{EditOp::Delete, p};
  s_->validate({&e, 1}, "");
  detail::checked_update(*this, *s_, {&e, 1});
}

std::vector<PointId> DynamicOctreeMesh::apply(std::span<const Edit<3>> edits) {
  s_->validate(edits, "edit");
  return detail::checked_update(*this, *s_, edits);
}

const Box<3>& DynamicOctreeMesh::box() const noexcept { return s_->core.box; }
std::size_t DynamicOctreeMesh::size() const noexcept { return s_->core.by_id.size(); }
bool DynamicOctreeMesh::contains(PointId id) const noexcept { return s_->core.by_id.contains(id); }
std::optional<PointId> DynamicOctreeMesh::find(const Point<3>& p) const noexcept { return s_->core.find(p); }
const Point<3>& DynamicOctreeMesh::point(PointId id) const { return s_->core.point(id); }
std::vector<std::pair<PointId, Point<3>>> DynamicOctreeMesh::points() const { return s_->core.points(); }

std::vector<Tetrahedron> DynamicOctreeMesh::tetrahedra() const { return s_->log.simplices(); }
std::size_t DynamicOctreeMesh::num_tetrahedra() const noexcept { return s_->log.num_simplices(); }
TetMesh DynamicOctreeMesh::mesh() const {
  // Two passes over the blocks, each making one block's tetrahedra at a time: the mesh is
  // never held as coordinates, six times the memory of its index form.
  TetMesh out;
  detail::TetNumbering numbering(out);
  std::vector<Tetrahedron> scratch;
  std::size_t count = 0;
  auto each = [&](auto&& f) {
    for (const detail::OctreeBlock* b = s_->log.live; b; b = b->next) {
      scratch.clear();
      detail::emit_simplices(s_->log.grid, b->shape, scratch);
      for (const Tetrahedron& t : scratch) f(t);
    }
  };
  each([&](const Tetrahedron& t) { numbering.gather(t), ++count; });
  numbering.close(count);
  each([&](const Tetrahedron& t) { numbering.add(t); });
  numbering.sort();
  return out;
}
const TetMeshChange& DynamicOctreeMesh::last_change() const noexcept { return s_->change; }

bool DynamicOctreeMesh::is_split(const CellId<3>& c) const noexcept { return s_->core.is_split(c); }

std::vector<Leaf<3>> DynamicOctreeMesh::refined_leaves() const {
  std::vector<Leaf<3>> out;
  for (const detail::OctreeBlock* b = s_->log.live; b; b = b->next) {
    const detail::OctreeGroupShape& g = b->shape;
    if (g.root_leaf) {
      out.push_back(Leaf<3>{g.cell, 0});
      continue;
    }
    // Every child that is not split: the kids word of the group's cell says which.
    const detail::Slot<3>* slot = s_->core.dir.find(g.cell);
    const std::uint64_t own = slot && slot->kids.written() ? slot->kids.get() : 0;
    for (unsigned w = 0; w < 8; ++w)
      if (!detail::any_split(detail::kid(own, w)))
        out.push_back(Leaf<3>{child(g.cell, w), static_cast<int>(w) == g.owner ? 1u : 0u});
  }
  std::sort(out.begin(), out.end());
  return out;
}

const UpdateStats& DynamicOctreeMesh::last_update() const noexcept { return s_->core.last; }
const sac::Stats& DynamicOctreeMesh::engine_stats() const noexcept { return s_->core.rt.stats(); }
sac::MemoryBreakdown DynamicOctreeMesh::memory_breakdown() const { return s_->core.rt.memory_breakdown(); }
std::size_t DynamicOctreeMesh::trace_bytes() const {
  return s_->core.bytes() + s_->counts.size() * (sizeof(CellId<3>) + 2 * sizeof(void*) + sizeof(std::int64_t));
}
std::size_t DynamicOctreeMesh::record_bytes() const { return s_->core.rt.record_bytes(); }
std::uint64_t DynamicOctreeMesh::live_events() const { return s_->core.rt.live_events(); }
void DynamicOctreeMesh::compact() { s_->core.compact(); }

void DynamicOctreeMesh::check_invariants() const {
  s_->core.check_invariants();
  detail::check_trees_of(*this, *s_);
  require_valid_tet_mesh(mesh(), box(), s_->present(),
                         TetMeshCheckOptions{.min_dihedral_deg = kOctreeMinDihedral,
                                             .max_dihedral_deg = kOctreeMaxDihedral});
}

}  // namespace dynmesh
