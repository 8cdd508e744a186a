// dynamic_mesh.cpp — DynamicMesh: QuadtreeCore<2> running QuadTreeRefine and the quadtree
// postprocess in one trace, the mesh's own input rules, and the change feed.
#include "dynmesh/dynamic_mesh.hpp"

#include <algorithm>
#include <iterator>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>

#include "dynmesh/detail/quadtree_mesh_rules.hpp"
#include "quadtree_core.hpp"
#include "quadtree_mesh_program.hpp"

namespace dynmesh {
namespace detail {

/// Points per cell of the mesh's resolution level, for its input rule.
using CellCounts = std::unordered_map<CellId<2>, std::int64_t, CellHash>;

/// The mesh's input rules over a batch: the quadtree's validate() calls insert/erase in
/// batch order; `delta` holds the batch's changes to the counts.
struct MeshChecks {
  const MeshGrid& grid;
  const CellCounts& counts;
  CellCounts delta{};

  int level() const { return std::max(grid.level_limit, 0); }
  std::int64_t count(const CellId<2>& c) const {
    std::int64_t k = 0;
    if (auto it = counts.find(c); it != counts.end()) k += it->second;
    if (auto it = delta.find(c); it != delta.end()) k += it->second;
    return k;
  }
  template <class Fail>
  void insert(const Position<2>& q, const Point<2>& p, Fail&& fail) {
    check_mesh_resolution(grid, q, p, [&](const CellId<2>& c) { return count(c) > 0; }, fail);
    ++delta[cell_of(q, level())];
  }
  void erase(const Position<2>& q) { --delta[cell_of(q, level())]; }
};

/// The box, validated before MeshGrid computes with it (its resolution level takes ilogb of
/// the side, which overflows for 0 or NaN): `log` is built before `core` validates.
const Box<2>& validated(const Box<2>& box) {
  validate_box(box);
  return box;
}

struct MeshState {
  MeshState(const Box<2>& box, MeshOptions opts) : options(opts), log(MeshGrid(validated(box))), core(box) {
    program.dir = &core.dir;
    program.input = &core.head;
    program.log = &log;
  }
  ~MeshState() { log.closing = true; }  // before core (and its engine) goes

  MeshOptions options;
  FeedLog log;
  CellCounts counts;
  MeshChange change;
  QuadtreeMeshProgram program{};
  QuadtreeCore<2> core;

  void validate(std::span<const Edit<2>> edits, const std::string& noun) const {
    core.validate(edits, noun, MeshChecks{log.grid, counts});
  }
  void count(std::span<const Edit<2>> edits) {
    const int level = std::max(log.grid.level_limit, 0);
    for (const Edit<2>& e : edits) {
      const CellId<2> c = cell_of(*try_locate(core.box, e.point), level);
      auto& k = counts[c];
      k += e.op == EditOp::Insert ? 1 : -1;
      if (k == 0) counts.erase(c);
    }
  }
  std::vector<PointId> update(std::span<const Edit<2>> edits) {
    log.created.clear();
    log.removed.clear();
    auto ids = core.update(edits);
    count(edits);
    collect_change();
    return ids;
  }
  /// The feed of the update just propagated: the triangles of the blocks it undid, less
  /// those of the blocks it made (a leaf re-made unchanged is no change).
  void collect_change() {
    std::vector<Triangle> added;
    for (LeafBlock* b : log.created) {
      if (!b) continue;
      triangulate_leaf(log.grid, b->shape, added);
      b->slot = LeafBlock::kOld;
    }
    log.created.clear();
    std::vector<Triangle> removed = std::move(log.removed);
    log.removed.clear();
    std::sort(added.begin(), added.end());
    std::sort(removed.begin(), removed.end());
    change.removed.clear();
    change.added.clear();
    std::set_difference(removed.begin(), removed.end(), added.begin(), added.end(),
                        std::back_inserter(change.removed));
    std::set_difference(added.begin(), added.end(), removed.begin(), removed.end(),
                        std::back_inserter(change.added));
  }
};

/// T* as the quadtree's contract states it, and T''s closure rule.
void check_trees_of(const DynamicMesh& mesh, const MeshState& s) {
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

/// Applies validated edits with one propagation. Built with the CMake option
/// SAC_DEBUG_CHECKS, every checker then runs: check_invariants() but the engine's, which
/// propagate() has just run.
std::vector<PointId> checked_update(const DynamicMesh& mesh, MeshState& s, std::span<const Edit<2>> edits) {
  std::vector<PointId> ids = s.update(edits);
#ifdef SAC_DEBUG_CHECKS
  s.core.check_own_invariants();
  check_trees_of(mesh, s);
#else
  (void)mesh;
#endif
  return ids;
}

}  // namespace detail

DynamicMesh::DynamicMesh(const Box<2>& box, std::span<const Point<2>> points, MeshOptions options)
    : s_(std::make_unique<detail::MeshState>(box, options)) {
  if (options.postprocess != Postprocess::Quadtree)
    throw InputError(InputError::Kind::Malformed, "the hpu postprocess is not available yet: use quadtree");
  std::vector<Edit<2>> edits;
  edits.reserve(points.size());
  for (const Point<2>& p : points) edits.push_back(Edit<2>{EditOp::Insert, p});
  s_->validate(edits, "point");
  validate_mesh_box(box);
  auto* program = &s_->program;
  s_->core.build(points, [program](sac::Engine& rt) { detail::QuadtreeMeshProgram::main(rt, program); });
  s_->count(edits);
  for (detail::LeafBlock* b : s_->log.created) b->slot = detail::LeafBlock::kOld;
  s_->log.created.clear();
}

DynamicMesh::~DynamicMesh() = default;
DynamicMesh::DynamicMesh(DynamicMesh&&) noexcept = default;
DynamicMesh& DynamicMesh::operator=(DynamicMesh&&) noexcept = default;

PointId DynamicMesh::insert(const Point<2>& p) {
  const Edit<2> e{EditOp::Insert, p};
  s_->validate({&e, 1}, "");
  return detail::checked_update(*this, *s_, {&e, 1}).front();
}

void DynamicMesh::erase(PointId id) {
  const Edit<2> e = s_->core.erase_edit(id);
  detail::checked_update(*this, *s_, {&e, 1});
}

void DynamicMesh::erase(const Point<2>& p) {
  const Edit<2> e{EditOp::Delete, p};
  s_->validate({&e, 1}, "");
  detail::checked_update(*this, *s_, {&e, 1});
}

std::vector<PointId> DynamicMesh::apply(std::span<const Edit<2>> edits) {
  s_->validate(edits, "edit");
  return detail::checked_update(*this, *s_, edits);
}

const Box<2>& DynamicMesh::box() const noexcept { return s_->core.box; }
const MeshOptions& DynamicMesh::options() const noexcept { return s_->options; }
std::size_t DynamicMesh::size() const noexcept { return s_->core.by_id.size(); }
bool DynamicMesh::contains(PointId id) const noexcept { return s_->core.by_id.contains(id); }
std::optional<PointId> DynamicMesh::find(const Point<2>& p) const noexcept { return s_->core.find(p); }
const Point<2>& DynamicMesh::point(PointId id) const { return s_->core.point(id); }
std::vector<std::pair<PointId, Point<2>>> DynamicMesh::points() const { return s_->core.points(); }

std::vector<Triangle> DynamicMesh::triangles() const {
  std::vector<Triangle> out;
  out.reserve(s_->log.live_count * 2);
  for (const detail::LeafBlock* b = s_->log.live; b; b = b->next) detail::triangulate_leaf(s_->log.grid, b->shape, out);
  std::sort(out.begin(), out.end());
  return out;
}

std::size_t DynamicMesh::num_triangles() const noexcept {
  std::size_t k = 0;
  std::vector<Triangle> scratch;
  for (const detail::LeafBlock* b = s_->log.live; b; b = b->next) {
    scratch.clear();
    detail::triangulate_leaf(s_->log.grid, b->shape, scratch);
    k += scratch.size();
  }
  return k;
}

Mesh DynamicMesh::mesh() const { return make_mesh(triangles()); }
const MeshChange& DynamicMesh::last_change() const noexcept { return s_->change; }

std::vector<Leaf<2>> DynamicMesh::refined_leaves() const {
  std::vector<Leaf<2>> out;
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
  return s_->core.bytes() + s_->counts.size() * (sizeof(CellId<2>) + 2 * sizeof(void*) + sizeof(std::int64_t));
}
std::size_t DynamicMesh::record_bytes() const { return s_->core.rt.record_bytes(); }
std::uint64_t DynamicMesh::live_events() const { return s_->core.rt.live_events(); }
void DynamicMesh::compact() { s_->core.compact(); }

void DynamicMesh::check_invariants() const {
  s_->core.check_invariants();
  detail::check_trees_of(*this, *s_);
}

}  // namespace dynmesh
