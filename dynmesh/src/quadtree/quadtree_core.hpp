// quadtree_core.hpp (private) — the program layer: the engine, the input point list, the
// cell directory and QuadTreeRefine, composed so that more than one program can share them.
//
// Purpose: DynamicQuadtree runs QuadTreeRefine alone; DynamicMesh's quadtree mesh (and the
// octree mesh) runs it and then a postprocess in the same engine and the same run(), so one
// propagate() carries a point update through the tree into the mesh. Two pieces:
//   InputPoints  – the input list (the root's point list, appended in insertion order), the
//                  point indexes and ids, validation of a batch of edits, and the mutator's
//                  linking and unlinking of points; also used alone by the hpu mesh's state,
//                  which runs no tree (src/mesh/dynamic_mesh.cpp);
//   QuadtreeCore – InputPoints plus the engine, the directory of cell slots
//                  (quadtree_refine.hpp) and the update (link, unlink, propagate, release,
//                  compact). A postprocess is a callable run after Refine::main inside the
//                  same run().
//
// Invariants (check_invariants()): the engine's; the input list, its mirror and the two
// indexes hold the same points; every per-level list node holds its point; the directory's.
// Failure atomicity: validate() runs over a whole batch before anything changes.
// Complexity: validate O(k·3^d) hash probes for k edits; an update O(trace distance) plus
// amortised O(1) compaction per slot.
// Paper: Acar & Hudson, Section 4 (the mutator: insertions and deletions as changes to the
// input, then change propagation).
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include <sac/engine.hpp>
#include <sac/hash.hpp>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/detail/cell_table.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/errors.hpp"
#include "quadtree/cell_index.hpp"
#include "quadtree/quadtree_refine.hpp"

namespace dynmesh::detail {


/// An input point: a list cell the program reads, plus the mutator's bookkeeping.
template <std::size_t d>
struct InputNode : PNode<d> {
  InputNode(const Position<d>& pos, const Point<d>& x, PointId i) : PNode<d>(pos), point(x), id(i) {}
  Point<d> point;
  PointId id;
  InputNode* prev = nullptr;  // list neighbours, mirrored for O(1) unlinking
  InputNode* succ = nullptr;
};

/// A pool of T that never moves its objects; freed objects are reused. T must be trivially
/// destructible, so the deque may drop them without running destructors twice.
template <class T>
class StablePool {
  static_assert(std::is_trivially_destructible_v<T>);

 public:
  template <class... A>
  T* create(A&&... a) {
    if (free_.empty()) return &store_.emplace_back(std::forward<A>(a)...);
    T* p = free_.back();
    free_.pop_back();
    return new (p) T(std::forward<A>(a)...);
  }
  void destroy(T* p) noexcept {
    p->~T();
    free_.push_back(p);
  }
  std::size_t bytes() const noexcept {
    return store_.size() * sizeof(T) + free_.capacity() * sizeof(T*);
  }
  /// Objects created and not destroyed.
  std::size_t live() const noexcept { return store_.size() - free_.size(); }

 private:
  std::deque<T> store_;
  std::vector<T*> free_;
};

/// Cells by name, outside the trace (see quadtree_refine.hpp). A slot is created, with
/// default state, the first time the program names its cell, and released by sweep() once
/// nothing in the trace refers to it.
template <std::size_t d>
class Directory {
 public:
  Slot<d>& get(sac::Engine& rt, const CellId<d>& c) {
    if (Slot<d>* s = table_.find(c)) return *s;
    Slot<d>* s = pool_.create(c);
    table_.insert(s);
    // Defaults, not base versions: a cell's lists end without a write, since the default
    // already says "nothing", and most slots are written before anything reads them.
    rt.init_default(s->split);
    rt.init_default(s->pts);
    if constexpr (d == 3) rt.init_default(s->kids);
    return *s;
  }
  const Slot<d>* find(const CellId<d>& c) const { return table_.find(c); }
  std::size_t size() const noexcept { return table_.size(); }
  std::size_t bytes() const noexcept { return pool_.bytes() + copies_.bytes() + table_bytes(); }
  /// The index's slot array at its capacity (a pointer per slot).
  std::size_t table_bytes() const noexcept { return table_.bytes(); }
  const StablePool<Slot<d>>& slot_pool() const noexcept { return pool_; }
  /// The points' list nodes below level 0 (see below()).
  const StablePool<PNode<d>>& node_pool() const noexcept { return copies_; }

  /// The node of p's point one level below p's, created on first use. Its `next` defaults
  /// to null: the partition does not write a list's end (quadtree_refine.hpp).
  PNode<d>* below(sac::Engine& rt, PNode<d>* p) {
    if (!p->down) {
      p->down = copies_.create(p->q);
      rt.init_default(p->down->next);
    }
    return p->down;
  }
  /// Frees the nodes below p that the trace no longer refers to (the deepest levels a point
  /// has left), or all of them (`all`, for an erased point). Returns false if a node that
  /// had to go is still referred to.
  bool release_below(sac::Engine& rt, PNode<d>* p, bool all) {
    // The levels a point is partitioned at are contiguous from the top, so the unused ones
    // form a suffix of the chain. A list's end is not written, so a listed node's own `next`
    // is used only if something reads it (today the crowding tests and partitions read every
    // list end, but this does not rely on it): a node is kept while the node above it is
    // used, since partitioning the cell above reads that node's `next`.
    PNode<d>* keep = p;
    if (!all)
      for (PNode<d>* c = p->down; c && !rt.unused(keep->next); c = c->down) keep = c;
    PNode<d>* c = keep->down;
    keep->down = nullptr;
    bool ok = true;
    while (c) {
      PNode<d>* nx = c->down;
      // A default that a read once saw has a base version in the engine: retire it.
      if (rt.unused(c->next)) rt.retire(c->next);
      else ok = false;
      copies_.destroy(c);
      c = nx;
    }
    return ok;
  }

  /// Releases every slot the trace no longer refers to. O(size).
  void sweep(sac::Engine& rt) {
    std::vector<Slot<d>*> dead;
    table_.for_each([&](Slot<d>* s) {
      if (rt.unused(s->split) && rt.unused(s->pts) && kids_unused(rt, *s) && !parent_used(rt, s->id()))
        dead.push_back(s);
    });
    for (Slot<d>* s : dead) {
      rt.retire(s->split);
      rt.retire(s->pts);
      if constexpr (d == 3) rt.retire(s->kids);
      table_.erase(s->id());
      pool_.destroy(s);
    }
  }
  template <class F>
  void for_each(F&& f) const {
    table_.for_each([&](const Slot<d>* s) { f(*s); });
  }

  /// Throws InvariantError unless each slot is filed under its own cell and every child of
  /// a split cell has a slot. O(size).
  void check_invariants() const {
    try {
      table_.check_invariants();
    } catch (const InvariantError& e) {
      throw InvariantError(std::string(e.what()) + " (directory slot filed under another cell)");
    }
    table_.for_each([&](const Slot<d>* s) {
      const CellId<d> c = s->id();
      if (!s->split.written() || !s->pts.written() || !kids_written(*s))
        throw InvariantError("dynmesh: directory slot " + to_string(c) + " without its default state");
      if (!tree_split(s->split.get())) return;
      if (c.level >= kMaxLevel) throw InvariantError("dynmesh: a level-52 cell is split");
      for (const CellId<d>& k : children(c)) {
        const Slot<d>* ks = find(k);
        if (!ks)
          throw InvariantError("dynmesh: child " + to_string(k) + " of split cell " + to_string(c) +
                               " has no slot");
      }
    });
  }

 private:
  static bool kids_unused(const sac::Engine& rt, const Slot<d>& s) {
    if constexpr (d == 3) return rt.unused(s.kids);
    else return true;
  }
  static bool kids_written(const Slot<d>& s) {
    if constexpr (d == 3) return s.kids.written();
    else return true;
  }

  /// Whether c's parent may have been split in the trace: then c's slot stays, even unused,
  /// because the parent's partition steps hold a pointer to its `pts` (an empty child's
  /// `pts` is never written, and may never be read).
  bool parent_used(const sac::Engine& rt, const CellId<d>& c) const {
    if (c.level == 0) return false;
    const Slot<d>* p = find(parent(c));
    return p && !rt.unused(p->split);
  }

  CellIndex<d, Slot<d>> table_;
  StablePool<Slot<d>> pool_;
  StablePool<PNode<d>> copies_;
};

template <std::size_t d>
struct PositionHash {
  std::size_t operator()(const Position<d>& q) const noexcept {
    std::uint64_t h = 0x51ed27a5ULL;
    for (std::size_t a = 0; a < d; ++a) h = sac::mix64(h ^ q[a]);
    return static_cast<std::size_t>(h);
  }
};


/// No checks beyond the quadtree's own (DynamicQuadtree). A postprocess's checks see each
/// validated insertion (insert(q, p, fail) may reject it) and deletion, in batch order.
struct NoExtraChecks {
  template <class Q, class P, class Fail>
  void insert(const Q&, const P&, Fail&&) {}
  template <class Q>
  void erase(const Q&) {}
};

/// The edits that insert `points`, in order: how a constructor validates its initial points
/// with the same rules (and messages, "point i") as an update.
template <std::size_t d>
std::vector<Edit<d>> inserts_of(std::span<const Point<d>> points) {
  std::vector<Edit<d>> edits;
  edits.reserve(points.size());
  for (const Point<d>& p : points) edits.push_back(Edit<d>{EditOp::Insert, p});
  return edits;
}

/// The input points: a list of modifiables in insertion order (the root's point list, which
/// a program reads), mirrored for the mutator, with indexes by located position and by id.
/// The engine is its owner's, passed to each call that writes the list; the owner sets
/// `head` to null once its engine exists, and destroys the engine before this.
template <std::size_t d>
class InputPoints {
 public:
  using Node = InputNode<d>;

  explicit InputPoints(const Box<d>& b) : box(b) { validate_box(box); }

  Box<d> box;
  StablePool<Node> inputs;
  Node* first = nullptr;  // the input list, mirrored for the mutator
  Node* tail = nullptr;
  std::unordered_map<Position<d>, Node*, PositionHash<d>> by_pos;
  std::unordered_map<PointId, Node*> by_id;
  PointId next_id = 0;
  sac::Mod<PNode<d>*> head;

  // ------------------------------------------------------------------ validation
  /// Checks a batch of edits against the set as it will be when each applies, changing
  /// nothing. `noun` names an edit in messages ("point 3", "edit 3"); empty for a single
  /// call, whose message names the point instead. The failing edit's index goes into
  /// InputError::point_indices() (both indices for two inserts at one position). `extra`
  /// adds a postprocess's own rules (see NoExtraChecks).
  template <class Extra = NoExtraChecks>
  void validate(std::span<const Edit<d>> edits, const std::string& noun, Extra&& extra = {}) const {
    std::unordered_map<Position<d>, std::size_t, PositionHash<d>> added;  // q -> edit index
    std::unordered_set<Position<d>, PositionHash<d>> removed;
    auto present = [&](const Position<d>& q) {
      return added.contains(q) || (by_pos.contains(q) && !removed.contains(q));
    };
    for (std::size_t i = 0; i < edits.size(); ++i) {
      const Edit<d>& e = edits[i];
      const std::string who = noun.empty() ? std::string{} : noun + " " + std::to_string(i) + ": ";
      auto fail = [&](InputError::Kind kind, const std::string& text) {
        throw InputError(kind, who + text).with_points({i});
      };
      std::optional<Position<d>> located;
      for (std::size_t a = 0; a < d; ++a)
        if (!std::isfinite(e.point[a]))
          fail(InputError::Kind::NotFinite, "point " + to_string<d>(e.point) + " has a NaN or infinite coordinate");
      located = try_locate(box, e.point);
      if (!located) fail(InputError::Kind::OutsideBox, "point " + to_string<d>(e.point) + " is outside the domain box");
      const Position<d> q = *located;
      if (e.op == EditOp::Insert) {
        if (auto a = added.find(q); a != added.end())
          throw InputError(InputError::Kind::Duplicate,
                           (noun.empty() ? std::string("points") : noun + "s") + " " + std::to_string(a->second) +
                               " and " + std::to_string(i) + " have the same located position")
              .with_points({a->second, i});
        if (present(q)) {
          // A different point at the same position is a spread beyond the resolution; say so.
          const auto a = added.find(q);
          const Point<d>& other = a != added.end() ? edits[a->second].point : by_pos.at(q)->point;
          fail(InputError::Kind::Duplicate,
               "point " + to_string<d>(e.point) + " has the same located position as a point in the set" +
                   (other == e.point ? std::string{}
                                     : " " + to_string<d>(other) + ": " + spread_text<d>(box, e.point, other) +
                                           " exceeds the resolution of 2^52"));
        }
        check_resolution(q, present, [&](const Position<d>& near) {
          // Name the near point and the spread the pair gives.
          const auto a = added.find(near);
          const Point<d>& other = a != added.end() ? edits[a->second].point : by_pos.at(near)->point;
          fail(InputError::Kind::Resolution,
               "point " + to_string<d>(e.point) + " lies within one grid unit (L/2^52) of " + to_string<d>(other) +
                   ": " + spread_text<d>(box, e.point, other) + " exceeds the resolution of 2^52");
        });
        extra.insert(q, e.point, [&](const std::string& text) { fail(InputError::Kind::Resolution, text); });
        added.emplace(q, i);
      } else {
        bool ok = false;
        if (auto a = added.find(q); a != added.end()) {
          ok = edits[a->second].point == e.point;
          if (ok) added.erase(a);
        } else if (auto b = by_pos.find(q); b != by_pos.end() && !removed.contains(q)) {
          ok = b->second->point == e.point;
          if (ok) removed.insert(q);
        }
        if (!ok) fail(InputError::Kind::Absent, "point " + to_string<d>(e.point) + " is not in the set");
        extra.erase(q);
      }
    }
  }

  /// A level-52 cell would be crowded: another located point within one grid unit of q per
  /// axis (q's level-52 neighbourhood): spread beyond the resolution. `fail(near)` gets the
  /// located position of that other point.
  template <class Present, class Fail>
  static void check_resolution(const Position<d>& q, Present&& present, Fail&& fail) {
    std::optional<Position<d>> near;
    for_each_neighbour(cell_of(q, kMaxLevel), [&](const CellId<d>& nb) {
      if (!near && present(nb.index)) near = nb.index;
    });
    if (near) fail(*near);
  }

  // ------------------------------------------------------------------ linking
  /// Links (validated) points to build from; ids are the input indices.
  void link_all(sac::Engine& rt, std::span<const Point<d>> points) {
    by_pos.reserve(points.size());
    by_id.reserve(points.size());
    for (const Point<d>& p : points) link_new(rt, *try_locate(box, p), p);
  }
  /// Applies validated edits to the list, in order: returns the ids of the insertions, and
  /// appends the unlinked nodes to `gone` (for release() after the propagation).
  std::vector<PointId> link_edits(sac::Engine& rt, std::span<const Edit<d>> edits, std::vector<Node*>& gone) {
    std::vector<PointId> ids;
    for (const Edit<d>& e : edits) {
      const Position<d> q = *try_locate(box, e.point);
      if (e.op == EditOp::Insert) {
        ids.push_back(link_new(rt, q, e.point)->id);
      } else {
        Node* n = by_pos.at(q);
        unlink(rt, n);
        gone.push_back(n);
      }
    }
    return ids;
  }
  /// After propagate(): frees the unlinked nodes, which no one reads any more.
  /// `release_below(n)` frees what its owner keeps below n (false: still read).
  template <class ReleaseBelow>
  void release(sac::Engine& rt, const std::vector<Node*>& gone, ReleaseBelow&& release_below) {
    for (Node* n : gone) {
      if (!rt.unused(n->next) || !release_below(n))
        throw InvariantError("dynmesh: an erased point is still read by the trace");
      rt.retire(n->next);
      inputs.destroy(n);
    }
  }

  // ------------------------------------------------------------------ reading
  /// The single edit that erases the point with this id (InputError(Absent) if none).
  Edit<d> erase_edit(PointId id) const {
    auto it = by_id.find(id);
    if (it == by_id.end()) throw InputError(InputError::Kind::Absent, "no point with id " + std::to_string(id));
    return Edit<d>{EditOp::Delete, it->second->point};
  }

  std::optional<PointId> find(const Point<d>& p) const noexcept {
    const auto q = try_locate(box, p);
    if (!q) return std::nullopt;
    auto it = by_pos.find(*q);
    if (it == by_pos.end() || it->second->point != p) return std::nullopt;
    return it->second->id;
  }
  const Point<d>& point(PointId id) const {
    auto it = by_id.find(id);
    if (it == by_id.end()) throw InputError(InputError::Kind::Absent, "no point with id " + std::to_string(id));
    return it->second->point;
  }
  std::vector<std::pair<PointId, Point<d>>> points() const {
    std::vector<std::pair<PointId, Point<d>>> out;
    out.reserve(by_id.size());
    for (const Node* n = first; n; n = n->succ) out.emplace_back(n->id, n->point);
    return out;
  }

  /// The list, its mirror and the indexes hold the same points; every per-level list node
  /// below a point holds that point.
  void check_list_invariants() const {
    std::size_t k = 0;
    for (const Node* n = first; n; n = n->succ, ++k) {
      if (n->succ && n->succ->prev != n) throw InvariantError("dynmesh: input list links broken");
      if (n->next.get() != n->succ) throw InvariantError("dynmesh: input list differs from its mirror");
      auto a = by_pos.find(n->q);
      auto b = by_id.find(n->id);
      if (a == by_pos.end() || a->second != n || b == by_id.end() || b->second != n)
        throw InvariantError("dynmesh: point indexes disagree with the input list");
      for (const PNode<d>* c = n->down; c; c = c->down)
        if (c->q != n->q) throw InvariantError("dynmesh: a point's list node holds another point");
    }
    if (head.get() != first) throw InvariantError("dynmesh: list head differs from its mirror");
    if (k != by_pos.size() || k != by_id.size())
      throw InvariantError("dynmesh: point indexes hold points not in the input list");
  }

 private:
  /// Appends a point to the input list. Appending, not prepending, keeps every cell's list
  /// head unchanged unless the cell held fewer than two points, and the crowding tests read
  /// only list heads.
  Node* link_new(sac::Engine& rt, const Position<d>& q, const Point<d>& x) {
    Node* n = inputs.create(q, x, next_id++);
    rt.set(n->next, static_cast<PNode<d>*>(nullptr));
    rt.set(tail ? tail->next : head, static_cast<PNode<d>*>(n));
    n->prev = tail;
    if (tail) tail->succ = n;
    else first = n;
    tail = n;
    by_pos.emplace(q, n);
    by_id.emplace(n->id, n);
    return n;
  }
  void unlink(sac::Engine& rt, Node* n) {
    PNode<d>* after = n->next.get();
    if (n->prev) rt.set(n->prev->next, after);
    else rt.set(head, after);
    if (n->prev) n->prev->succ = n->succ;
    else first = n->succ;
    if (n->succ) n->succ->prev = n->prev;
    else tail = n->prev;
    by_pos.erase(n->q);
    by_id.erase(n->id);
  }
};

/// DynamicQuadtreeOptions::split_below, checked.
inline int checked_split_below(int level) {
  if (level < 0 || level > kMaxSplitBelow)
    throw std::invalid_argument("dynmesh: split_below must be 0 to " + std::to_string(kMaxSplitBelow));
  return level;
}

template <std::size_t d>
class QuadtreeCore : public InputPoints<d> {
  using Base = InputPoints<d>;

 public:
  using Node = InputNode<d>;
  using Program = Refine<d, Directory<d>>;
  using Base::box;
  using Base::by_id;
  using Base::by_pos;
  using Base::first;
  using Base::head;
  using Base::inputs;

  explicit QuadtreeCore(const Box<d>& b) : Base(b) {
    rt.set(head, static_cast<PNode<d>*>(nullptr));
    program.dir = &dir;
    program.input = &head;
  }

  Directory<d> dir;
  UpdateStats last;
  std::size_t compact_mark = 0;
  Program program{};
  // Declared last, destroyed first: its records point into the slots and input nodes.
  sac::Engine rt;

  // ------------------------------------------------------------------ building and updating
  /// Links the (validated) points and runs QuadTreeRefine, then `post(rt)` in the same run.
  /// Ids are the input indices.
  template <class Post>
  void build(std::span<const Point<d>> points, Post&& post) {
    this->link_all(rt, points);
    rt.set_context(&program);
    rt.run([&post](sac::Engine& rt2) {
      Program::main(rt2);
      post(rt2);
    });
    compact_mark = dir.size();
  }

  struct NoHook {
    void operator()(sac::Engine&) const noexcept {}
  };
  /// Applies validated edits and propagates once; returns the ids of the insertions.
  /// `before(engine)` runs after the points are linked, before the propagation: a program
  /// that shares the trace relinks its own inputs there.
  template <class Before = NoHook>
  std::vector<PointId> update(std::span<const Edit<d>> edits, Before&& before = {}) {
    std::vector<Node*> gone;
    std::vector<PointId> ids = this->link_edits(rt, edits, gone);
    before(rt);
    propagate();
    this->release(rt, gone, [this](Node* n) { return dir.release_below(rt, n, true); });
    maybe_compact();
    return ids;
  }

  std::size_t bytes() const {
    return rt.trace_bytes() + rt.input_bytes() + dir.bytes() + inputs.bytes();
  }

  void compact() {
    dir.sweep(rt);
    for (Node* n = first; n; n = n->succ) dir.release_below(rt, n, false);
    compact_mark = dir.size();
  }

  /// The engine, the list and indexes, the point nodes and the directory (not the tree's
  /// shape: see DynamicQuadtree::check_invariants).
  void check_invariants() const {
    rt.check_invariants();
    check_own_invariants();
  }
  /// check_invariants() but the engine's: for SAC_DEBUG_CHECKS after an update, whose
  /// propagate() has just checked the engine.
  void check_own_invariants() const {
    this->check_list_invariants();
    dir.check_invariants();
    check_cell_lists();
  }
  /// Every node on a cell's point list is a live node of one of its points, at the cell's
  /// level and inside the cell: compaction freed nothing that a list still holds. (A list
  /// ends at a null default, so its last node's `next` may be unused while it is listed.)
  /// A cell whose list is an input node (level 0) below the root is a postprocess's own
  /// write (the quadtree mesh's warped leaves), not a partition list.
  void check_cell_lists() const {
    std::unordered_map<const PNode<d>*, int> level_of;
    for (const Node* n = first; n; n = n->succ) {
      int l = 0;
      for (const PNode<d>* c = n->down; c; c = c->down) level_of.emplace(c, ++l);
    }
    dir.for_each([&](const Slot<d>& s) {
      const CellId<d> cell = s.id();
      const PNode<d>* p = s.pts.get();
      if (!p) return;
      if (auto in = by_pos.find(p->q); in != by_pos.end() && static_cast<const PNode<d>*>(in->second) == p) return;
      for (; p; p = p->next.get()) {
        auto it = level_of.find(p);
        if (it == level_of.end())
          throw InvariantError("dynmesh: the point list of " + to_string(cell) + " holds a freed node");
        if (it->second != cell.level || !contains(cell, p->q))
          throw InvariantError("dynmesh: the point list of " + to_string(cell) + " holds another cell's node");
      }
    });
  }

  // ------------------------------------------------------------------ reading the tree
  /// Split in T* (the quadtree), as opposed to split by a postprocess's refinement.
  bool is_split(const CellId<d>& c) const {
    const Slot<d>* s = dir.find(c);
    return s && s->split.written() && tree_split(s->split.get());
  }
  const PNode<d>* points_in(const CellId<d>& c) const {
    if (c.level == 0) return head.get();
    const Slot<d>* s = dir.find(c);
    return s && s->pts.written() ? s->pts.get() : nullptr;
  }
  /// Leaves of the tree whose split cells satisfy `split`, depth first, under `from` (the
  /// whole tree by default; `from` itself when it is not split).
  template <class IsSplit, class F>
  void for_each_leaf_of(IsSplit&& split, F&& f, const CellId<d>& from = CellId<d>::root()) const {
    std::vector<CellId<d>> stack{from};
    while (!stack.empty()) {
      const CellId<d> c = stack.back();
      stack.pop_back();
      if (split(c)) {
        for (unsigned w = kChildren<d>; w-- > 0;) stack.push_back(child(c, w));
      } else {
        f(c);
      }
    }
  }

 private:
  void propagate() {
    const auto t0 = std::chrono::steady_clock::now();
    rt.propagate();
    const auto t1 = std::chrono::steady_clock::now();
    last.seconds = std::chrono::duration<double>(t1 - t0).count();
    last.trace_distance = rt.stats().last_trace_distance;
    last.reexecuted = rt.stats().last_reexecuted;
  }
  void maybe_compact() {
    if (dir.size() > 2 * std::max<std::size_t>(compact_mark, 4096)) compact();
  }
};

}  // namespace dynmesh::detail
