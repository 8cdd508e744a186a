// dynamic_mesh.cpp — DynamicMesh: one of two mesh states behind one interface (MeshState),
// the meshes' shared input rules, and the change feed.
//
// Purpose: the public class holds a MeshState, chosen once by the options:
//   QuadtreeMeshState – QuadtreeCore<2> running QuadTreeRefine and the quadtree mesh's
//                       postprocess in one trace; its feed is the program's FeedLog;
//   HpuMeshState      – the hpu program (src/hpu/hpu_cells_program.hpp) in its own engine,
//                       on its own input list and cell store (HpuCellsState), with no tree;
//                       its feed is HpuMeshFeed.
// Both keep the input points and their ids in an InputPoints<2> (quadtree_core.hpp), whose
// validation, with the meshes' own resolution rule (MeshInputRules), every mutator call runs
// over its whole input before anything changes.
// Invariants: check_invariants() as dynamic_mesh.hpp states it. Failure atomicity: a state
// validates before it links, commits or propagates anything.
// Complexity: as dynamic_mesh.hpp states it; the interface costs one virtual call per call.
// Paper: Acar & Hudson, Section 4 (the mutator: changes to the input, then change
// propagation); docs/DESIGN.md, "An update, hop by hop".
#include "dynmesh/dynamic_mesh.hpp"

#include <algorithm>
#include <chrono>
#include <iterator>
#include <span>
#include <stdexcept>
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
/// the side, which overflows for 0 or NaN).
const Box<2>& validated(const Box<2>& box) {
  validate_box(box);
  return box;
}

/// The options, validated before anything is built.
MeshOptions validated(MeshOptions o) {
  if (o.postprocess == Postprocess::Hpu) validate_min_angle(o.min_angle);
  checked_split_below(o.tree.split_below);
  if (o.postprocess == Postprocess::Hpu && o.tree.split_below != 0)
    throw std::invalid_argument("dynmesh: the hpu mesh refines no quadtree: tree options apply to the quadtree mesh");
  return o;
}

/// The meshes' own input rule (mesh_input_rules.hpp: no two points closer than the mesh's
/// resolution allows) on the counts of present points per cell, next to the quadtree's rules
/// that InputPoints::validate checks.
struct MeshInputRules {
  CellCounts<2> counts;

  /// Checks a batch against the points' rules and the mesh's, changing nothing.
  void validate(const InputPoints<2>& input, const MeshGrid& grid, std::span<const Edit<2>> edits,
                const std::string& noun) const {
    input.validate(edits, noun, MeshChecks<2>{grid, counts});
  }
  /// After a committed update.
  void count(const MeshGrid& grid, const Box<2>& box, std::span<const Edit<2>> edits) {
    count_edits<2>(grid, box, edits, counts);
  }
  std::size_t bytes() const noexcept {
    return counts.size() * (sizeof(CellId<2>) + 2 * sizeof(void*) + sizeof(std::int64_t));
  }
};

/// The update's time is the whole of it but the validation: relinking, the propagation and
/// the change feed.
template <class Update>
std::vector<PointId> timed(UpdateStats& last, Update&& update) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<PointId> ids = update();
  last.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return ids;
}

/// A mesh's state behind DynamicMesh: its input points, its engine, its program and its
/// feed. Every mutator validates its whole input first and throws InputError with nothing
/// changed.
class MeshState {
 public:
  explicit MeshState(MeshOptions o) : options(o) {}
  virtual ~MeshState() = default;
  MeshState(const MeshState&) = delete;
  MeshState& operator=(const MeshState&) = delete;

  /// Validates the points (as "point i"), then meshes them from scratch.
  virtual void build(std::span<const Point<2>> points) = 0;
  /// Validates the batch (`noun` as InputPoints::validate), then applies it with one
  /// propagation; returns the insertions' ids. Built with SAC_DEBUG_CHECKS, every checker
  /// then runs but the engine's (propagate() has just run it) and the O(n lg n) mesh
  /// contract.
  virtual std::vector<PointId> apply(std::span<const Edit<2>> edits, const std::string& noun) = 0;

  virtual const InputPoints<2>& input() const noexcept = 0;
  virtual const sac::Engine& engine() const noexcept = 0;
  virtual const UpdateStats& last_update() const noexcept = 0;
  virtual std::vector<Triangle> triangles() const = 0;
  virtual Mesh mesh() const { return make_mesh(triangles()); }
  virtual std::size_t num_triangles() const noexcept = 0;
  virtual std::vector<Leaf<2>> refined_leaves() const = 0;
  virtual bool is_split(const CellId<2>&) const noexcept { return false; }
  virtual std::size_t trace_bytes() const = 0;
  virtual void compact() = 0;
  virtual void check_invariants() const = 0;

  const MeshOptions options;
  MeshChange change;  // the last update's
};

// ---------------------------------------------------------------------- the quadtree mesh

class QuadtreeMeshState final : public MeshState {
 public:
  QuadtreeMeshState(const Box<2>& box, MeshOptions o) : MeshState(o), log(MeshGrid(validated(box))), core(box) {
    program.dir = &core.dir;
    program.input = &core.head;
    program.log = &log;
    core.program.split_below = o.tree.split_below;
  }
  ~QuadtreeMeshState() override { log.closing = true; }  // before core (and its engine) goes

  void build(std::span<const Point<2>> points) override {
    const std::vector<Edit<2>> edits = inserts_of<2>(points);
    rules.validate(core, log.grid, edits, "point");
    validate_mesh_box(core.box);
    auto* mesh_program = &program;
    core.build(points, [mesh_program](sac::Engine& rt) { QuadtreeMeshProgram::main(rt, mesh_program); });
    rules.count(log.grid, core.box, edits);
    log.settle();
  }

  std::vector<PointId> apply(std::span<const Edit<2>> edits, const std::string& noun) override {
    rules.validate(core, log.grid, edits, noun);
    std::vector<PointId> ids = timed(core.last, [&] {
      std::vector<PointId> out = core.update(edits);
      rules.count(log.grid, core.box, edits);
      log.take_change(change);
      return out;
    });
#ifdef SAC_DEBUG_CHECKS
    core.check_own_invariants();
    check_trees();
#endif
    return ids;
  }

  const InputPoints<2>& input() const noexcept override { return core; }
  const sac::Engine& engine() const noexcept override { return core.rt; }
  const UpdateStats& last_update() const noexcept override { return core.last; }
  std::vector<Triangle> triangles() const override { return log.simplices(); }
  std::size_t num_triangles() const noexcept override { return log.num_simplices(); }

  bool is_split(const CellId<2>& c) const noexcept override { return core.is_split(c); }
  std::vector<Leaf<2>> refined_leaves() const override {
    std::vector<Leaf<2>> out;
    for (const LeafBlock* b = log.live; b; b = b->next) {
      std::uint32_t held = 0;
      if (b->shape.warped >= 0) {
        const auto q = try_locate(core.box, b->shape.warp_to);
        held = q && dynmesh::contains(b->shape.cell, *q) ? 1 : 0;
      }
      out.push_back(Leaf<2>{b->shape.cell, held});
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  std::size_t trace_bytes() const override { return core.bytes() + rules.bytes(); }
  void compact() override { core.compact(); }
  void check_invariants() const override {
    core.check_invariants();
    check_trees();
  }

 private:
  /// T* as the quadtree's contract states it, and T''s closure rule.
  void check_trees() const {
    std::vector<Position<2>> qs;
    for (const auto* n = core.first; n; n = n->succ) qs.push_back(n->q);
    std::vector<Leaf<2>> tree;
    core.for_each_leaf_of([&](const CellId<2>& c) { return core.is_split(c); },
                          [&](const CellId<2>& c) {
                            std::uint32_t k = 0;
                            for (const auto* p = core.points_in(c); p; p = p->next.get()) ++k;
                            tree.push_back(Leaf<2>{c, k});
                          });
    std::sort(tree.begin(), tree.end());
    require_valid_tree<2>(qs, tree, core.program.split_below);
    // T': every point leaf has its block of same-size leaves.
    require_refined_tree(refined_leaves(), core.by_id.size());
  }

  FeedLog log;
  MeshInputRules rules;
  QuadtreeMeshProgram program{};
  QuadtreeCore<2> core;
};

// ---------------------------------------------------------------------- the hpu mesh

class HpuMeshState final : public MeshState {
 public:
  HpuMeshState(const Box<2>& box, MeshOptions o)
      : MeshState(o), grid(validated(box)), cells(box), input_points(box), program(rt, cells, o.min_angle) {
    rt.set(input_points.head, static_cast<PNode<2>*>(nullptr));
    cells.start(rt);
  }
  ~HpuMeshState() override { cells.feed.close(); }  // before the engine goes

  void build(std::span<const Point<2>> points) override {
    const std::vector<Edit<2>> edits = inserts_of<2>(points);
    const HpuInputs::Plan plan = validate(edits, "point");
    validate_mesh_box(input_points.box);
    cells.commit(rt, plan);
    input_points.link_all(rt, points);
    rt.set_context(&program);
    cells.feed.set_logging(false);
    rt.run([](sac::Engine& rt2) { HpuCellsProgram::main(rt2); });
    cells.feed.set_logging(true);
    rules.count(grid, input_points.box, edits);
  }

  std::vector<PointId> apply(std::span<const Edit<2>> edits, const std::string& noun) override {
    const HpuInputs::Plan plan = validate(edits, noun);
    std::vector<PointId> ids = timed(last, [&] {
      std::vector<InputPoints<2>::Node*> gone;
      std::vector<PointId> out = input_points.link_edits(rt, edits, gone);
      cells.commit(rt, plan);
      propagate();
      // No tree below an input node: it goes once the trace no longer reads it.
      input_points.release(rt, gone, [](InputPoints<2>::Node*) { return true; });
      cells.release(rt);
      rules.count(grid, input_points.box, edits);
      change = cells.feed.take_change();
      return out;
    });
#ifdef SAC_DEBUG_CHECKS
    input_points.check_list_invariants();
    cells.check_invariants(present());
#endif
    return ids;
  }

  const InputPoints<2>& input() const noexcept override { return input_points; }
  const sac::Engine& engine() const noexcept override { return rt; }
  const UpdateStats& last_update() const noexcept override { return last; }
  std::vector<Triangle> triangles() const override { return cells.feed.triangles(); }
  /// Without the copies of make_mesh(triangles()): at 10^6 points they are about 0.4 GB
  /// while the trace is alive.
  Mesh mesh() const override { return cells.feed.mesh(); }
  std::size_t num_triangles() const noexcept override { return cells.feed.live_count(); }
  /// Empty: the hpu mesh refines no tree.
  std::vector<Leaf<2>> refined_leaves() const override { return {}; }
  std::size_t trace_bytes() const override {
    return rt.trace_bytes() + rt.input_bytes() + input_points.inputs.bytes() + cells.bytes() + rules.bytes();
  }
  /// Nothing to sweep: a left input node is freed by its update, and the cell store keeps
  /// every cell it made.
  void compact() override {}
  void check_invariants() const override {
    rt.check_invariants();
    input_points.check_list_invariants();
    cells.check_invariants(present());
    const Mesh m = mesh();
    if (m != make_mesh(triangles()))
      throw InvariantError("dynmesh: DynamicMesh: the feed's mesh() and its triangles differ");
    require_valid_mesh(m, input_points.box, present(),
                       MeshCheckOptions{.min_angle_deg = options.min_angle, .delaunay = true});
  }

 private:
  /// The whole batch against the points' and the mesh's input rules, then the hpu input
  /// list's plan (the side midpoints the batch adds or removes), which build/apply commit.
  /// Changes nothing.
  HpuInputs::Plan validate(std::span<const Edit<2>> edits, const std::string& noun) const {
    rules.validate(input_points, grid, edits, noun);
    return cells.plan(edits);
  }
  void propagate() {
    rt.propagate();
    last.trace_distance = rt.stats().last_trace_distance;
    last.reexecuted = rt.stats().last_reexecuted;
  }
  /// The present points, in insertion order (for the checkers).
  std::vector<Point<2>> present() const {
    std::vector<Point<2>> out;
    for (const auto* n = input_points.first; n; n = n->succ) out.push_back(n->point);
    return out;
  }

  MeshGrid grid;
  MeshInputRules rules;
  HpuCellsState cells;  // the input list, cell store and feed: they outlive the engine
  InputPoints<2> input_points;
  UpdateStats last;
  sac::Engine rt;
  HpuCellsProgram program;  // after the engine: its view is built on it
};

std::unique_ptr<MeshState> make_state(const Box<2>& box, MeshOptions options) {
  options = validated(options);
  if (options.postprocess == Postprocess::Hpu) return std::make_unique<HpuMeshState>(box, options);
  return std::make_unique<QuadtreeMeshState>(box, options);
}

}  // namespace detail

DynamicMesh::DynamicMesh(const Box<2>& box, std::span<const Point<2>> points, MeshOptions options)
    : s_(detail::make_state(box, options)) {
  s_->build(points);
}

DynamicMesh::~DynamicMesh() = default;
DynamicMesh::DynamicMesh(DynamicMesh&&) noexcept = default;
DynamicMesh& DynamicMesh::operator=(DynamicMesh&&) noexcept = default;

PointId DynamicMesh::insert(const Point<2>& p) {
  const Edit<2> e{EditOp::Insert, p};
  return s_->apply({&e, 1}, "").front();
}

void DynamicMesh::erase(PointId id) {
  const Edit<2> e = s_->input().erase_edit(id);
  s_->apply({&e, 1}, "");
}

void DynamicMesh::erase(const Point<2>& p) {
  const Edit<2> e{EditOp::Delete, p};
  s_->apply({&e, 1}, "");
}

std::vector<PointId> DynamicMesh::apply(std::span<const Edit<2>> edits) { return s_->apply(edits, "edit"); }

const Box<2>& DynamicMesh::box() const noexcept { return s_->input().box; }
const MeshOptions& DynamicMesh::options() const noexcept { return s_->options; }
std::size_t DynamicMesh::size() const noexcept { return s_->input().by_id.size(); }
bool DynamicMesh::contains(PointId id) const noexcept { return s_->input().by_id.contains(id); }
std::optional<PointId> DynamicMesh::find(const Point<2>& p) const noexcept { return s_->input().find(p); }
const Point<2>& DynamicMesh::point(PointId id) const { return s_->input().point(id); }
std::vector<std::pair<PointId, Point<2>>> DynamicMesh::points() const { return s_->input().points(); }

std::vector<Triangle> DynamicMesh::triangles() const { return s_->triangles(); }
std::size_t DynamicMesh::num_triangles() const noexcept { return s_->num_triangles(); }
Mesh DynamicMesh::mesh() const { return s_->mesh(); }
const MeshChange& DynamicMesh::last_change() const noexcept { return s_->change; }
std::vector<Leaf<2>> DynamicMesh::refined_leaves() const { return s_->refined_leaves(); }
bool DynamicMesh::is_split(const CellId<2>& c) const noexcept { return s_->is_split(c); }

const UpdateStats& DynamicMesh::last_update() const noexcept { return s_->last_update(); }
const sac::Stats& DynamicMesh::engine_stats() const noexcept { return s_->engine().stats(); }
sac::MemoryBreakdown DynamicMesh::memory_breakdown() const { return s_->engine().memory_breakdown(); }
std::size_t DynamicMesh::trace_bytes() const { return s_->trace_bytes(); }
std::size_t DynamicMesh::record_bytes() const { return s_->engine().record_bytes(); }
std::uint64_t DynamicMesh::live_events() const { return s_->engine().live_events(); }
void DynamicMesh::compact() { s_->compact(); }
void DynamicMesh::check_invariants() const { s_->check_invariants(); }

}  // namespace dynmesh
