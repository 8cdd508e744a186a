// dynamic_mesh.cpp — DynamicMesh: QuadtreeCore<2> running QuadTreeRefine and a postprocess
// in one trace (the quadtree mesh, or the hpu mesh on its input list), the mesh's own input
// rules, and the change feed.
#include "dynmesh/dynamic_mesh.hpp"

#include <algorithm>
#include <chrono>
#include <iterator>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>

#include "dynmesh/detail/quadtree_mesh_rules.hpp"
#include "dynmesh/mesh_check.hpp"
#include "hpu/hpu_cells_program.hpp"
#include "hpu/hpu_cells_state.hpp"
#include "hpu/hpu_geometry.hpp"
#include "hpu/hpu_inputs.hpp"
#include "hpu/hpu_mesh_feed.hpp"
#include "mesh/mesh_input_rules.hpp"
#include "quadtree/quadtree_core.hpp"
#include "quadtree_mesh/quadtree_mesh_program.hpp"

namespace dynmesh {
namespace detail {


/// The box, validated before MeshGrid computes with it (its resolution level takes ilogb of
/// the side, which overflows for 0 or NaN): `log` is built before `core` validates.
const Box<2>& validated(const Box<2>& box) {
  validate_box(box);
  return box;
}

/// The options, validated before anything is built.
MeshOptions validated(MeshOptions o) {
  if (o.postprocess == Postprocess::Hpu) validate_min_angle(o.min_angle);
  return o;
}

struct MeshState {
  MeshState(const Box<2>& box, MeshOptions opts)
      : options(validated(opts)), log(MeshGrid(validated(box))), hpu_state(box), core(box),
        hpu(core.rt, hpu_state, options.min_angle) {
    program.dir = &core.dir;
    program.input = &core.head;
    program.log = &log;
    if (is_hpu()) hpu_state.start(core.rt);
  }
  ~MeshState() {  // before core (and its engine) goes
    log.closing = true;
    hpu_state.feed.close();
  }

  bool is_hpu() const noexcept { return options.postprocess == Postprocess::Hpu; }

  MeshOptions options;
  FeedLog log;
  CellCounts<2> counts;
  MeshChange change;
  QuadtreeMeshProgram program{};
  HpuCellsState hpu_state;  // the hpu mesh's input list, cell store and feed outlive the engine
  QuadtreeCore<2> core;
  HpuCellsProgram hpu;

  /// The whole batch against the quadtree's and the mesh's input rules; with hpu, also its
  /// side midpoints (returned as the plan to commit). Changes nothing.
  HpuInputs::Plan validate(std::span<const Edit<2>> edits, const std::string& noun) const {
    core.validate(edits, noun, MeshChecks<2>{log.grid, counts});
    return is_hpu() ? hpu_state.plan(edits) : HpuInputs::Plan{};
  }
  void count(std::span<const Edit<2>> edits) { count_edits<2>(log.grid, core.box, edits, counts); }
  std::vector<PointId> update(std::span<const Edit<2>> edits, const HpuInputs::Plan& plan) {
    if (is_hpu()) {
      auto ids = core.update(edits, [&](sac::Engine& e) { hpu_state.commit(e, plan); });
      hpu_state.release(core.rt);
      count(edits);
      change = hpu_state.feed.take_change();
      return ids;
    }
    auto ids = core.update(edits);
    count(edits);
    collect_change();
    return ids;
  }
  /// The present points (for the hpu mesh's checkers).
  std::vector<Point<2>> present() const {
    std::vector<Point<2>> out;
    for (const auto* n = core.first; n; n = n->succ) out.push_back(n->point);
    return out;
  }
  void collect_change() { log.take_change(change); }
};

/// T* as the quadtree's contract states it, and T''s closure rule (the quadtree mesh only:
/// the hpu mesh runs no tree).
void check_trees_of(const DynamicMesh& mesh, const MeshState& s) {
  if (s.is_hpu()) return;
  std::vector<Position<2>> qs;
  for (const auto* n = s.core.first; n; n = n->succ) qs.push_back(n->q);
  std::vector<Leaf<2>> tree;
  s.core.for_each_leaf_of([&](const CellId<2>& c) { return s.core.is_split(c); },
                          [&](const CellId<2>& c) {
                            std::uint32_t k = 0;
                            for (const auto* p = s.core.points_in(c); p; p = p->next.get()) ++k;
                            tree.push_back(Leaf<2>{c, k});
                          });
  std::sort(tree.begin(), tree.end());
  require_valid_tree<2>(qs, tree);
  // T': every point leaf has its block of same-size leaves.
  require_refined_tree(mesh.refined_leaves(), mesh.size());
}

/// The hpu mesh's own structures: the feed's blocks, the input list and the cell store's
/// base values. O(n lg n).
void check_hpu_structures(const MeshState& s) {
  s.hpu_state.check_invariants(s.present());
}

/// Applies validated edits with one propagation. Built with the CMake option
/// SAC_DEBUG_CHECKS, every checker then runs: check_invariants() but the engine's, which
/// propagate() has just run.
std::vector<PointId> checked_update(const DynamicMesh& mesh, MeshState& s, std::span<const Edit<2>> edits,
                                    const HpuInputs::Plan& plan) {
  // The update's time is the whole of it but the validation: relinking, the propagation
  // and the change feed.
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<PointId> ids = s.update(edits, plan);
  s.core.last.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
#ifdef SAC_DEBUG_CHECKS
  s.core.check_own_invariants();
  check_trees_of(mesh, s);
  if (s.is_hpu()) check_hpu_structures(s);
#else
  (void)mesh;
#endif
  return ids;
}

}  // namespace detail

DynamicMesh::DynamicMesh(const Box<2>& box, std::span<const Point<2>> points, MeshOptions options)
    : s_(std::make_unique<detail::MeshState>(box, options)) {
  std::vector<Edit<2>> edits;
  edits.reserve(points.size());
  for (const Point<2>& p : points) edits.push_back(Edit<2>{EditOp::Insert, p});
  const auto plan = s_->validate(edits, "point");
  validate_mesh_box(box);
  if (s_->is_hpu()) {
    s_->hpu_state.commit(s_->core.rt, plan);
    auto* hpu = &s_->hpu;
    // The hpu program reads its own input list and cell store, not the quadtree: no tree.
    s_->core.build(points, [hpu](sac::Engine& rt) { detail::HpuCellsProgram::main(rt, hpu); }, false);
    s_->hpu_state.feed.clear_change();
  } else {
    auto* program = &s_->program;
    s_->core.build(points, [program](sac::Engine& rt) { detail::QuadtreeMeshProgram::main(rt, program); });
  }
  s_->count(edits);
  s_->log.settle();
}

DynamicMesh::~DynamicMesh() = default;
DynamicMesh::DynamicMesh(DynamicMesh&&) noexcept = default;
DynamicMesh& DynamicMesh::operator=(DynamicMesh&&) noexcept = default;

PointId DynamicMesh::insert(const Point<2>& p) {
  const Edit<2> e{EditOp::Insert, p};
  const auto plan = s_->validate({&e, 1}, "");
  return detail::checked_update(*this, *s_, {&e, 1}, plan).front();
}

void DynamicMesh::erase(PointId id) {
  const Edit<2> e = s_->core.erase_edit(id);
  const auto plan = s_->validate({&e, 1}, "");
  detail::checked_update(*this, *s_, {&e, 1}, plan);
}

void DynamicMesh::erase(const Point<2>& p) {
  const Edit<2> e{EditOp::Delete, p};
  const auto plan = s_->validate({&e, 1}, "");
  detail::checked_update(*this, *s_, {&e, 1}, plan);
}

std::vector<PointId> DynamicMesh::apply(std::span<const Edit<2>> edits) {
  const auto plan = s_->validate(edits, "edit");
  return detail::checked_update(*this, *s_, edits, plan);
}

const Box<2>& DynamicMesh::box() const noexcept { return s_->core.box; }
const MeshOptions& DynamicMesh::options() const noexcept { return s_->options; }
std::size_t DynamicMesh::size() const noexcept { return s_->core.by_id.size(); }
bool DynamicMesh::contains(PointId id) const noexcept { return s_->core.by_id.contains(id); }
std::optional<PointId> DynamicMesh::find(const Point<2>& p) const noexcept { return s_->core.find(p); }
const Point<2>& DynamicMesh::point(PointId id) const { return s_->core.point(id); }
std::vector<std::pair<PointId, Point<2>>> DynamicMesh::points() const { return s_->core.points(); }

std::vector<Triangle> DynamicMesh::triangles() const {
  if (s_->is_hpu()) return s_->hpu_state.feed.triangles();
  return s_->log.simplices();
}

std::size_t DynamicMesh::num_triangles() const noexcept {
  if (s_->is_hpu()) return s_->hpu_state.feed.live_count();
  return s_->log.num_simplices();
}

Mesh DynamicMesh::mesh() const { return make_mesh(triangles()); }
const MeshChange& DynamicMesh::last_change() const noexcept { return s_->change; }

std::vector<Leaf<2>> DynamicMesh::refined_leaves() const {
  std::vector<Leaf<2>> out;
  if (s_->is_hpu()) return out;
  for (const detail::LeafBlock* b = s_->log.live; b; b = b->next) {
    std::uint32_t held = 0;
    if (b->shape.warped >= 0) {
      const auto q = try_locate(s_->core.box, b->shape.warp_to);
      held = q && dynmesh::contains(b->shape.cell, *q) ? 1 : 0;
    }
    out.push_back(Leaf<2>{b->shape.cell, held});
  }
  std::sort(out.begin(), out.end());
  return out;
}

const UpdateStats& DynamicMesh::last_update() const noexcept { return s_->core.last; }
const sac::Stats& DynamicMesh::engine_stats() const noexcept { return s_->core.rt.stats(); }
std::size_t DynamicMesh::trace_bytes() const {
  std::size_t hpu = 0;
  if (s_->is_hpu())
    hpu = s_->hpu_state.bytes();
  return s_->core.bytes() + hpu + s_->counts.size() * (sizeof(CellId<2>) + 2 * sizeof(void*) + sizeof(std::int64_t));
}
std::size_t DynamicMesh::record_bytes() const { return s_->core.rt.record_bytes(); }
std::uint64_t DynamicMesh::live_events() const { return s_->core.rt.live_events(); }
void DynamicMesh::compact() { s_->core.compact(); }

void DynamicMesh::check_invariants() const {
  s_->core.check_invariants();
  detail::check_trees_of(*this, *s_);
  if (!s_->is_hpu()) return;
  detail::check_hpu_structures(*s_);
  require_valid_mesh(mesh(), box(), s_->present(),
                     MeshCheckOptions{.min_angle_deg = s_->options.min_angle, .delaunay = true});
}

}  // namespace dynmesh
