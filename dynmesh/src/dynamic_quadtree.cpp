// dynamic_quadtree.cpp — the mutator side of the self-adjusting quadtree: input list, point
// indexes, the cell directory, validation, and reading the tree out of the slots.
#include "dynmesh/dynamic_quadtree.hpp"

#include "dynmesh/detail/touching_leaves.hpp"

#include <algorithm>
#include <chrono>
#include <deque>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include <sac/engine.hpp>

#include "quadtree_refine.hpp"

namespace dynmesh {
namespace detail {

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
    auto [v, fresh] = table_.try_emplace(c, nullptr);
    if (!fresh) return **v;
    Slot<d>* s = pool_.create(c);
    *v = s;
    rt.init(s->split, std::uint8_t{0});
    rt.init(s->pts, static_cast<PNode<d>*>(nullptr));
    return *s;
  }
  const Slot<d>* find(const CellId<d>& c) const {
    Slot<d>* const* v = table_.find(c);
    return v ? *v : nullptr;
  }
  std::size_t size() const noexcept { return table_.size(); }
  std::size_t bytes() const noexcept {
    return pool_.bytes() + copies_.bytes() + table_.size() * 2 * (8 * d + sizeof(void*));
  }

  /// The node of p's point one level below p's, created on first use.
  PNode<d>* below(PNode<d>* p) {
    if (!p->down) p->down = copies_.create(p->q);
    return p->down;
  }
  /// Frees the nodes below p that the trace no longer refers to (the deepest levels a point
  /// has left), or all of them (`all`, for an erased point). Returns false if a node that
  /// had to go is still referred to.
  bool release_below(sac::Engine& rt, PNode<d>* p, bool all) {
    // The levels a point is partitioned at are contiguous from the top, so the unused ones
    // form a suffix of the chain.
    PNode<d>* keep = p;
    if (!all)
      for (PNode<d>* c = p->down; c && !rt.unused(c->next); c = c->down) keep = c;
    PNode<d>* c = keep->down;
    keep->down = nullptr;
    bool ok = true;
    while (c) {
      PNode<d>* nx = c->down;
      ok = ok && rt.unused(c->next);
      copies_.destroy(c);
      c = nx;
    }
    return ok;
  }

  /// Releases every slot the trace no longer refers to. O(size).
  void sweep(sac::Engine& rt) {
    std::vector<Slot<d>*> dead;
    table_.for_each([&](const CellId<d>&, Slot<d>* s) {
      if (rt.unused(s->split) && rt.unused(s->pts)) dead.push_back(s);
    });
    for (Slot<d>* s : dead) {
      rt.retire(s->split);
      rt.retire(s->pts);
      table_.erase(s->id);
      pool_.destroy(s);
    }
  }
  template <class F>
  void for_each(F&& f) const {
    table_.for_each([&](const CellId<d>&, Slot<d>* s) { f(*s); });
  }

  /// Throws InvariantError unless each slot is filed under its own cell and every child of
  /// a split cell has a slot with a written point list. O(size).
  void check_invariants(const sac::Engine& rt) const {
    table_.for_each([&](const CellId<d>& c, const Slot<d>* s) {
      if (!(s->id == c)) throw InvariantError("dynmesh: directory slot filed under another cell");
      if (!s->split.written() || !s->pts.written())
        throw InvariantError("dynmesh: directory slot " + to_string(c) + " without its default state");
      if (s->split.get() == 0) return;
      if (c.level >= kMaxLevel) throw InvariantError("dynmesh: a level-52 cell is split");
      for (const CellId<d>& k : children(c)) {
        const Slot<d>* ks = find(k);
        if (!ks || rt.unused(ks->pts))
          throw InvariantError("dynmesh: child " + to_string(k) + " of split cell " + to_string(c) +
                               " has no point list");
      }
    });
  }

 private:
  CellTable<d, Slot<d>*> table_;
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

template <std::size_t d>
struct DynamicState {
  using Node = InputNode<d>;
  using Program = Refine<d, Directory<d>>;

  explicit DynamicState(const Box<d>& b) : box(b) {}

  Box<d> box;
  StablePool<Node> inputs;
  Node* first = nullptr;  // the input list, mirrored for the mutator
  Node* tail = nullptr;
  std::unordered_map<Position<d>, Node*, PositionHash<d>> by_pos;
  std::unordered_map<PointId, Node*> by_id;
  PointId next_id = 0;
  Directory<d> dir;
  sac::Mod<PNode<d>*> head;
  UpdateStats last;
  std::size_t compact_mark = 0;
  Program program{};
  // Declared last, destroyed first: its records point into the slots and input nodes.
  sac::Engine rt;

  // ------------------------------------------------------------------ validation
  /// The located points within one grid unit of q per axis (excluding q itself) make a
  /// level-52 cell crowded: spread beyond the resolution.
  template <class Present>
  static void check_resolution(const Position<d>& q, Present&& present) {
    // q's level-52 cell and its neighbourhood: the located positions one unit away.
    bool near = false;
    for_each_neighbour(cell_of(q, kMaxLevel), [&](const CellId<d>& nb) {
      if (!near && present(nb.index)) near = true;
    });
    if (near)
      throw InputError(InputError::Kind::Resolution,
                       "another point lies within one grid unit (L/2^52): spread beyond the "
                       "resolution of 2^52");
  }

  // ------------------------------------------------------------------ list edits
  /// Appends a point to the input list. Appending, not prepending, keeps every cell's list
  /// head unchanged unless the cell held fewer than two points, and the crowding tests read
  /// only list heads.
  Node* link_new(const Position<d>& q, const Point<d>& x) {
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
  void unlink(Node* n) {
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
  /// After propagate(): the unlinked nodes are no longer read by anyone.
  void release(const std::vector<Node*>& gone) {
    for (Node* n : gone) {
      if (!rt.unused(n->next) || !dir.release_below(rt, n, true))
        throw InvariantError("dynmesh: an erased point is still read by the trace");
      rt.retire(n->next);
      inputs.destroy(n);
    }
  }

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
  void compact() {
    dir.sweep(rt);
    for (Node* n = first; n; n = n->succ) dir.release_below(rt, n, false);
    compact_mark = dir.size();
  }

  // ------------------------------------------------------------------ reading the tree
  bool is_split(const CellId<d>& c) const {
    const Slot<d>* s = dir.find(c);
    return s && s->split.written() && s->split.get() != 0;
  }
  const PNode<d>* points_in(const CellId<d>& c) const {
    if (c.level == 0) return head.get();
    const Slot<d>* s = dir.find(c);
    return s && s->pts.written() ? s->pts.get() : nullptr;
  }
  template <class F>
  void for_each_leaf(F&& f) const {
    std::vector<CellId<d>> stack{CellId<d>::root()};
    while (!stack.empty()) {
      const CellId<d> c = stack.back();
      stack.pop_back();
      if (is_split(c)) {
        for (unsigned w = kChildren<d>; w-- > 0;) stack.push_back(child(c, w));
      } else {
        f(c, points_in(c));
      }
    }
  }
  bool is_leaf(const CellId<d>& c) const {
    return valid(c) && (c.level == 0 || is_split(parent(c))) && !is_split(c);
  }
  CellId<d> leaf_at(const Position<d>& q) const {
    CellId<d> c = CellId<d>::root();
    while (is_split(c)) c = cell_of(q, c.level + 1);
    return c;
  }
};

}  // namespace detail


template <std::size_t d>
  requires SupportedDim<d>
DynamicQuadtree<d>::DynamicQuadtree(const Box<d>& box, std::span<const Point<d>> points)
    : s_(std::make_unique<detail::DynamicState<d>>(box)) {
  validate_box(box);
  auto& s = *s_;
  // Validate everything before building anything.
  std::vector<Position<d>> qs(points.size());
  std::unordered_map<Position<d>, std::size_t, detail::PositionHash<d>> seen;
  seen.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t a = 0; a < d; ++a)
      if (!std::isfinite(points[i][a]))
        throw InputError(InputError::Kind::NotFinite,
                         "point " + std::to_string(i) + " has a NaN or infinite coordinate")
            .with_points({i});
    auto q = try_locate(box, points[i]);
    if (!q)
      throw InputError(InputError::Kind::OutsideBox,
                       "point " + std::to_string(i) + " is outside the domain box")
          .with_points({i});
    qs[i] = *q;
    auto [it, fresh] = seen.emplace(*q, i);
    if (!fresh)
      throw InputError(InputError::Kind::Duplicate,
                       "points " + std::to_string(it->second) + " and " + std::to_string(i) +
                           " have the same located position")
          .with_points({it->second, i});
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    try {
      detail::DynamicState<d>::check_resolution(qs[i], [&](const Position<d>& r) { return seen.contains(r); });
    } catch (InputError& e) {
      throw InputError(e.kind(), "point " + std::to_string(i) + ": " + e.text()).with_points({i});
    }
  }
  // The list holds the points in input order; ids are the input indices.
  s.by_pos.reserve(points.size());
  s.by_id.reserve(points.size());
  s.rt.set(s.head, static_cast<detail::PNode<d>*>(nullptr));
  for (std::size_t i = 0; i < points.size(); ++i) s.link_new(qs[i], points[i]);
  s.program.dir = &s.dir;
  s.program.input = &s.head;
  auto* program = &s.program;
  s.rt.run([program](sac::Engine& rt) { detail::DynamicState<d>::Program::main(rt, program); });
  s.compact_mark = s.dir.size();
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
  auto& s = *s_;
  const Position<d> q = dynmesh::locate(s.box, p);
  if (auto it = s.by_pos.find(q); it != s.by_pos.end())
    throw InputError(InputError::Kind::Duplicate,
                     "point " + to_string<d>(p) + " has the same located position as point " +
                         std::to_string(it->second->id));
  s.check_resolution(q, [&](const Position<d>& r) { return s.by_pos.contains(r); });
  auto* n = s.link_new(q, p);
  s.propagate();
  s.maybe_compact();
  return n->id;
}

template <std::size_t d>
  requires SupportedDim<d>
void DynamicQuadtree<d>::erase(PointId id) {
  auto& s = *s_;
  auto it = s.by_id.find(id);
  if (it == s.by_id.end())
    throw InputError(InputError::Kind::Absent, "no point with id " + std::to_string(id));
  auto* n = it->second;
  s.unlink(n);
  s.propagate();
  s.release({n});
  s.maybe_compact();
}

template <std::size_t d>
  requires SupportedDim<d>
void DynamicQuadtree<d>::erase(const Point<d>& p) {
  const auto id = find(p);
  if (!id) throw InputError(InputError::Kind::Absent, "point " + to_string<d>(p) + " is not in the set");
  erase(*id);
}

template <std::size_t d>
  requires SupportedDim<d>
std::vector<PointId> DynamicQuadtree<d>::apply(std::span<const Edit<d>> edits) {
  auto& s = *s_;
  using Node = detail::InputNode<d>;
  // Validate the whole batch against the set as it will be when each edit applies.
  std::unordered_map<Position<d>, const Point<d>*, detail::PositionHash<d>> added;
  std::unordered_set<Position<d>, detail::PositionHash<d>> removed;
  auto present = [&](const Position<d>& q) {
    return added.contains(q) || (s.by_pos.contains(q) && !removed.contains(q));
  };
  for (std::size_t i = 0; i < edits.size(); ++i) {
    const Edit<d>& e = edits[i];
    try {
      const Position<d> q = dynmesh::locate(s.box, e.point);
      if (e.op == EditOp::Insert) {
        if (present(q))
          throw InputError(InputError::Kind::Duplicate,  // as insert() reports it
                           "point " + to_string<d>(e.point) + " is already in the set (same located position)");
        s.check_resolution(q, present);
        added.emplace(q, &e.point);
      } else {
        bool ok = false;
        if (auto a = added.find(q); a != added.end()) {
          ok = *a->second == e.point;
          if (ok) added.erase(a);
        } else if (auto b = s.by_pos.find(q); b != s.by_pos.end() && !removed.contains(q)) {
          ok = b->second->point == e.point;
          if (ok) removed.insert(q);
        }
        if (!ok)
          throw InputError(InputError::Kind::Absent,
                           "point " + to_string<d>(e.point) + " is not in the set");
      }
    } catch (const InputError& err) {
      // The script line when the edit has one (InputError::line()), else the edit's index.
      if (e.line != 0) throw InputError(err.kind(), err.text(), std::string{}, e.line);
      throw InputError(err.kind(), "edit " + std::to_string(i) + ": " + err.text());
    }
  }
  // Apply: nothing below can fail on valid input.
  std::vector<PointId> ids;
  std::vector<Node*> gone;
  for (const Edit<d>& e : edits) {
    const Position<d> q = *try_locate(s.box, e.point);
    if (e.op == EditOp::Insert) {
      ids.push_back(s.link_new(q, e.point)->id);
    } else {
      Node* n = s.by_pos.at(q);
      s.unlink(n);
      // Re-inserted within the batch? Then the node is dead but a new one took its place.
      gone.push_back(n);
    }
  }
  s.propagate();
  s.release(gone);
  s.maybe_compact();
  return ids;
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
std::optional<PointId> DynamicQuadtree<d>::find(const Point<d>& p) const noexcept {
  const auto q = try_locate(s_->box, p);
  if (!q) return std::nullopt;
  auto it = s_->by_pos.find(*q);
  if (it == s_->by_pos.end() || it->second->point != p) return std::nullopt;
  return it->second->id;
}

template <std::size_t d>
  requires SupportedDim<d>
const Point<d>& DynamicQuadtree<d>::point(PointId id) const {
  auto it = s_->by_id.find(id);
  if (it == s_->by_id.end())
    throw InputError(InputError::Kind::Absent, "no point with id " + std::to_string(id));
  return it->second->point;
}

template <std::size_t d>
  requires SupportedDim<d>
std::vector<std::pair<PointId, Point<d>>> DynamicQuadtree<d>::points() const {
  std::vector<std::pair<PointId, Point<d>>> out;
  out.reserve(size());
  for (auto* n = s_->first; n; n = n->succ) out.emplace_back(n->id, n->point);
  return out;
}

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
  std::vector<Leaf<d>> out;
  s_->for_each_leaf([&](const CellId<d>& c, const detail::PNode<d>* p) {
    std::uint32_t k = 0;
    for (; p; p = p->next.get()) ++k;
    out.push_back(Leaf<d>{c, k});
  });
  std::sort(out.begin(), out.end());
  return out;
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
      leaf, [&](const CellId<d>& x) { return s.is_split(x); }, [](const CellId<d>&) { return true; },
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
    if (slot.split.written() && slot.split.get() != 0) ++k;
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
std::size_t DynamicQuadtree<d>::trace_bytes() const {
  return s_->rt.trace_bytes() + s_->rt.input_bytes() + s_->dir.bytes() + s_->inputs.bytes();
}

template <std::size_t d>
  requires SupportedDim<d>
std::size_t DynamicQuadtree<d>::record_bytes() const { return s_->rt.record_bytes(); }

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
  const auto& s = *s_;
  s.rt.check_invariants();
  // The indexes and the list agree.
  std::size_t k = 0;
  for (auto* n = s.first; n; n = n->succ, ++k) {
    if (n->succ && n->succ->prev != n) throw InvariantError("dynmesh: input list links broken");
    if (n->next.get() != n->succ) throw InvariantError("dynmesh: input list differs from its mirror");
    auto a = s.by_pos.find(n->q);
    auto b = s.by_id.find(n->id);
    if (a == s.by_pos.end() || a->second != n || b == s.by_id.end() || b->second != n)
      throw InvariantError("dynmesh: point indexes disagree with the input list");
  }
  if (s.head.get() != s.first) throw InvariantError("dynmesh: list head differs from its mirror");
  for (auto* n = s.first; n; n = n->succ)
    for (const detail::PNode<d>* c = n->down; c; c = c->down)
      if (c->q != n->q) throw InvariantError("dynmesh: a point's list node holds another point");
  s.dir.check_invariants(s.rt);
  if (k != s.by_pos.size() || k != s.by_id.size())
    throw InvariantError("dynmesh: point indexes hold points not in the input list");
  // Every leaf's list holds exactly the points located in it.
  s.for_each_leaf([&](const CellId<d>& c, const detail::PNode<d>* p) {
    for (; p; p = p->next.get())
      if (!dynmesh::contains(c, p->q) || !s.by_pos.contains(p->q))
        throw InvariantError("dynmesh: leaf " + to_string(c) + " lists a point it does not hold");
  });
  const auto pts = positions();
  const auto ls = leaves();
  require_valid_tree<d>(pts, ls);
}

template class DynamicQuadtree<2>;
template class DynamicQuadtree<3>;

}  // namespace dynmesh
