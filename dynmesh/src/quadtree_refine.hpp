// quadtree_refine.hpp (private) — QuadTreeRefine written as static code on sac-runtime.
//
// Purpose: the program that DynamicQuadtree runs once and then keeps up to date by change
// propagation. It is the seed's Figure 2 with its queues made explicit:
//
//   refine(l, C_l):                        C_l: the crowded cells of size class l, FIFO
//     for c in C_l: SPLIT(c)                 (split_crowded)
//     for c in C_l:                          (classify)
//       for each child k of c: if k is crowded, append k to C_{l+1}
//       for each leaf u of class l−1 touching c: append (u, witness c) to G_{l−1}
//     cascade(G_{l−1}); refine(l+1, C_{l+1})
//   cascade(G_m):                          the grading rounds that follow round l
//     for (u, w) in G_m: if u is still a leaf: SPLIT(u); append each class-(m−1) leaf
//       touching u to G_{m−1} with witness u          (grade)
//     cascade(G_{m−1})
//   SPLIT(c): mark c split; partition c's points among its 2^d children  (split, partition)
//
// This is exactly Figure 2's order: after the crowded round of class l the largest non-empty
// bucket is l−1 (ill-graded cells), then l−2, ..., and only then l+1 (Lemma 2.1/2.2: a
// grading split creates no crowded cell and no ill-graded cell below its class). Each work
// entry is a list node keyed by (cell) or (cell, witness), as Section 4 prescribes, and the
// class-l round of one cascade is keyed by (l, m), so re-executions find the same entries.
//
// How it is made stable (DESIGN.md, "Writing it on the runtime so that it is stable"):
//   * cells are named by CellId and found in a directory of slots outside the trace; a slot
//     holds two versioned modifiables, `split` (0 until SPLIT writes 1) and `pts` (the head
//     of the cell's point list), both defaulting to "nothing" (Engine::init), so a test of
//     a cell that does not exist yet reads the default and is re-run if it comes to exist
//     earlier in the trace;
//   * SPLIT's partition is a memoized, order-preserving, destination-passing walk over the
//     cell's point list (one memo_read, one keyed allocation and one write per point), so a
//     new point changes O(1) expected trace per level;
//   * the crowding test of a child k reads only k's first two list cells and, when k holds
//     exactly one point, the list heads of N(k) until it finds a point;
//   * every queue is a modifiable list built by destination passing; each walk step is a
//     memo_read keyed by (list cell, destinations), so after a change the walk re-joins the
//     old trace within O(1) steps.
// Why the tests read what they read (the invariants the program relies on, all consequences
// of Figure 2's order; the differential tests check the output they imply):
//   * when class l's crowded round tests child k, every point of N(k) lies in a child of a
//     cell of N(c) split in this round: a cell of N(c) (or a larger leaf there) holding a
//     point while k holds one would be crowded, hence in C_l (or split earlier);
//   * a class-(l−1) cell touching a class-l leaf exists (its parent is split), because the
//     tree is graded between rounds; so reading its `split` tells leaf from split.
// The level-52 limit is enforced by the mutator before a point enters (two points within
// one grid unit), so the program never splits a level-52 cell.
// Complexity: from scratch O(Σ_points depth + |T*|·3^d) events; per single-point update
// O(lg L/s) expected trace distance.
// Paper: Acar & Hudson, Figure 2, Lemmas 2.1–2.2, Section 4 (keyed appWork, monotonicity).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

#include <sac/engine.hpp>
#include <sac/fn.hpp>

#include "dynmesh/cell.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh::detail {

/// A cell of a point list: the located point and the rest of the list.
template <std::size_t d>
struct PNode {
  explicit PNode(const Position<d>& p) : q(p) {}
  Position<d> q;
  sac::Mod<PNode*> next;
};

/// Key of a point's list cell at one level: the point (its position is unique) and level.
template <std::size_t d>
struct PointAtLevel {
  Position<d> q;
  int level;
  bool operator==(const PointAtLevel&) const = default;
  std::size_t hash() const noexcept {
    std::uint64_t h = sac::mix64(static_cast<std::uint64_t>(level) * 0x9e3779b97f4a7c15ULL);
    for (std::size_t a = 0; a < d; ++a) h = sac::mix64(h ^ q[a]);
    return static_cast<std::size_t>(h);
  }
};

/// The directory entry of a cell: its versioned state. Lives outside the trace; found by
/// CellId, so identities never depend on when or where a run first named the cell.
template <std::size_t d>
struct Slot {
  explicit Slot(const CellId<d>& c) : id(c) {}
  CellId<d> id;
  sac::Mod<std::uint8_t> split;  // 1 once SPLIT ran on the cell
  sac::Mod<PNode<d>*> pts;       // the cell's points (written by its parent's SPLIT)
};

/// A crowded-queue entry (C_l), keyed by its cell.
template <std::size_t d>
struct QNode {
  explicit QNode(const CellId<d>& c) : cell(c) {}
  CellId<d> cell;
  sac::Mod<QNode*> next;
};

/// A grading-queue entry (G_m): a cell that may be ill-graded and the cell whose split
/// witnessed it, the pair being the key (Section 4).
template <std::size_t d>
struct GNode {
  explicit GNode(const CellId<d>& c, const CellId<d>& w) : cell(c), witness(w) {}
  CellId<d> cell;
  CellId<d> witness;
  sac::Mod<GNode*> next;
};

/// What the program needs from its owner: the cell directory and the root's point list.
/// `Dir` provides `Slot<d>& get(sac::Engine&, const CellId<d>&)`, creating a slot with
/// default state on first use.
template <std::size_t d, class Dir>
struct Refine {
  using Node = PNode<d>;
  using List = sac::Mod<Node*>;
  using Crowded = sac::Mod<QNode<d>*>;
  using Grading = sac::Mod<GNode<d>*>;

  Dir* dir;
  List* input;  // the root's list: the input points

  Slot<d>& slot(sac::Engine& r, const CellId<d>& c) { return dir->get(r, c); }
  List& points_of(sac::Engine& r, const CellId<d>& c) {
    return c.level == 0 ? *input : slot(r, c).pts;
  }

  /// Where SPLIT sends each child's points.
  struct Dests {
    std::array<List*, kChildren<d>> to;
    bool operator==(const Dests&) const = default;
    std::size_t hash() const noexcept {
      std::uint64_t h = 0;
      for (List* m : to) h = sac::hash_combine(h, reinterpret_cast<std::uintptr_t>(m));
      return static_cast<std::size_t>(h);
    }
  };
  /// Tails of the two queues a crowded round appends to.
  struct Emit {
    Crowded* crowded;
    Grading* grading;
    bool operator==(const Emit&) const = default;
    std::size_t hash() const noexcept {
      return sac::hash_combine(reinterpret_cast<std::uintptr_t>(crowded),
                               reinterpret_cast<std::uintptr_t>(grading));
    }
  };

  static unsigned child_code(const Position<d>& q, int child_level) {
    unsigned w = 0;
    for (std::size_t a = 0; a < d; ++a)
      w |= static_cast<unsigned>((q[a] >> (kMaxLevel - child_level)) & 1u) << a;
    return w;
  }

  // ------------------------------------------------------------------ the program

  static void main(sac::Engine& r, Refine* cx) {
    // The root is crowded when it holds two points (its neighbourhood is itself).
    Crowded* c0 = r.alloc<Crowded>(0);
    r.read(*cx->input, [cx, c0](sac::Engine& x, Node* a) {
      if (!a) return x.write(*c0, nullptr);
      x.read(a->next, [c0](sac::Engine& y, Node* b) {
        if (!b) return y.write(*c0, nullptr);
        QNode<d>* root = y.alloc<QNode<d>>(CellId<d>::root(), CellId<d>::root());
        y.write(root->next, nullptr);
        y.write(*c0, root);
      });
    });
    r.memo(sac::fn<&refine>(cx, 0, c0));
  }

  /// One crowded round of class l and the grading rounds it causes, then class l+1.
  static void refine(sac::Engine& r, Refine* cx, int l, Crowded* cl) {
    r.read(*cl, [cx, l, cl](sac::Engine& x, QNode<d>* head) {
      if (!head) return;  // no crowded cell left: the tree is done
      Crowded* next = x.alloc<Crowded>(l + 1);
      Grading* ill = x.alloc<Grading>(std::pair<int, int>(l, l - 1));
      x.memo_read(*cl, sac::fn<&split_crowded>(cx));
      x.memo_read(*cl, sac::fn<&classify>(cx, Emit{next, ill}));
      x.memo(sac::fn<&cascade>(cx, l, l - 1, ill));
      x.memo(sac::fn<&refine>(cx, l + 1, next));
    });
  }

  static void split_crowded(sac::Engine& r, QNode<d>* e, Refine* cx) {
    if (!e) return;
    split(r, cx, e->cell);
    r.memo_read(e->next, sac::fn<&split_crowded>(cx));
  }

  /// Figure 2's SPLIT: c becomes split and its points go to its children.
  static void split(sac::Engine& r, Refine* cx, const CellId<d>& c) {
    r.write(cx->slot(r, c).split, std::uint8_t{1});
    Dests to;
    for (unsigned w = 0; w < static_cast<unsigned>(kChildren<d>); ++w)
      to.to[w] = &cx->slot(r, child(c, w)).pts;
    r.memo_read(cx->points_of(r, c), sac::fn<&partition>(cx, c.level + 1, to));
  }

  static void partition(sac::Engine& r, Node* p, Refine* cx, int child_level, Dests to) {
    if (!p) {
      for (List* m : to.to) r.write(*m, nullptr);
      return;
    }
    const unsigned w = child_code(p->q, child_level);
    Node* copy = r.alloc<Node>(PointAtLevel<d>{p->q, child_level}, p->q);
    r.write(*to.to[w], copy);
    to.to[w] = &copy->next;
    r.memo_read(p->next, sac::fn<&partition>(cx, child_level, to));
  }

  /// Step of the walk over C_l after its splits: queue the crowded children of e's cell and
  /// the ill-graded larger leaves around it.
  static void classify(sac::Engine& r, QNode<d>* e, Refine* cx, Emit out) {
    if (!e) {
      r.write(*out.crowded, nullptr);
      r.write(*out.grading, nullptr);
      return;
    }
    classify_child(r, cx, e, 0, out);
  }

  static void classify_child(sac::Engine& r, Refine* cx, QNode<d>* e, unsigned w, Emit out) {
    if (w == static_cast<unsigned>(kChildren<d>)) return emit_ill_graded(r, cx, e, 0, out);
    r.read(cx->slot(r, child(e->cell, w)).pts, [cx, e, w, out](sac::Engine& x, Node* a) {
      if (!a) return classify_child(x, cx, e, w + 1, out);  // empty: not crowded
      x.read(a->next, [cx, e, w, out](sac::Engine& y, Node* b) {
        if (b) return emit_crowded(y, cx, e, w, out);      // two points: self-crowded
        scan_neighbourhood(y, cx, e, w, 0, out);            // one point: look around
      });
    });
  }

  /// k = child w of e's cell holds one point: k is crowded iff a cell of N(k) holds another.
  static void scan_neighbourhood(sac::Engine& r, Refine* cx, QNode<d>* e, unsigned w, int i,
                                 Emit out) {
    const auto around = neighbourhood(child(e->cell, w));  // k itself first
    if (i == 0) i = 1;
    if (i >= around.size()) return classify_child(r, cx, e, w + 1, out);
    r.read(cx->slot(r, around[i]).pts, [cx, e, w, i, out](sac::Engine& x, Node* p) {
      if (p) return emit_crowded(x, cx, e, w, out);
      scan_neighbourhood(x, cx, e, w, i + 1, out);
    });
  }

  static void emit_crowded(sac::Engine& r, Refine* cx, QNode<d>* e, unsigned w, Emit out) {
    QNode<d>* k = r.alloc<QNode<d>>(child(e->cell, w), child(e->cell, w));
    r.write(*out.crowded, k);
    out.crowded = &k->next;
    classify_child(r, cx, e, w + 1, out);
  }

  /// After e's cell c (class l) split, every class-(l−1) leaf touching c is ill-graded.
  static void emit_ill_graded(sac::Engine& r, Refine* cx, QNode<d>* e, int j, Emit out) {
    const CellId<d> c = e->cell;
    if (c.level == 0 || j >= coarser_touching(c).size())
      return r.memo_read(e->next, sac::fn<&classify>(cx, out));
    const CellId<d> u = coarser_touching(c)[j];
    // The closure is kept for re-execution, so it must not change its captures.
    r.read(cx->slot(r, u).split, [cx, e, j, u, c, out](sac::Engine& x, std::uint8_t s) {
      Emit o = out;
      if (!s) {
        GNode<d>* g = x.alloc<GNode<d>>(std::pair<CellId<d>, CellId<d>>(u, c), u, c);
        x.write(*o.grading, g);
        o.grading = &g->next;
      }
      emit_ill_graded(x, cx, e, j + 1, o);
    });
  }

  /// The grading rounds of class m, m−1, ... that follow crowded round j.
  static void cascade(sac::Engine& r, Refine* cx, int j, int m, Grading* gm) {
    r.read(*gm, [cx, j, m, gm](sac::Engine& x, GNode<d>* head) {
      if (!head) return;
      Grading* next = x.alloc<Grading>(std::pair<int, int>(j, m - 1));
      x.memo_read(*gm, sac::fn<&grade>(cx, next));
      x.memo(sac::fn<&cascade>(cx, j, m - 1, next));
    });
  }

  /// Step of the walk over G_m: split the entry's cell unless an earlier entry did, and
  /// queue the larger leaves that this split makes ill-graded.
  static void grade(sac::Engine& r, GNode<d>* g, Refine* cx, Grading* out) {
    if (!g) return r.write(*out, nullptr);
    r.read(cx->slot(r, g->cell).split, [cx, g, out](sac::Engine& x, std::uint8_t s) {
      if (s) return x.memo_read(g->next, sac::fn<&grade>(cx, out));
      split(x, cx, g->cell);
      grade_neighbours(x, cx, g, 0, out);
    });
  }

  static void grade_neighbours(sac::Engine& r, Refine* cx, GNode<d>* g, int j, Grading* out) {
    const CellId<d> c = g->cell;
    if (c.level == 0 || j >= coarser_touching(c).size())
      return r.memo_read(g->next, sac::fn<&grade>(cx, out));
    const CellId<d> u = coarser_touching(c)[j];
    r.read(cx->slot(r, u).split, [cx, g, j, u, c, out](sac::Engine& x, std::uint8_t s) {
      Grading* o = out;
      if (!s) {
        GNode<d>* n = x.alloc<GNode<d>>(std::pair<CellId<d>, CellId<d>>(u, c), u, c);
        x.write(*o, n);
        o = &n->next;
      }
      grade_neighbours(x, cx, g, j + 1, o);
    });
  }
};

}  // namespace dynmesh::detail
