// hpu_inputs.hpp (private) — the input list of the self-adjusting hpu mesh, kept by the
// mutator: the input points and the side midpoints they need, in insertion_less order
// (hpu_geometry.hpp: BRIO rounds, then (Morton, xy)).
//
// Purpose: HpuCellsProgram (hpu_cells_program.hpp) reads one list, `head`, of the first
// vertices after the box's corners: the inputs and side_midpoints(box, inputs) (hpu_geometry.hpp), less the
// box's corners (an input may lie on one, in the closed box: it is the box's own vertex;
// fuzz_dynamic_mesh found the far corners inserted twice when only the near one was left
// out). HpuInputs keeps that list equal to its
// definition under insertions and deletions of inputs, relinking it with Engine::set, in
// time proportional to the change rather than to n:
//   * A midpoint belongs to exactly one side (it is never a corner). Per side, the side's
//     vertices (its corners and the inputs on it) and a count per midpoint: how many inputs
//     have it on their halving path (side_path). An input's path depends only on it and the
//     two side vertices around its projection, so an input off the side adds or removes
//     its own path and nothing else.
//   * An input on a side changes that side's vertices and so other inputs' paths: the
//     side's counts are recomputed from every input (O(n), and rare: it needs an input
//     exactly on the box's boundary).
// Two phases make a call failure-atomic: plan() computes everything that can fail (a path
// that double precision cannot halve: InputError(Resolution)) and changes nothing;
// commit() applies a plan and cannot fail (but for memory). After the propagation that
// follows, release() retires the nodes that left the list.
//
// Invariants (check_invariants): walking the list from head gives exactly the inputs and
// their side midpoints less the box's corners, each once, strictly in insertion_less order;
// the counts equal a from-scratch count; every node in the map is in the list.
// Complexity: plan + commit O(k (lg n + path)) for k edits off the sides (a path has O(lg
// L/s) midpoints); O(n) for a batch holding an input on a side.
// Paper: Ruppert (1995) and Shewchuk's Triangle for encroached subsegments; Acar & Hudson,
// Figure 5 (DynHPU).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <sac/engine.hpp>
#include <sac/mod.hpp>

#include "dynmesh/box.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"
#include "hpu/hpu_geometry.hpp"
#include "hpu/cell_store.hpp"

namespace dynmesh::detail {

/// A node of the input list: an input or a side midpoint, and the rest of the list. It is
/// the point's vertex too (the cell store's base values hold it).
struct HpuInputNode : CellVertex {
  explicit HpuInputNode(const Point<2>& x) : CellVertex(x) {}
  sac::Mod<HpuInputNode*> next;
};

class HpuInputs {
 public:
  explicit HpuInputs(const Box<2>& box) : box_(box) {
    for (int k = 0; k < 4; ++k) {
      const SideFrame f = frame(k);
      side_[k] = {box.origin[f.u], box.origin[f.u] + box.side};
    }
  }
  HpuInputs(const HpuInputs&) = delete;
  HpuInputs& operator=(const HpuInputs&) = delete;

  /// Keeps `cells`' base values the bucket tree of the box's corners (already inserted) and
  /// the list's nodes from now on. Call before the first commit.
  void attach(InputCells* cells) noexcept { cells_ = cells; }

  /// The list's head: the program's `input`.
  sac::Mod<HpuInputNode*>& head() noexcept { return head_; }

  /// What a batch of edits changes; computed by plan(), applied by commit().
  struct Plan {
    std::vector<std::pair<Point<2>, bool>> inputs;  // (point, present after), each point once
    std::array<bool, 4> rebuild{};                  // sides whose vertices change
    std::array<std::set<double>, 4> sides;          // rebuilt sides: their new vertices
    std::array<std::map<double, int>, 4> mids;      // rebuilt: the new counts; others: deltas
  };

  /// The plan of `edits`, which the quadtree's rules have validated (a deletion names a
  /// present point, an insertion an absent one, in batch order). Throws InputError
  /// (Resolution) when a needed midpoint cannot be computed; changes nothing.
  Plan plan(std::span<const Edit<2>> edits) const {
    Plan pl;
    std::map<Point<2>, bool> after;  // touched points: present after the batch?
    for (const Edit<2>& e : edits) after[e.point] = e.op == EditOp::Insert;
    for (const auto& [p, present] : after)
      if (present != is_input(p)) pl.inputs.emplace_back(p, present);
    for (int k = 0; k < 4; ++k) {
      const SideFrame f = frame(k);
      for (const auto& [p, present] : pl.inputs) {
        if (p[f.w] != f.c) continue;
        if (!pl.rebuild[k]) pl.sides[k] = side_[k];
        pl.rebuild[k] = true;
        if (present) pl.sides[k].insert(p[f.u]);
        else if (p[f.u] != side_end(k, 0) && p[f.u] != side_end(k, 1)) pl.sides[k].erase(p[f.u]);
      }
    }
    std::vector<Point<2>> path;
    for (int k = 0; k < 4; ++k) {
      auto& counts = pl.mids[k];
      if (pl.rebuild[k]) {
        // Every input after the batch, against the side's new vertices.
        const auto count_all = [&](const Point<2>& p) {
          path.clear();
          side_path(k, pl.sides[k], p, path);
          for (const Point<2>& m : path) ++counts[m[frame(k).u]];
        };
        for (const auto& [at, entry] : list_)
          if (entry.input && !after.count(at.p)) count_all(at.p);
        for (const auto& [p, present] : after)
          if (present) count_all(p);
        continue;
      }
      for (const auto& [p, present] : pl.inputs) {
        path.clear();
        side_path(k, side_[k], p, path);
        for (const Point<2>& m : path) counts[m[frame(k).u]] += present ? 1 : -1;
      }
    }
    return pl;
  }

  /// Applies a plan made on the current state, relinking the list with rt.set (outside the
  /// computation).
  void commit(sac::Engine& rt, const Plan& pl) {
    if (!head_.written()) rt.set(head_, nullptr);
    std::vector<Point<2>> touched;
    for (const auto& [p, present] : pl.inputs) touched.push_back(p);
    for (int k = 0; k < 4; ++k) {
      const SideFrame f = frame(k);
      const auto at = [&](double t) {
        Point<2> m;
        m[f.u] = t;
        m[f.w] = f.c;
        return m;
      };
      if (pl.rebuild[k]) {
        for (const auto& [t, n] : mids_[k]) touched.push_back(at(t));
        for (const auto& [t, n] : pl.mids[k]) touched.push_back(at(t));
        side_[k] = pl.sides[k];
        mids_[k] = pl.mids[k];
        continue;
      }
      for (const auto& [t, d] : pl.mids[k]) {
        if (d == 0) continue;
        touched.push_back(at(t));
        const int n = mids_[k][t] += d;
        if (n < 0) throw InvariantError("dynmesh: HpuInputs: a side midpoint counted below zero");
        if (n == 0) mids_[k].erase(t);
      }
    }
    std::map<Point<2>, bool> input_after;
    for (const auto& [p, present] : pl.inputs) input_after[p] = present;
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    for (const Point<2>& p : touched) {
      auto it = list_.find(key(p));
      const auto in = input_after.find(p);
      const bool input = in != input_after.end() ? in->second : it != list_.end() && it->second.input;
      const bool listed = (input || is_midpoint(p)) && !is_corner(p);
      if (listed && it == list_.end()) link(rt, p, input);
      else if (!listed && it != list_.end()) unlink(rt, it);
      else if (it != list_.end()) it->second.input = input;
    }
  }

  /// After the propagation that follows commit(): frees the nodes that left the list.
  void release(sac::Engine& rt) {
    for (auto& n : gone_) {
      if (!rt.unused(n->next)) throw InvariantError("dynmesh: HpuInputs: the trace still reads a node that left");
      rt.retire(n->next);
    }
    gone_.clear();
  }

  /// The list is what its definition says for `inputs` (the present points). O(n lg n).
  void check_invariants(std::span<const Point<2>> inputs) const {
    const auto fail = [](const std::string& what) { throw InvariantError("dynmesh: HpuInputs: " + what); };
    std::set<Point<2>> want(inputs.begin(), inputs.end());
    for (const Point<2>& m : side_midpoints(box_, inputs)) want.insert(m);
    for (auto it = want.begin(); it != want.end();) it = is_corner(*it) ? want.erase(it) : std::next(it);
    std::vector<Point<2>> order(want.begin(), want.end());
    std::sort(order.begin(), order.end(), InsertionOrder{box_});
    std::size_t i = 0;
    for (const HpuInputNode* n = head_.get(); n; n = n->next.get(), ++i) {
      if (i >= order.size()) fail("the list has more points than the inputs and their side midpoints");
      if (n->p != order[i]) fail("the list's point " + std::to_string(i) + " is " + to_string(n->p) +
                                     ", its definition says " + to_string(order[i]));
      const auto it = list_.find(key(n->p));
      if (it == list_.end() || it->second.node.get() != n) fail("a listed node is not in the map");
    }
    if (i != order.size()) fail("the list misses points (" + std::to_string(i) + " of " + std::to_string(order.size()) + ")");
    if (list_.size() != order.size()) fail("the map holds nodes that are not listed");
    const std::set<Point<2>> in(inputs.begin(), inputs.end());
    for (const auto& [at, entry] : list_)
      if (entry.input != (in.count(at.p) > 0)) fail("a node's input flag is wrong: " + to_string(at.p));
  }

  /// Points listed (inputs and midpoints).
  std::size_t size() const noexcept { return list_.size(); }
  /// Bytes held outside the trace (map nodes, list nodes, counts), estimated.
  std::size_t bytes() const noexcept {
    std::size_t mids = 0;
    for (const auto& m : mids_) mids += m.size();
    return list_.size() * (sizeof(InsertionKey) + sizeof(Entry) + 4 * sizeof(void*) + sizeof(HpuInputNode)) +
           mids * (sizeof(double) + sizeof(int) + 4 * sizeof(void*));
  }

 private:
  struct InsertionOrder {
    Box<2> box;
    bool operator()(const Point<2>& a, const Point<2>& b) const noexcept { return insertion_less(box, a, b); }
  };
  // The map compares keys at every step of a search: computing the BRIO hash and the
  // Morton code there was most of the mutator's work from scratch.
  InsertionKey key(const Point<2>& p) const noexcept { return insertion_key(box_, p); }
  struct Entry {
    std::unique_ptr<HpuInputNode> node;
    bool input = false;
  };
  /// Side k: 0 bottom, 1 top (along x), 2 left, 3 right (along y); u the axis along it,
  /// w the axis across, c its w coordinate.
  struct SideFrame {
    unsigned u, w;
    double c;
  };
  SideFrame frame(int k) const noexcept {
    const unsigned u = k < 2 ? 0 : 1, w = 1 - u;
    return {u, w, box_.origin[w] + (k % 2 == 1 ? box_.side : 0.0)};
  }
  double side_end(int k, int end) const noexcept { return box_.origin[frame(k).u] + (end ? box_.side : 0.0); }

  /// p's halving path on side k with vertices `verts` (side_midpoints' rule).
  void side_path(int k, const std::set<double>& verts, const Point<2>& p, std::vector<Point<2>>& out) const {
    const SideFrame f = frame(k);
    if (p[f.w] == f.c) return;
    const auto it = verts.upper_bound(p[f.u]);
    if (it == verts.begin() || it == verts.end() || !(*std::prev(it) < p[f.u])) return;
    Point<2> a, b;
    a[f.u] = *std::prev(it), a[f.w] = f.c;
    b[f.u] = *it, b[f.w] = f.c;
    halving_path(a, b, p, f.u, out);
  }

  /// A box corner (HpuCellsState's arithmetic): the box's own vertex already.
  bool is_corner(const Point<2>& p) const noexcept {
    const double x1 = box_.origin[0] + box_.side, y1 = box_.origin[1] + box_.side;
    return (p[0] == box_.origin[0] || p[0] == x1) && (p[1] == box_.origin[1] || p[1] == y1);
  }
  bool is_input(const Point<2>& p) const {
    const auto it = list_.find(key(p));
    return it != list_.end() && it->second.input;
  }
  bool is_midpoint(const Point<2>& p) const {
    for (int k = 0; k < 4; ++k) {
      const SideFrame f = frame(k);
      if (p[f.w] == f.c && mids_[k].count(p[f.u])) return true;
    }
    return false;
  }
  void link(sac::Engine& rt, const Point<2>& p, bool input) {
    auto [it, fresh] = list_.emplace(key(p), Entry{std::make_unique<HpuInputNode>(p), input});
    HpuInputNode* n = it->second.node.get();
    if (cells_) cells_->insert(rt, n);
    const auto after = std::next(it);
    rt.set(n->next, after == list_.end() ? nullptr : after->second.node.get());
    rt.set(it == list_.begin() ? head_ : std::prev(it)->second.node->next, n);
  }
  void unlink(sac::Engine& rt, std::map<InsertionKey, Entry>::iterator it) {
    const auto after = std::next(it);
    rt.set(it == list_.begin() ? head_ : std::prev(it)->second.node->next,
          after == list_.end() ? nullptr : after->second.node.get());
    if (cells_) cells_->erase(rt, it->second.node.get());
    gone_.push_back(std::move(it->second.node));
    list_.erase(it);
  }

  Box<2> box_;
  std::map<InsertionKey, Entry> list_;
  std::array<std::set<double>, 4> side_;       // per side: the along coordinates of its vertices
  std::array<std::map<double, int>, 4> mids_;  // per side: midpoint (along coordinate) → paths
  std::vector<std::unique_ptr<HpuInputNode>> gone_;
  sac::Mod<HpuInputNode*> head_;
  InputCells* cells_ = nullptr;
};

}  // namespace dynmesh::detail
