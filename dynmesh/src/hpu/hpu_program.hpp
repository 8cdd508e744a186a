// hpu_program.hpp (private) — DynHPU's off-center refinement as a self-adjusting program on
// sac-runtime, on top of the self-adjusting Delaunay triangulation (sa_delaunay.hpp).
//
// Purpose: after run() and after every propagate(), the live triangles equal those of the
// static twin HpuMesh (hpu_mesh.cpp, class Refiner) on the current input points, box and
// angle, bit for bit. It makes the twin's decisions in the twin's order (hpu_mesh.hpp's
// rules 1-6), on the same shared geometry (hpu_geometry.hpp):
//   1. insert the input list (the inputs and their side midpoints in insertion_less order:
//      BRIO rounds, Morton within a round; the mutator keeps it, hpu_inputs.hpp) in list
//      order, each from the previous point's triangle, and build the list of initial
//      vertices: the box's corners in (Morton, xy) order, then the list — the twin's
//      initial order;
//   2. the class of each initial vertex (its shortest edge's), after all insertions;
//   3. per class j, smallest first: Q_j = (initial entries of class j, in initial order)
//      ++ (continuations made during class j − 1); rounds: collect every entry of the
//      round (its loose pairs, into the entry's own list, and its continuation into
//      Q_{j+1}), then process the pairs in collection order (entry by entry); births
//      (off-centers and side midpoints) form the next round.
// Lists by destination passing (quadtree_refine.hpp's pattern): every list cell is a keyed
// allocation (an entry by (vertex, class, birth), a pair by (its collector's entry, p, q),
// a class by j, a round by the modifiable holding its first entry), so a re-executed step
// that appends the same cell hands the same destination on and the next memoized step
// re-joins the old trace. The initial vertices' list is filtered once per class: its cells
// keep what is left for later classes by writing new versions of their own `next`.
// Phases that follow a list pass are issued after it as siblings (not from the last cell's
// body), so a change at a list's end does not re-run everything after it; what a later
// phase needs from an earlier one travels in modifiables (a round's continuation tail, the
// smallest initial class).
// Memo keys never reach across insertions (sa_delaunay.hpp's warning): each holds the
// cell, class or round it belongs to, so it can only match its own old call; a list step's
// key also holds its predecessor's predecessor, and the fan's the births' tail, so that an
// entry, a pair or an off-center that an update moved earlier cannot match its old call
// far ahead and discard everything in between (docs/EXPERIMENTS.md, "What made the trace
// distance flat"). No destination is threaded through a sparse list: an entry owns its
// pairs, so a change in one entry's pairs leaves the keys of the pairless entries after it.
// Process, the twin's loop for one pair p→q: read p's star (its triangles too); p→q must be
// an edge with a triangle t = (p, q, tv) on its left and still loose; r = the off-center;
// r outside the box → split the box edge holding the first crossing X of m→r with the
// side (found by a walk to X: the edge holding X, or, when X is a vertex, the edge after
// it along the side — the twin's std::map::upper_bound rule, clamped at the side's end);
// otherwise walk to r and collect its cavity (SaDelaunay::insert_with); box edges of the
// cavity that r encroaches → split them in pair_less order; else commit the fan. After a
// split the pair is tried again.
//
// Invariants: those of SaDelaunay (SaTriRegistry::check_invariants) after run/propagate;
// every list is terminated (null) by its pass before any later phase reads it; a vertex
// has at most one entry per class (initial at its class, continuations above it, a birth
// at the class of its creation), so the entry keys are unique in a run.
// Complexity: the twin's work (O(n lg n + m) expected) plus one pass over the initial
// vertices per size class (the filter; O(n · classes)). An update re-runs the insertions it
// touches and the refinement steps whose stars or walks they change, plus list steps up to
// the next cell appended as before (tests/dynmesh/hpu_program_test.cpp prints the figures).
// Paper: Acar & Hudson, Figure 5 and Appendix A (DynHPU); Har-Peled & Üngör (2005); Üngör,
// "Off-centers" (2004); Acar, Ahmed & Blume (POPL'08) for memoized reads, keyed allocation
// and destination passing.
#pragma once

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include <sac/engine.hpp>
#include <sac/fn.hpp>
#include <sac/hash.hpp>
#include <sac/mod.hpp>

#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/predicates.hpp"
#include "hpu/hpu_geometry.hpp"
#include "hpu/sa_delaunay.hpp"

namespace dynmesh::detail {

struct HpuPair;

/// A queue entry (the twin's Entry), keyed by (vertex, class, birth).
struct HpuEntry {
  HpuEntry(SaVertex* x, bool b) : v(x), birth(b) {}
  HpuEntry(const HpuEntry&) = delete;
  HpuEntry& operator=(const HpuEntry&) = delete;
  SaVertex* v;
  bool birth;
  sac::Mod<HpuEntry*> next;
  sac::Mod<HpuPair*> pairs;  // the loose pairs its collect found, in order
};

/// A collected pair p→q, keyed by (its collector's entry, p, q).
struct HpuPair {
  HpuPair(SaVertex* a, SaVertex* b) : p(a), q(b) {}
  HpuPair(const HpuPair&) = delete;
  HpuPair& operator=(const HpuPair&) = delete;
  SaVertex* p;
  SaVertex* q;
  sac::Mod<HpuPair*> next;
};

/// An initial vertex, keyed by it: its class, and the rest of the list (each class's filter
/// writes a new version: the vertices left for later classes).
struct HpuCell {
  explicit HpuCell(SaVertex* x) : v(x) {}
  HpuCell(const HpuCell&) = delete;
  HpuCell& operator=(const HpuCell&) = delete;
  SaVertex* v;
  sac::Mod<int> cls;
  sac::Mod<HpuCell*> next;
};

/// A size class, keyed by j.
struct HpuClass {
  explicit HpuClass(int c) : j(c) {}
  HpuClass(const HpuClass&) = delete;
  HpuClass& operator=(const HpuClass&) = delete;
  int j;
  sac::Mod<HpuEntry*> init;  // Q_j: the initial entries of class j, then `cont`
  sac::Mod<HpuEntry*> cont;  // the continuations made during class j − 1
  sac::Mod<HpuCell*> rest;   // the initial vertices of classes above j
};

/// A round, keyed by the modifiable holding its first entry.
struct HpuRound {
  HpuRound() = default;
  HpuRound(const HpuRound&) = delete;
  HpuRound& operator=(const HpuRound&) = delete;
  sac::Mod<HpuEntry*> births;                 // the next round
  sac::Mod<sac::Mod<HpuEntry*>*> cont_tail;   // Q_{j+1}'s tail after this round's collect
};

/// The run's fixed state (allocated once by main, which never re-runs).
struct HpuStart {
  HpuStart() = default;
  HpuStart(const HpuStart&) = delete;
  HpuStart& operator=(const HpuStart&) = delete;
  sac::Mod<HpuCell*> cells;  // the initial vertices, in order
  sac::Mod<int> min_class;   // the smallest initial class
};

/// The program. Preconditions (the mutator's): the list's points are distinct, in the box,
/// none a box corner (an input at a corner is the box's vertex already: leave it out).
/// Run with e.run([&](sac::Engine& r) { HpuProgram::main(r, &program); }); the mutator keeps `input` equal to the inputs and their side midpoints in
/// insertion_less order (HpuInputs, relinking with Engine::set) and calls propagate().
struct HpuProgram {
  SaDelaunay* dt;
  sac::Mod<SaInputNode*>* input;
  double leaf;  // leaf_height(θ)
  double apex;  // apex_height(θ)
  HpuStart* start = nullptr;

  HpuProgram(SaDelaunay* d, sac::Mod<SaInputNode*>* in, double min_angle_deg)
      : dt(d), input(in), leaf(leaf_height(min_angle_deg)), apex(apex_height(min_angle_deg)) {}

  const Box<2>& box() const noexcept { return dt->box; }

  // ---------------------------------------------------------------- 1. insertion

  static void main(sac::Engine& e, HpuProgram* pg) {
    const std::array<SaVertex*, 4> c = SaDelaunay::init_box(e, pg->dt);
    pg->start = e.alloc<HpuStart>(0);
    std::array<SaVertex*, 4> order = c;
    std::sort(order.begin(), order.end(),
              [pg](const SaVertex* a, const SaVertex* b) { return morton_less(pg->box(), a->p, b->p); });
    // The initial vertices: the corners in (Morton, xy) order, then the list's.
    sac::Mod<HpuCell*>* dest = &pg->start->cells;
    for (SaVertex* v : order) dest = append_cell(e, v, dest);
    e.memo_read(*pg->input, sac::fn<&place>(pg, c[0], dest));
    e.memo_read(pg->start->cells, sac::fn<&class_step>(pg, INT_MAX));
    e.memo(sac::fn<&refine_start>(pg));
  }

  static sac::Mod<HpuCell*>* append_cell(sac::Engine& e, SaVertex* v, sac::Mod<HpuCell*>* dest) {
    HpuCell* c = e.alloc<HpuCell>(v, v);
    e.write(*dest, c);
    return &c->next;
  }

  /// Inserts n's point from prev's triangle and appends it to the initial vertices;
  /// memoized on (n.next, x, …) as SaDelaunayProgram::place.
  static void place(sac::Engine& e, SaInputNode* n, HpuProgram* pg, SaVertex* prev, sac::Mod<HpuCell*>* dest) {
    if (!n) return e.write(*dest, nullptr);
    SaVertex* x = SaDelaunay::vertex(e, n->point);
    SaDelaunay::insert_near(e, pg->dt, x, prev);
    dest = append_cell(e, x, dest);
    e.memo_read(n->next, sac::fn<&place>(pg, x, dest));
  }

  // ---------------------------------------------------------------- 2. initial classes

  struct ClassK {
    HpuProgram* pg;
    HpuCell* cell;
    int mn;
    void operator()(sac::Engine& e, std::span<SaVertex* const> ring, std::span<SaTri* const>, bool) const {
      int c = INT_MAX;
      for (const SaVertex* q : ring) c = std::min(c, edge_class(cell->v->p, q->p));
      e.write(cell->cls, c);
      e.memo_read(cell->next, sac::fn<&class_step>(pg, std::min(mn, c)));
    }
  };

  static void class_step(sac::Engine& e, HpuCell* cell, HpuProgram* pg, int mn) {
    if (!cell) return e.write(pg->start->min_class, mn);
    SaDelaunay::read_star(e, cell->v, ClassK{pg, cell, mn});
  }

  // ---------------------------------------------------------------- 3. classes and rounds

  static void refine_start(sac::Engine& e, HpuProgram* pg) {
    e.read(pg->start->min_class, [pg](sac::Engine& e2, int j) {
      HpuClass* cs = e2.alloc<HpuClass>(j, j);
      e2.write(cs->cont, nullptr);  // nothing continues into the first class
      e2.memo(sac::fn<&class_start>(pg, cs, &pg->start->cells));
    });
  }

  /// Class j: filter its initial entries out of `src`, then its rounds.
  static void class_start(sac::Engine& e, HpuProgram* pg, HpuClass* cs, sac::Mod<HpuCell*>* src) {
    HpuClass* csn = e.alloc<HpuClass>(cs->j + 1, cs->j + 1);
    e.memo_read(*src, sac::fn<&filter_step>(pg, cs, &cs->init, &cs->rest));
    e.memo(sac::fn<&round>(pg, cs, csn, &cs->init, &csn->cont));
  }

  static void filter_step(sac::Engine& e, HpuCell* cell, HpuProgram* pg, HpuClass* cs, sac::Mod<HpuEntry*>* qdest,
                          sac::Mod<HpuCell*>* rdest) {
    if (!cell) {
      e.write(*rdest, nullptr);
      // Q_j = its initial entries ++ the continuations of class j − 1 (terminated by now).
      e.read(cs->cont, [qdest](sac::Engine& e2, HpuEntry* h) { e2.write(*qdest, h); });
      return;
    }
    e.read(cell->cls, [cell, pg, cs, qdest, rdest](sac::Engine& e2, int c) {
      sac::Mod<HpuEntry*>* q = qdest;
      sac::Mod<HpuCell*>* r = rdest;
      if (c == cs->j) {
        HpuEntry* ent = e2.alloc<HpuEntry>(std::tuple{cell->v, cs->j, true}, cell->v, true);
        e2.write(*q, ent);
        q = &ent->next;
      } else {
        e2.write(*r, cell);
        r = &cell->next;
      }
      e2.memo_read(cell->next, sac::fn<&filter_step>(pg, cs, q, r));
    });
  }

  /// A round of class j on the entries from `head`: collect all, then process the pairs,
  /// then the next round (the births) or the next class.
  static void round(sac::Engine& e, HpuProgram* pg, HpuClass* cs, HpuClass* csn, sac::Mod<HpuEntry*>* head,
                    sac::Mod<HpuEntry*>* cdest) {
    HpuRound* rs = e.alloc<HpuRound>(head);
    e.memo_read(*head, sac::fn<&collect_step>(pg, cs, rs, cdest, nullptr, nullptr));
    e.memo_read(*head, sac::fn<&process_entry>(pg, cs, rs, &rs->births, nullptr, nullptr));
    e.memo(sac::fn<&round_end>(pg, cs, csn, rs));
  }

  static void round_end(sac::Engine& e, HpuProgram* pg, HpuClass* cs, HpuClass* csn, HpuRound* rs) {
    e.read(rs->births, [pg, cs, csn, rs](sac::Engine& e2, HpuEntry* b) {
      e2.read(rs->cont_tail, [pg, cs, csn, rs, b](sac::Engine& e3, sac::Mod<HpuEntry*>* tail) {
        if (b) return e3.memo(sac::fn<&round>(pg, cs, csn, &rs->births, tail));
        e3.write(*tail, nullptr);
        e3.memo(sac::fn<&class_end>(pg, cs, csn));
      });
    });
  }

  /// The next class when anything is left: continuations, or initial vertices above j.
  static void class_end(sac::Engine& e, HpuProgram* pg, HpuClass* cs, HpuClass* csn) {
    e.read(csn->cont, [pg, cs, csn](sac::Engine& e2, HpuEntry* c) {
      e2.read(cs->rest, [pg, cs, csn, c](sac::Engine& e3, HpuCell* r) {
        if (c || r) e3.memo(sac::fn<&class_start>(pg, csn, &cs->rest));
      });
    });
  }

  // ---------------------------------------------------------------- collect

  /// The twin's collect(v, j, birth) on v's star: loose pairs (both sides, of class j, ≤ j
  /// at a birth) in (x, y) order, and v's continuation into Q_{j+1}.
  struct CollectK {
    HpuProgram* pg;
    HpuClass* cs;
    HpuRound* rs;
    HpuEntry* ent;
    HpuEntry* before;  // the entry before ent (null: ent is first)
    sac::Mod<HpuEntry*>* cdest;
    void operator()(sac::Engine& e, std::span<SaVertex* const> star, std::span<SaTri* const>,
                    bool cycle) const {
      SaVertex* v = ent->v;
      const int j = cs->j;
      const std::size_t d = star.size();
      bool go_on = false;
      std::vector<std::pair<SaVertex*, SaVertex*>> local;
      for (std::size_t i = 0; i < d; ++i) {
        SaVertex* q = star[i];
        const int c = edge_class(v->p, q->p);
        if (i + 1 < d || cycle) go_on = go_on || circumradius_above(v->p, q->p, star[(i + 1) % d]->p, j);
        if (c > j) go_on = true;
        if (ent->birth ? c > j : c != j) continue;
        const SaVertex* left = i + 1 < d ? star[i + 1] : cycle ? star[0] : nullptr;
        const SaVertex* right = i > 0 ? star[i - 1] : cycle ? star[d - 1] : nullptr;
        const Point<2>* lp = left ? &left->p : nullptr;
        const Point<2>* rp = right ? &right->p : nullptr;
        if (loose(v->p, q->p, pg->leaf, lp, rp)) local.emplace_back(v, q);
        if (loose(q->p, v->p, pg->leaf, rp, lp)) local.emplace_back(q, v);
      }
      std::sort(local.begin(), local.end(), [](const auto& a, const auto& b) {
        if (a.first->p != b.first->p) return xy_less(a.first->p, b.first->p);
        return xy_less(a.second->p, b.second->p);
      });
      // The entry's own list: no tail threads through the round, so a change in one
      // entry's pairs does not change the keys of the (mostly pairless) entries after it.
      sac::Mod<HpuPair*>* pd = &ent->pairs;
      for (const auto& [p, q] : local) {
        HpuPair* pc = e.alloc<HpuPair>(std::tuple{ent, p, q}, p, q);
        e.write(*pd, pc);
        pd = &pc->next;
      }
      e.write(*pd, nullptr);
      sac::Mod<HpuEntry*>* cd = cdest;
      if (go_on) {
        HpuEntry* c = e.alloc<HpuEntry>(std::tuple{v, j + 1, false}, v, false);
        e.write(*cd, c);
        cd = &c->next;
      }
      e.memo_read(ent->next, sac::fn<&collect_step>(pg, cs, rs, cd, ent, before));
    }
  };

  /// ent was read from owner's `next` (owner null: the round's head). owner's predecessor
  /// is in the key: when an update moves an entry earlier in the list, its own `next` and
  /// the destinations can be those of its old step far ahead, which would then match and
  /// discard everything in between (measured: 144k events for a deletion at n = 50,000);
  /// with the predecessor it runs anew in place. process_step does the same.
  static void collect_step(sac::Engine& e, HpuEntry* ent, HpuProgram* pg, HpuClass* cs, HpuRound* rs,
                           sac::Mod<HpuEntry*>* cdest, HpuEntry* owner, HpuEntry* owner_pred) {
    (void)owner_pred;
    if (!ent) return e.write(rs->cont_tail, cdest);
    SaDelaunay::read_star(e, ent->v, CollectK{pg, cs, rs, ent, owner, cdest});
  }

  // ---------------------------------------------------------------- process

  /// Where a pair's processing stands: the pair and the births' tail.
  struct Ctx {
    HpuProgram* pg;
    HpuClass* cs;
    HpuRound* rs;
    HpuPair* pc;
    sac::Mod<HpuEntry*>* bdest;
    HpuPair* prev;        // the pair before pc in its entry's list (null: pc is first)
    HpuEntry* ent;        // pc's entry
    HpuEntry* ent_prev;   // the entry before it (null: ent is first)
    friend bool operator==(const Ctx&, const Ctx&) = default;
    std::size_t hash() const noexcept {
      std::uint64_t h = sac::Hash<HpuPair*>{}(pc);
      h = sac::hash_combine(h, sac::Hash<sac::Mod<HpuEntry*>*>{}(bdest));
      h = sac::hash_combine(h, sac::Hash<HpuRound*>{}(rs));
      return static_cast<std::size_t>(h);
    }
  };

  /// The process pass walks the round's entries and each entry's pairs. nent was read from
  /// owner's `next` (owner null: the round's head); owner's predecessor is in the key, as
  /// in collect_step.
  static void process_entry(sac::Engine& e, HpuEntry* nent, HpuProgram* pg, HpuClass* cs, HpuRound* rs,
                            sac::Mod<HpuEntry*>* bdest, HpuEntry* owner, HpuEntry* owner_pred) {
    (void)owner_pred;
    if (!nent) return e.write(*bdest, nullptr);
    e.memo_read(nent->pairs, sac::fn<&process_step>(pg, cs, rs, bdest, nent, owner, nullptr, nullptr));
  }

  /// pc was read from owner's `next` (owner null: ent's list head); owner's predecessor is
  /// in the key, as in collect_step.
  static void process_step(sac::Engine& e, HpuPair* pc, HpuProgram* pg, HpuClass* cs, HpuRound* rs,
                           sac::Mod<HpuEntry*>* bdest, HpuEntry* ent, HpuEntry* ent_prev, HpuPair* owner,
                           HpuPair* owner_pred) {
    (void)owner_pred;
    if (!pc) return e.memo_read(ent->next, sac::fn<&process_entry>(pg, cs, rs, bdest, ent, ent_prev));
    try_pair(e, Ctx{pg, cs, rs, pc, bdest, owner, ent, ent_prev});
  }

  /// The pair is done: the next one.
  static void done(sac::Engine& e, const Ctx& c) {
    e.memo_read(c.pc->next, sac::fn<&process_step>(c.pg, c.cs, c.rs, c.bdest, c.ent, c.ent_prev, c.pc, c.prev));
  }

  /// x was inserted: its birth entry joins the next round.
  static Ctx birth(sac::Engine& e, Ctx c, SaVertex* x) {
    HpuEntry* ent = e.alloc<HpuEntry>(std::tuple{x, c.cs->j, true}, x, true);
    e.write(*c.bdest, ent);
    c.bdest = &ent->next;
    return c;
  }

  /// One try of the twin's process(p, q, j) loop.
  static void try_pair(sac::Engine& e, const Ctx& c) { SaDelaunay::read_star(e, c.pc->p, TryK{c}); }

  struct TryK {
    Ctx c;
    void operator()(sac::Engine& e, std::span<SaVertex* const> ring, std::span<SaTri* const> tris,
                    bool cycle) const {
      HpuProgram* pg = c.pg;
      SaVertex* p = c.pc->p;
      SaVertex* q = c.pc->q;
      const std::size_t d = ring.size();
      std::size_t i = 0;
      while (i < d && ring[i] != q) ++i;
      if (i == d || (i + 1 == d && !cycle)) return done(e, c);  // not an edge, or the box on its left
      const SaVertex* tv = ring[(i + 1) % d];
      const SaVertex* uv = i > 0 ? ring[i - 1] : cycle ? ring[d - 1] : nullptr;
      if (!loose(p->p, q->p, pg->leaf, &tv->p, uv ? &uv->p : nullptr)) return done(e, c);
      SaTri* t = tris[i];
      const Point<2> r = off_center(p->p, q->p, tv->p, pg->apex).at;
      if (!std::isfinite(r[0]) || !std::isfinite(r[1])) throw InvariantError("dynmesh: a non-finite off-center");
      const Box<2>& b = pg->box();
      const double x1 = b.origin[0] + b.side, y1 = b.origin[1] + b.side;
      if (!(r[0] >= b.origin[0] && r[0] <= x1 && r[1] >= b.origin[1] && r[1] <= y1)) {
        const SideCrossing s = side_crossed(b, p->p, q->p, r);
        const unsigned along = s.side % 2 == 0 ? 0 : 1;
        const double across = s.side == 0 ? b.origin[1] : s.side == 1 ? x1 : s.side == 2 ? y1 : b.origin[0];
        Point<2> x;
        x[along] = s.along;
        x[1 - along] = across;
        return side_edge_at(e, s.side, x, t, SplitFound{c});
      }
      SaVertex* rv = SaDelaunay::vertex(e, r);
      SaDelaunay::insert_with(e, pg->dt, rv, t, DecideK{c});
    }
  };

  /// Box edges to split, in order (a memo key part: comparable and hashable).
  struct Splits {
    std::vector<std::pair<SaVertex*, SaVertex*>> s;
    friend bool operator==(const Splits&, const Splits&) = default;
    std::size_t hash() const noexcept {
      std::uint64_t h = s.size();
      for (const auto& [a, b] : s) h = sac::hash_combine(h, sac::Hash<std::pair<SaVertex*, SaVertex*>>{}({a, b}));
      return static_cast<std::size_t>(h);
    }
  };

  /// r's cavity is known: commit it, or split the box edges of the cavity r encroaches.
  struct DecideK {
    Ctx c;
    friend bool operator==(const DecideK&, const DecideK&) = default;
    std::size_t hash() const noexcept { return c.hash(); }
    void operator()(sac::Engine& e, SaDelaunay* dt, SaVertex* x, const SaDelaunay::Cavity& w) const {
      Splits sp;
      for (const SaDelaunay::Boundary& bd : w.boundary)
        if (bd.edge->box_side && encroaches(bd.a->p, bd.b->p, x->p)) sp.s.emplace_back(bd.a, bd.b);
      if (sp.s.empty()) {
        SaDelaunay::fan(e, dt, x, w, c.bdest);
        return done(e, birth(e, c, x));
      }
      std::sort(sp.s.begin(), sp.s.end(), [](const auto& u, const auto& v) {
        return pair_less(u.first->p, u.second->p, v.first->p, v.second->p);
      });
      split_next(e, c, sp, 0);
    }
  };

  /// Splits sp.s[i..] in order, then tries the pair again.
  static void split_next(sac::Engine& e, const Ctx& c, const Splits& sp, std::size_t i) {
    if (i == sp.s.size()) return try_pair(e, c);
    SaVertex* a = sp.s[i].first;
    SaVertex* m = SaDelaunay::vertex(e, side_midpoint(a->p, sp.s[i].second->p));
    e.read(a->tri, [c, sp, i, m](sac::Engine& e2, SaTri* hint) {
      SaDelaunay::insert_with(e2, c.pg->dt, m, hint, AfterSplit{c, sp, i});
    });
  }

  struct AfterSplit {
    Ctx c;
    Splits sp;
    std::size_t i;
    friend bool operator==(const AfterSplit&, const AfterSplit&) = default;
    std::size_t hash() const noexcept { return sac::hash_combine(c.hash(), sp.hash() + i); }
    void operator()(sac::Engine& e, SaDelaunay* dt, SaVertex* x, const SaDelaunay::Cavity& w) const {
      SaDelaunay::fan(e, dt, x, w, c.bdest);
      split_next(e, birth(e, c, x), sp, i + 1);
    }
  };

  /// Split the box edge (a, b) the side crossing found, then try the pair again.
  struct SplitFound {
    Ctx c;
    friend bool operator==(const SplitFound&, const SplitFound&) = default;
    std::size_t hash() const noexcept { return c.hash(); }
    void operator()(sac::Engine& e, SaVertex* a, SaVertex* b) const { split_next(e, c, Splits{{{a, b}}}, 0); }
  };

  // ---------------------------------------------------------------- the side crossed

  /// The box edge of side `side` (0 bottom, 1 right, 2 top, 3 left) that holds X (a point
  /// of that side), by the twin's rule: of the side's vertices in order along it, the edge
  /// from the last one ≤ X to the next, and the side's last edge when X is its far end
  /// (std::map::upper_bound, clamped). Walks from t (live here) to X (SaDelaunay::locate)
  /// and reads the box edges there: the edge of the triangle holding X strictly inside, or,
  /// X a vertex, that vertex's neighbours along the side (its star's ends). Calls
  /// k(Engine&, SaVertex* a, SaVertex* b) in the last read's body; k must be comparable and
  /// hashable (part of the walk's memo keys).
  template <class K>
  static void side_edge_at(sac::Engine& e, int side, const Point<2>& x, SaTri* t, const K& k) {
    SaDelaunay::locate(e, x, t, SideEdgeK<K>{side, x[0], x[1], k});
  }

  template <class K>
  struct SideEdgeK {
    int side;
    double x0, x1;  // X
    K k;
    friend bool operator==(const SideEdgeK&, const SideEdgeK&) = default;
    std::size_t hash() const noexcept {
      std::uint64_t h = sac::Hash<K>{}(k);
      h = sac::hash_combine(h, sac::Hash<double>{}(x0));
      return static_cast<std::size_t>(sac::hash_combine(h, sac::Hash<double>{}(x1)));
    }
    void operator()(sac::Engine& e, SaTri* t) const {
      const Point<2> x{x0, x1};
      const unsigned along = side % 2 == 0 ? 0 : 1;
      for (int i = 0; i < 3; ++i) {
        const SaEdge* ed = t->e[sa_index::at(i)];
        if (!ed->box_side) continue;
        const Point<2>&a = ed->lo->p, &b = ed->hi->p;
        if (a[1 - along] != x[1 - along] || b[1 - along] != x[1 - along]) continue;  // another side
        const double lo = std::min(a[along], b[along]), hi = std::max(a[along], b[along]);
        if (lo < x[along] && x[along] < hi) return k(e, ed->lo, ed->hi);
      }
      for (SaVertex* v : t->v)
        if (v->p == x) return SaDelaunay::read_star(e, v, PickK<K>{side, v, k});
      throw InvariantError("dynmesh: HpuProgram: the side crossing is on no box edge of its triangle");
    }
  };

  /// X is the vertex v of the side: the edge to its neighbour along the side after it,
  /// else (v the side's far end) before it. A boundary vertex's star runs from one box side
  /// to the other, so those neighbours are its ends.
  template <class K>
  struct PickK {
    int side;
    SaVertex* v;
    K k;
    void operator()(sac::Engine& e, std::span<SaVertex* const> ring, std::span<SaTri* const>,
                    bool cycle) const {
      if (cycle || ring.empty()) throw InvariantError("dynmesh: HpuProgram: a side crossing at an inner vertex");
      const unsigned along = side % 2 == 0 ? 0 : 1;
      SaVertex* after = nullptr;
      SaVertex* before = nullptr;
      for (SaVertex* w : {ring.front(), ring.back()}) {
        if (w->p[1 - along] != v->p[1 - along]) continue;  // along the other side (v a corner)
        if (w->p[along] > v->p[along]) after = w;
        else before = w;
      }
      if (after) return k(e, v, after);
      if (!before) throw InvariantError("dynmesh: HpuProgram: a side vertex without a neighbour on its side");
      k(e, before, v);
    }
  };
};

}  // namespace dynmesh::detail
