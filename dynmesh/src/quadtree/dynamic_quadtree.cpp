// dynamic_quadtree.cpp — DynamicQuadtree: the public API over its DynamicState
// (dynamic_quadtree_state.hpp: QuadtreeCore running QuadTreeRefine alone).
#include "dynmesh/dynamic_quadtree.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "quadtree/dynamic_quadtree_state.hpp"
#include "dynmesh/detail/touching_leaves.hpp"

namespace dynmesh {
namespace detail {

/// The length of a leaf's point list.
template <std::size_t d>
std::uint32_t count_points(const PNode<d>* p) noexcept {
  std::uint32_t k = 0;
  for (; p; p = p->next.get()) ++k;
  return k;
}

/// The tree's rules: every leaf's list holds exactly the points located in it, and the
/// leaves are those of T* (check_tree).
template <std::size_t d>
void check_tree_of(const DynamicQuadtree<d>& tree, const DynamicState<d>& s) {
  s.for_each_leaf([&](const CellId<d>& c, const PNode<d>* p) {
    for (; p; p = p->next.get())
      if (!dynmesh::contains(c, p->q) || !s.by_pos.contains(p->q))
        throw InvariantError("dynmesh: leaf " + to_string(c) + " lists a point it does not hold");
  });
  require_valid_tree<d>(tree.positions(), tree.leaves(), s.program.split_below);
}

/// Applies validated edits with one propagation. Built with the CMake option
/// SAC_DEBUG_CHECKS, every checker then runs: check_invariants() but the engine's, which
/// propagate() has just run.
template <std::size_t d>
std::vector<PointId> checked_update(const DynamicQuadtree<d>& tree, DynamicState<d>& s,
                                    std::span<const Edit<d>> edits) {
  std::vector<PointId> ids = s.update(edits);
#ifdef SAC_DEBUG_CHECKS
  s.check_own_invariants();
  check_tree_of(tree, s);
#else
  (void)tree;
#endif
  return ids;
}

}  // namespace detail

template <std::size_t d>
  requires SupportedDim<d>
DynamicQuadtree<d>::DynamicQuadtree(const Box<d>& box, std::span<const Point<d>> points,
                                    const DynamicQuadtreeOptions& options)
    : s_(std::make_unique<detail::DynamicState<d>>(box)) {
  s_->program.split_below = detail::checked_split_below(options.split_below);
  s_->validate(detail::inserts_of<d>(points), "point");
  s_->build(points, [](sac::Engine&) {});
}

template <std::size_t d>
  requires SupportedDim<d>
DynamicQuadtree<d>::~DynamicQuadtree() = default;
template <std::size_t d>
  requires SupportedDim<d>
DynamicQuadtree<d>::DynamicQuadtree(DynamicQuadtree&&) noexcept = default;
template <std::size_t d>
  requires SupportedDim<d>
DynamicQuadtree<d>& DynamicQuadtree<d>::operator=(DynamicQuadtree&&) noexcept = default;

template <std::size_t d>
  requires SupportedDim<d>
PointId DynamicQuadtree<d>::insert(const Point<d>& p) {
  const Edit<d> e{EditOp::Insert, p};
  s_->validate({&e, 1}, "");
  return detail::checked_update<d>(*this, *s_, {&e, 1}).front();
}

template <std::size_t d>
  requires SupportedDim<d>
void DynamicQuadtree<d>::erase(PointId id) {
  const Edit<d> e = s_->erase_edit(id);
  detail::checked_update<d>(*this, *s_, {&e, 1});
}

template <std::size_t d>
  requires SupportedDim<d>
void DynamicQuadtree<d>::erase(const Point<d>& p) {
  const Edit<d> e{EditOp::Delete, p};
  s_->validate({&e, 1}, "");
  detail::checked_update<d>(*this, *s_, {&e, 1});
}

template <std::size_t d>
  requires SupportedDim<d>
std::vector<PointId> DynamicQuadtree<d>::apply(std::span<const Edit<d>> edits) {
  s_->validate(edits, "edit");
  return detail::checked_update<d>(*this, *s_, edits);
}

template <std::size_t d>
  requires SupportedDim<d>
const Box<d>& DynamicQuadtree<d>::box() const noexcept { return s_->box; }

template <std::size_t d>
  requires SupportedDim<d>
std::size_t DynamicQuadtree<d>::size() const noexcept { return s_->by_id.size(); }

template <std::size_t d>
  requires SupportedDim<d>
bool DynamicQuadtree<d>::contains(PointId id) const noexcept { return s_->by_id.contains(id); }

template <std::size_t d>
  requires SupportedDim<d>
std::optional<PointId> DynamicQuadtree<d>::find(const Point<d>& p) const noexcept { return s_->find(p); }

template <std::size_t d>
  requires SupportedDim<d>
const Point<d>& DynamicQuadtree<d>::point(PointId id) const { return s_->point(id); }

template <std::size_t d>
  requires SupportedDim<d>
std::vector<std::pair<PointId, Point<d>>> DynamicQuadtree<d>::points() const { return s_->points(); }

template <std::size_t d>
  requires SupportedDim<d>
std::vector<Position<d>> DynamicQuadtree<d>::positions() const {
  std::vector<Position<d>> out;
  out.reserve(size());
  for (auto* n = s_->first; n; n = n->succ) out.push_back(n->q);
  return out;
}

template <std::size_t d>
  requires SupportedDim<d>
std::vector<Leaf<d>> DynamicQuadtree<d>::leaves() const {
  // T* has 1 + (2^d − 1)·(split cells) leaves: reserving them keeps the vector's growth
  // (up to twice its size, beside the trace) off the peak of a large run.
  std::size_t split = 0;
  s_->dir.for_each([&](const detail::Slot<d>& sl) {
    split += sl.split.written() && detail::tree_split(sl.split.get());
  });
  std::vector<Leaf<d>> out;
  out.reserve(1 + static_cast<std::size_t>(kChildren<d> - 1) * split);
  s_->for_each_leaf(
      [&](const CellId<d>& c, const detail::PNode<d>* p) { out.push_back(Leaf<d>{c, detail::count_points(p)}); });
  std::sort(out.begin(), out.end());
  return out;
}

template <std::size_t d>
  requires SupportedDim<d>
std::vector<Leaf<d>> DynamicQuadtree<d>::leaves_in(const CellId<d>& c) const {
  std::vector<Leaf<d>> out;
  if (!valid(c) || !(s_->is_split(c) || s_->is_leaf(c))) return out;  // inside a leaf
  s_->for_each_leaf(
      [&](const CellId<d>& cell, const detail::PNode<d>* p) { out.push_back(Leaf<d>{cell, detail::count_points(p)}); }, c);
  std::sort(out.begin(), out.end());
  return out;
}

template <std::size_t d>
  requires SupportedDim<d>
bool DynamicQuadtree<d>::is_split(const CellId<d>& c) const noexcept {
  return s_->is_split(c);
}

template <std::size_t d>
  requires SupportedDim<d>
std::vector<LeafPoints<d>> DynamicQuadtree<d>::leaves_with_points() const {
  std::vector<LeafPoints<d>> out;
  s_->for_each_leaf([&](const CellId<d>& c, const detail::PNode<d>* p) {
    LeafPoints<d> lp{c, {}};
    for (; p; p = p->next.get()) lp.points.push_back(s_->by_pos.at(p->q)->id);
    out.push_back(std::move(lp));
  });
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.cell < b.cell; });
  return out;
}

template <std::size_t d>
  requires SupportedDim<d>
CellId<d> DynamicQuadtree<d>::locate(const Point<d>& p) const {
  return s_->leaf_at(dynmesh::locate(s_->box, p));
}

template <std::size_t d>
  requires SupportedDim<d>
std::vector<CellId<d>> DynamicQuadtree<d>::neighbours(const CellId<d>& leaf) const {
  const auto& s = *s_;
  if (!s.is_leaf(leaf)) throw std::invalid_argument("neighbours: " + to_string(leaf) + " is not a leaf");
  std::vector<CellId<d>> out, stack;
  detail::for_each_touching_leaf<d>(
      leaf, [&](const CellId<d>& cell) { return s.is_split(cell); }, [](const CellId<d>&) { return true; },
      [&](const CellId<d>& l) { out.push_back(l); },
      [&](const CellId<d>& l, const CellId<d>&) { out.push_back(l); }, stack);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

template <std::size_t d>
  requires SupportedDim<d>
std::size_t DynamicQuadtree<d>::num_split() const {
  std::size_t k = 0;
  s_->dir.for_each([&](const detail::Slot<d>& slot) {
    if (slot.split.written() && detail::tree_split(slot.split.get())) ++k;
  });
  return k;
}

template <std::size_t d>
  requires SupportedDim<d>
const UpdateStats& DynamicQuadtree<d>::last_update() const noexcept { return s_->last; }

template <std::size_t d>
  requires SupportedDim<d>
const sac::Stats& DynamicQuadtree<d>::engine_stats() const noexcept { return s_->rt.stats(); }

template <std::size_t d>
  requires SupportedDim<d>
std::size_t DynamicQuadtree<d>::trace_bytes() const { return s_->bytes(); }

template <std::size_t d>
  requires SupportedDim<d>
std::size_t DynamicQuadtree<d>::record_bytes() const { return s_->rt.record_bytes(); }

template <std::size_t d>
  requires SupportedDim<d>
QuadtreeMemory DynamicQuadtree<d>::memory_breakdown() const {
  const auto& s = *s_;
  QuadtreeMemory m;
  m.engine = s.rt.memory_breakdown();
  m.slots = s.dir.slot_pool().live();
  m.slot_bytes = s.dir.slot_pool().bytes();
  m.level_nodes = s.dir.node_pool().live();
  m.level_node_bytes = s.dir.node_pool().bytes();
  m.table_bytes = s.dir.table_bytes();
  m.input_nodes = s.inputs.live();
  m.input_node_bytes = s.inputs.bytes();
  return m;
}

template <std::size_t d>
  requires SupportedDim<d>
std::uint64_t DynamicQuadtree<d>::live_events() const { return s_->rt.live_events(); }

template <std::size_t d>
  requires SupportedDim<d>
std::size_t DynamicQuadtree<d>::directory_size() const noexcept { return s_->dir.size(); }

template <std::size_t d>
  requires SupportedDim<d>
void DynamicQuadtree<d>::compact() { s_->compact(); }

template <std::size_t d>
  requires SupportedDim<d>
void DynamicQuadtree<d>::check_invariants() const {
  s_->check_invariants();
  detail::check_tree_of(*this, *s_);
}

template class DynamicQuadtree<2>;
template class DynamicQuadtree<3>;

}  // namespace dynmesh
