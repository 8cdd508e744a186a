// sa_delaunay.hpp (private) — the Delaunay triangulation of points in a box as a
// self-adjusting program on sac-runtime: Bowyer–Watson insertion, run once from scratch and
// then kept up to date by change propagation when input points come and go.
//
// Purpose: the first brick of the self-adjusting off-center mesher (DynHPU). It computes
// exactly what delaunay.hpp (the static twin) computes — the same box and diagonal, the same
// perturbed in-circle rule, the same splitting of box sides — so its triangles equal
// Delaunay::triangles() of a from-scratch build on the current points (the triangulation is
// a function of the point set). It is written as building blocks that later programs (the
// Steiner points of the mesher) call in the same trace:
//
//   SaDelaunay{registry, box}        the context every block takes (static functions, so
//                                    that calls can be memoized with sac::fn)
//   SaDelaunay::vertex(p)            the vertex of p (keyed by its coordinates)
//   SaDelaunay::init_box()           the four corners and the two triangles of the box
//   SaDelaunay::insert(x, hint)      walk from `hint` (live here) to x, collect the cavity,
//                                    fan it from x
//   SaDelaunay::insert_near(x, v)    insert(x, v.tri), v.tri read in the trace
//   SaDelaunay::insert_with(x, h, k) insert's walk and cavity, then k decides: commit the
//                                    fan (fan(e, dt, x, cavity)) or leave it (the mesher
//                                    refuses off-centers that encroach a box edge)
//   SaDelaunay::locate(p, t, k)      the walk alone, to the triangle holding p, passed to k
//   SaDelaunay::read_star(v, k)      v's neighbours counter-clockwise and the triangles
//                                    between them, passed to k
//   SaDelaunayProgram                the input list inserted in list order, each point from
//                                    the previous one's triangle (QuadtreeMeshProgram style)
//   SaTriRegistry                    outside the trace: the live triangles and the change
//                                    feed (SaTriEvent records of births and deaths)
//
// Representation (everything that changes is a modifiable; corners never change, so
// in-circle and orientation tests need no read):
//   SaVertex – keyed by its point; `tri`, a live triangle with that corner.
//   SaEdge   – keyed by its two corners; side[0] / side[1], the triangle on the left of
//              lo→hi / hi→lo (lo the (x, y)-smaller end). A box side is flagged on
//              construction and its sides are never read or written: nothing lies beyond.
//   SaTri    – keyed by its corners in canonical rotation (the (x, y)-smallest first,
//              counter-clockwise) and its three edges; e[i] is the edge opposite v[i], the
//              neighbour across it the other side of e[i]. `dead`: written (true) once, by
//              the insertion whose cavity takes it; never written = alive.
// Why the links live on edges rather than in the triangles: a triangle's writes are then a
// function of the triangle alone ("I am on this side of these three edges"), so making it
// never reads or rewrites a neighbour. With the links in the triangles (the first version:
// one state per triangle), each new triangle had to read and rewrite its outside
// neighbour's state, so one changed link re-ran every later relink of that triangle and
// every read of those versions; an update then cost 2.2% of the from-scratch trace, here
// 0.9% (n = 1000, the test's figure). Keyed allocation reuses a triangle only with the same
// edge objects (they are part of its key), so a reused triangle never holds a stale edge.
//
// The trace of one insertion, each read nested in the previous one's body:
//   walk    at t, the exit edge is a function of t's corners and x (Delaunay::walk's rule:
//           of the edges x is strictly beyond, the one whose end points are smallest in
//           (x, y) order); memo_read(the far side of that edge, walk_via(x, t)). Memoized on
//           (x, t): when an earlier change re-routes the walk, it re-joins its old trace at
//           the first triangle of the old path it meets and reuses the rest.
//   cavity  breadth first from the walk's triangle, as Delaunay::cavity: a read of the far
//           side of each edge of each member, except box sides and edges shared with a
//           member. The search so far travels in the closures.
//   fan     keyed allocation of the new edges (x to each corner) and triangles; per new
//           triangle one memo writing its inner sides and its first corner's `tri`; per
//           cavity member one memo writing `dead`; one memo writing x's `tri`. Memoized on
//           what they write, so a fan re-run by an earlier change re-does only the
//           triangles that differ.
// Every memo key holds x: a hit undoes all the trace between the caller and the entry it
// reuses, so a key that could match a call of a later insertion (say `dead` keyed by the
// triangle alone, when an earlier insertion now takes it) would silently discard every
// insertion in between, and they would all be re-run from scratch. For the same reason the
// fan's keys also hold the caller's `token`, the place of the insertion in the caller's
// order (the refinement passes its pair): when an update makes an insertion happen earlier
// than before (the refinement inserts an off-center in an earlier round), x alone would
// match its old fan far ahead and discard everything in between (measured: about 3,000
// pairs of one class re-run for a deletion on the data's hull at n = 20,000); with the
// token it runs anew here, and its old trace is dropped when propagation reaches it.
// A point on a box side: the flat boundary edge (the side's edge through x) is not fanned,
// its halves become box edges of the neighbouring new triangles (Delaunay::insert's rule).
//
// Invariants (SaTriRegistry::check_invariants, after run()/propagate()): every live
// triangle is strictly counter-clockwise and canonically rotated, holds its corners' edges,
// is the latest triangle on its side of each inner edge, and the other side is a live
// triangle with that edge; every vertex's `tri` is live and has it as a corner;
// t = 2v − h − 2 (Euler). What the program relies on: it only reads the sides of edges of
// triangles reached through live links of the same moment (or a vertex's `tri`), so change
// propagation, which re-executes reads in time order on a consistent prefix, never follows
// a stale link.
// Identity: a vertex object lasts as long as its point stays in the list (a node that is
// re-placed finds its old vertex in the re-execution window, since no memo key reaches
// across insertions), so code outside the program may hold SaVertex* across updates (the
// star test does). With a key that could (see above), the vertex was undone and made anew,
// and a later reader of the old one failed with "no value at the time of this read".
// Determinism: the trace depends on the points, the list order and the triangulation, never
// on pointer values or hash order (pointers are only compared for equality; the registry's
// order is sorted away).
// Preconditions (the mutator's to check; a violation throws InvariantError inside the
// computation, which poisons the engine): points distinct, inside the closed box, none a
// box corner.
// Complexity: an insertion is O(walk + cavity) events, like the static twin's; the walk from
// the previous point is O(√n) expected for points in random order. A point update re-runs
// its own insertion, its successor's walk up to where it meets the old path, and the steps
// of later insertions whose reads the change touches: later walks re-routed through the
// changed region (the walks are long) and the cavities next to it. Measured at n = 1000
// (tests/dynmesh/sa_delaunay_test.cpp prints it): 0.9% of the from-scratch trace per
// update; about 200 walk steps and 100 cavity reads run again or anew, 15 fans re-run of
// which only ~18 triangles and ~14 deaths differ. The cavity travels by value in its
// closures: O(c²) for a cavity of c triangles (c is O(1) expected; degenerate input can
// make it large).
// Paper: Bowyer (1981), Watson (1981); Acar, Ahmed & Blume, "Imperative self-adjusting
// computation" (POPL'08) and Acar, "Self-adjusting computation" (2005) for memoized reads
// re-joining the old trace and keyed allocation; Acar, Cotter, Hudson & Türkoğlu, "Dynamic
// well-spaced point sets" (2010) for a self-adjusting mesher on this structure.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <sac/engine.hpp>
#include <sac/fn.hpp>
#include <sac/mod.hpp>

#include "geometry/delaunay.hpp"
#include "hpu/inline_vec.hpp"
#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/predicates.hpp"

namespace dynmesh::detail {

struct SaTri;
class SaTriRegistry;

namespace sa_index {
constexpr int next(int i) noexcept { return i == 2 ? 0 : i + 1; }
constexpr int prev(int i) noexcept { return i == 0 ? 2 : i - 1; }
constexpr std::size_t at(int i) noexcept { return static_cast<std::size_t>(i); }
}  // namespace sa_index

/// A vertex, allocated under its coordinates.
struct SaVertex {
  explicit SaVertex(const Point<2>& x) : p(x) {}
  SaVertex(const SaVertex&) = delete;
  SaVertex& operator=(const SaVertex&) = delete;

  Point<2> p;
  sac::Mod<SaTri*> tri;  // a live triangle with this corner
};

/// An edge, allocated under its corners (lo, hi), (x, y)-ordered. The box is a constant of
/// the program, so the constructor's arguments are a function of the key.
struct SaEdge {
  SaEdge(SaVertex* a, SaVertex* b, const Box<2>& box) : lo(a), hi(b) {
    const double x0 = box.origin[0], y0 = box.origin[1], x1 = x0 + box.side, y1 = y0 + box.side;
    const Point<2>&p = a->p, &q = b->p;
    box_side = (p[0] == q[0] && (p[0] == x0 || p[0] == x1)) || (p[1] == q[1] && (p[1] == y0 || p[1] == y1));
  }
  SaEdge(const SaEdge&) = delete;
  SaEdge& operator=(const SaEdge&) = delete;

  /// The side of the directed edge a→b (a an end): 0 when a is lo.
  int side_of(const SaVertex* a) const noexcept { return a == lo ? 0 : 1; }

  SaVertex* lo;
  SaVertex* hi;
  bool box_side;                          // on a side of the box: nothing beyond
  std::array<sac::Mod<SaTri*>, 2> side;  // the triangle left of lo→hi, of hi→lo
};

/// A triangle, allocated under its corners in canonical rotation and its edges. Registers
/// itself, so the mutator can list the live triangles after run()/propagate().
struct SaTri {
  SaTri(const std::array<SaVertex*, 3>& corners, const std::array<SaEdge*, 3>& edges, SaTriRegistry* r);
  ~SaTri();
  SaTri(const SaTri&) = delete;
  SaTri& operator=(const SaTri&) = delete;

  int index_of(const SaVertex* x) const noexcept { return v[0] == x ? 0 : v[1] == x ? 1 : v[2] == x ? 2 : -1; }
  /// Perturbed in-circle (delaunay.hpp): is x inside the circumcircle?
  bool in_conflict(const Point<2>& x) const noexcept { return perturbed_incircle(v[0]->p, v[1]->p, v[2]->p, x); }
  /// This triangle's side of edge i.
  int side(int i) const noexcept { return e[sa_index::at(i)]->side_of(v[sa_index::at(sa_index::next(i))]); }
  /// The modifiable holding the neighbour across edge i (not a box side).
  sac::Mod<SaTri*>& across(int i) const noexcept { return e[sa_index::at(i)]->side[sa_index::at(1 - side(i))]; }
  /// For the mutator, after run()/propagate().
  bool alive() const { return !dead.written() || !dead.get(); }

  std::array<SaVertex*, 3> v;  // counter-clockwise, v[0] the (x, y)-smallest
  std::array<SaEdge*, 3> e;    // e[i]: the edge opposite v[i]
  sac::Mod<bool> dead;         // written once, by the insertion whose cavity takes it
  SaTriRegistry* registry;
  std::size_t slot = 0;  // index in registry->all_
};

/// A list of triangles as a memo key (sac/hash.hpp: a type with hash()).
struct SaTriList {
  std::vector<SaTri*> t;
  friend bool operator==(const SaTriList&, const SaTriList&) = default;
  std::size_t hash() const noexcept {
    std::uint64_t h = t.size();
    for (SaTri* x : t) h = sac::hash_combine(h, sac::Hash<SaTri*>{}(x));
    return static_cast<std::size_t>(h);
  }
};

/// Every SaTri the engine holds (live or dead), outside the trace. Must outlive the engine
/// (the engine destroys its allocations, and with them their registrations).
class SaTriRegistry {
 public:
  SaTriRegistry() = default;
  SaTriRegistry(const SaTriRegistry&) = delete;
  SaTriRegistry& operator=(const SaTriRegistry&) = delete;

  /// Allocated triangles, in no meaningful order.
  std::span<SaTri* const> all() const noexcept { return all_; }

  /// The live triangles, canonical and sorted (Delaunay::triangles()'s form). Mutator only.
  std::vector<Triangle> triangles() const {
    std::vector<Triangle> out;
    for (const SaTri* t : all_)
      if (t->alive()) out.push_back(canonical_triangle(t->v[0]->p, t->v[1]->p, t->v[2]->p));
    std::sort(out.begin(), out.end());
    return out;
  }

  /// The live triangle count, kept by the feed's records (below). O(1).
  std::size_t live_count() const noexcept { return live_; }

  /// The change feed since the last call: the triangles that were live then and are not
  /// now (removed) and the other way round (added), each sorted. A triangle's birth (its
  /// fan) and death (a cavity's kill) each make a keyless SaTriEvent record in the trace;
  /// propagation makes and undoes records, and the records' net count per triangle is the
  /// change (a triangle re-made unchanged nets 0). O(e log e) for e events.
  MeshChange take_change() {
    std::sort(events_.begin(), events_.end());
    MeshChange out;
    for (std::size_t i = 0; i < events_.size();) {
      std::size_t j = i;
      int net = 0;
      for (; j < events_.size() && events_[j].first == events_[i].first; ++j) net += events_[j].second;
      if (net > 0) out.added.push_back(events_[i].first);
      else if (net < 0) out.removed.push_back(events_[i].first);
      if (net < -1 || net > 1) throw InvariantError("dynmesh: SaDelaunay: a triangle born or killed twice");
      i = j;
    }
    events_.clear();
    return out;
  }
  /// Drops the pending events (after run(): the whole mesh is new).
  void clear_change() noexcept { events_.clear(); }
  /// Call before the engine is destroyed: its records' destructors then log nothing.
  void close() noexcept { closing_ = true; }
  /// For the checker's negative test only: one live triangle too many.
  void corrupt_live_count_for_testing() noexcept { ++live_; }

  /// Throws InvariantError naming the first broken rule (see the header). Mutator only. O(t).
  void check_invariants(const Box<2>& box) const {
    using sa_index::at;
    using sa_index::next;
    using sa_index::prev;
    const auto fail = [](const std::string& what) { throw InvariantError("dynmesh: SaDelaunay: " + what); };
    const double x0 = box.origin[0], y0 = box.origin[1], x1 = x0 + box.side, y1 = y0 + box.side;
    std::size_t live = 0;
    std::vector<SaVertex*> verts;
    for (const SaTri* t : all_) {
      if (!t->alive()) continue;
      ++live;
      const auto& v = t->v;
      if (orient2d(v[0]->p, v[1]->p, v[2]->p) <= 0) fail("a live triangle is not ccw");
      if (xy_less(v[1]->p, v[0]->p) || xy_less(v[2]->p, v[0]->p)) fail("a triangle not in canonical rotation");
      for (int i = 0; i < 3; ++i) {
        verts.push_back(v[at(i)]);
        const SaEdge* e = t->e[at(i)];
        const SaVertex* a = v[at(next(i))];
        const SaVertex* b = v[at(prev(i))];
        if (!((e->lo == a && e->hi == b) || (e->lo == b && e->hi == a)) || !xy_less(e->lo->p, e->hi->p))
          fail("a triangle's edge has other ends");
        if (e->box_side) continue;
        const auto& mine = e->side[at(t->side(i))];
        if (!mine.written() || mine.get() != t) fail("a live triangle is not the latest on its side of an edge");
        const auto& far = t->across(i);
        if (!far.written()) fail("an inner edge with one side");
        const SaTri* u = far.get();
        if (!u || !u->alive()) fail("a link to a dead triangle");
        if (std::find(u->e.begin(), u->e.end(), e) == u->e.end()) fail("the neighbour lacks the shared edge");
      }
    }
    // Sorting pointers only counts the distinct vertices: nothing depends on the order.
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    std::size_t h = 0;
    for (const SaVertex* x : verts) {
      if (!x->tri.written()) fail("a vertex without a triangle");
      const SaTri* t = x->tri.get();
      if (!t || !t->alive() || t->index_of(x) < 0) fail("a vertex's triangle is dead or lacks it: " + to_string(x->p));
      if (x->p[0] == x0 || x->p[0] == x1 || x->p[1] == y0 || x->p[1] == y1) ++h;
    }
    if (live + h + 2 != 2 * verts.size()) fail("Euler's formula fails: the triangles do not tile the box");
    if (live != live_) fail("the feed's live count is " + std::to_string(live_) + ", not " + std::to_string(live));
  }

 private:
  friend struct SaTri;
  friend struct SaTriEvent;
  void note(const Triangle& t, int d) {
    if (closing_) return;
    events_.emplace_back(t, d);
    live_ = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(live_) + d);
  }
  std::vector<SaTri*> all_;
  std::vector<std::pair<Triangle, int>> events_;
  std::size_t live_ = 0;
  bool closing_ = false;
};

/// A birth (+1) or death (−1) of a triangle in the trace (make<SaTriEvent>): logged when
/// made and, negated, when propagation undoes it. Holds the corners by value, since the
/// triangle's own allocation may be undone first.
struct SaTriEvent {
  SaTriEvent(SaTriRegistry* r, const SaTri* t, int s)
      : registry(r), tri{{t->v[0]->p, t->v[1]->p, t->v[2]->p}}, sign(s) {
    registry->note(tri, sign);
  }
  ~SaTriEvent() { registry->note(tri, -sign); }
  SaTriEvent(const SaTriEvent&) = delete;
  SaTriEvent& operator=(const SaTriEvent&) = delete;
  SaTriRegistry* registry;
  Triangle tri;  // canonical: SaTri's corners are in canonical rotation
  int sign;
};

inline SaTri::SaTri(const std::array<SaVertex*, 3>& corners, const std::array<SaEdge*, 3>& edges, SaTriRegistry* r)
    : v(corners), e(edges), registry(r) {
  slot = r->all_.size();
  r->all_.push_back(this);
}

inline SaTri::~SaTri() {
  auto& all = registry->all_;
  SaTri* last = all.back();
  all[slot] = last;
  last->slot = slot;
  all.pop_back();
}

/// The building blocks. Functions are static and take the context, so that they can be
/// memoized with sac::fn; all of them run inside the computation.
struct SaDelaunay {
  SaTriRegistry* registry;
  Box<2> box;

  // ------------------------------------------------------------------ objects

  /// The vertex at p. -0.0 is stored as +0.0, so the object is a function of its key.
  static SaVertex* vertex(sac::Engine& e, const Point<2>& p) {
    const Point<2> q{p[0] + 0.0, p[1] + 0.0};
    return e.alloc<SaVertex>(std::pair{q[0], q[1]}, q);
  }

  /// The edge between a and b.
  static SaEdge* edge(sac::Engine& e, SaDelaunay* dt, SaVertex* a, SaVertex* b) {
    if (xy_less(b->p, a->p)) std::swap(a, b);
    return e.alloc<SaEdge>(std::pair{a, b}, a, b, dt->box);
  }

  /// The triangle with counter-clockwise corners c and edges e (e[i] opposite c[i]), in
  /// any rotation.
  static SaTri* triangle(sac::Engine& e, SaDelaunay* dt, std::array<SaVertex*, 3> c, std::array<SaEdge*, 3> ed) {
    const std::size_t r = xy_less(c[1]->p, c[0]->p) && xy_less(c[1]->p, c[2]->p) ? 1
                          : xy_less(c[2]->p, c[0]->p) && xy_less(c[2]->p, c[1]->p) ? 2
                                                                                   : 0;
    std::rotate(c.begin(), c.begin() + static_cast<std::ptrdiff_t>(r), c.end());
    std::rotate(ed.begin(), ed.begin() + static_cast<std::ptrdiff_t>(r), ed.end());
    return e.alloc<SaTri>(std::tuple{c[0], c[1], c[2], ed[0], ed[1], ed[2]}, c, ed, dt->registry);
  }

  /// t takes its side of each of its inner edges.
  static void put_sides(sac::Engine& e, SaTri* t) {
    for (int i = 0; i < 3; ++i) {
      SaEdge* ed = t->e[sa_index::at(i)];
      if (!ed->box_side) e.write(ed->side[sa_index::at(t->side(i))], t);
    }
  }

  /// The box's corners (counter-clockwise from the origin) and its two triangles, the
  /// diagonal chosen by the perturbation as in Delaunay's constructor. Makes no read, so it
  /// returns its result.
  static std::array<SaVertex*, 4> init_box(sac::Engine& e, SaDelaunay* dt) {
    const Box<2>& box = dt->box;
    const double x0 = box.origin[0], y0 = box.origin[1], x1 = x0 + box.side, y1 = y0 + box.side;
    const std::array<SaVertex*, 4> c{vertex(e, {x0, y0}), vertex(e, {x1, y0}), vertex(e, {x1, y1}),
                                     vertex(e, {x0, y1})};
    const std::array<SaEdge*, 4> sides{edge(e, dt, c[0], c[1]), edge(e, dt, c[1], c[2]), edge(e, dt, c[2], c[3]),
                                       edge(e, dt, c[3], c[0])};
    SaTri* s;
    SaTri* t;
    if (!perturbed_incircle(c[0]->p, c[1]->p, c[2]->p, c[3]->p)) {
      SaEdge* d = edge(e, dt, c[0], c[2]);
      s = triangle(e, dt, {c[0], c[1], c[2]}, {sides[1], d, sides[0]});
      t = triangle(e, dt, {c[0], c[2], c[3]}, {sides[2], sides[3], d});
    } else {
      SaEdge* d = edge(e, dt, c[1], c[3]);
      s = triangle(e, dt, {c[0], c[1], c[3]}, {d, sides[3], sides[0]});
      t = triangle(e, dt, {c[1], c[2], c[3]}, {sides[2], d, sides[1]});
    }
    put_sides(e, s);
    put_sides(e, t);
    e.make<SaTriEvent>(dt->registry, s, +1);
    e.make<SaTriEvent>(dt->registry, t, +1);
    // Corners 0 and 1 are in s, 2 and 3 in t, for either diagonal.
    e.write(c[0]->tri, s);
    e.write(c[1]->tri, s);
    e.write(c[2]->tri, t);
    e.write(c[3]->tri, t);
    return c;
  }

  // ------------------------------------------------------------------ insertion

  /// Inserts x (a vertex() inside the closed box, not yet in the triangulation) starting
  /// the walk at `hint`, which must be live at this point of the trace (read from a
  /// vertex's `tri` in the calling body, say: its corners are not read, its links are).
  static void insert(sac::Engine& e, SaDelaunay* dt, SaVertex* x, SaTri* hint) { walk_at(e, dt, x, hint, Commit{}); }

  /// The continuation of an insertion that commits it: fan the cavity.
  struct Commit {
    friend bool operator==(const Commit&, const Commit&) = default;
    std::size_t hash() const noexcept { return 0x9e37'79b9; }
    template <class C>
    void operator()(sac::Engine& e, SaDelaunay* dt, SaVertex* x, const C& w) const {
      fan(e, dt, x, w);
    }
  };

  /// Insertion with a say: walks from `hint` (as insert) and collects x's cavity, then calls
  /// k(Engine&, SaDelaunay*, SaVertex* x, const Cavity&) in the body of the cavity's last
  /// read, which may commit it (fan(e, dt, x, cavity)) or leave the triangulation as it is
  /// (the refinement refuses an off-center that encroaches a box edge of its cavity). k must
  /// be equality comparable and hashable (it is part of the walk's memo keys), and copyable.
  template <class K>
  static void insert_with(sac::Engine& e, SaDelaunay* dt, SaVertex* x, SaTri* hint, const K& k) {
    walk_at(e, dt, x, hint, k);
  }

  /// Walks from t (live here) to the triangle holding p in its closure (p in the closed
  /// box) by walk_at's rule, and calls k(Engine&, SaTri*) there, in the last read's body.
  /// Memoized on (p, t, k), like the insertion's walk.
  template <class K>
  static void locate(sac::Engine& e, const Point<2>& p, SaTri* t, const K& k) {
    const int exit = exit_edge(*t, p);
    if (exit < 0) return k(e, t);
    if (t->e[sa_index::at(exit)]->box_side)
      throw InvariantError("dynmesh: SaDelaunay: locating " + to_string(p) + " outside the box");
    e.memo_read(t->across(exit), sac::fn<&locate_via<K>>(std::pair{p[0], p[1]}, t, k));
  }
  template <class K>
  static void locate_via(sac::Engine& e, SaTri* u, std::pair<double, double> p, SaTri* t, K k) {
    (void)t;  // part of the memo key only
    locate(e, Point<2>{p.first, p.second}, u, k);
  }

  /// Inserts x starting from the triangle `near` points at (read here, so a change of it
  /// re-routes the walk).
  static void insert_near(sac::Engine& e, SaDelaunay* dt, SaVertex* x, SaVertex* near) {
    e.memo_read(near->tri, sac::fn<&insert_from>(dt, x));
  }

  static void insert_from(sac::Engine& e, SaTri* hint, SaDelaunay* dt, SaVertex* x) { insert(e, dt, x, hint); }

  /// The edge of t that x is strictly beyond, by Delaunay::walk's rule, or -1 when x is in
  /// t's closure.
  static int exit_edge(const SaTri& t, const Point<2>& x) {
    using sa_index::at;
    using sa_index::next;
    using sa_index::prev;
    int exit = -1;
    const auto key = [&](int i) {
      const Point<2>& u = t.v[at(next(i))]->p;
      const Point<2>& w = t.v[at(prev(i))]->p;
      return xy_less(u, w) ? std::pair{u, w} : std::pair{w, u};
    };
    for (int i = 0; i < 3; ++i) {
      if (orient2d(t.v[at(next(i))]->p, t.v[at(prev(i))]->p, x) >= 0) continue;
      if (exit < 0) {
        exit = i;
        continue;
      }
      const auto ki = key(i), ke = key(exit);
      if (xy_less(ki.first, ke.first) || (ki.first == ke.first && xy_less(ki.second, ke.second))) exit = i;
    }
    return exit;
  }

  /// The walk at t (live now): leave through the exit edge, or start the cavity at t.
  template <class K>
  static void walk_at(sac::Engine& e, SaDelaunay* dt, SaVertex* x, SaTri* t, const K& k) {
    const int exit = exit_edge(*t, x->p);
    if (exit >= 0) {
      if (t->e[sa_index::at(exit)]->box_side)
        throw InvariantError("dynmesh: SaDelaunay: inserting " + to_string(x->p) + " outside the box");
      return e.memo_read(t->across(exit), sac::fn<&walk_via<K>>(dt, x, t, k));
    }
    for (const SaVertex* c : t->v)
      if (c->p == x->p) throw InvariantError("dynmesh: SaDelaunay: " + to_string(x->p) + " inserted twice");
    cavity_step(e, dt, x, Cavity{{t}, 0, 0, {}}, k);
  }

  /// The walk crossed t's exit edge into u.
  template <class K>
  static void walk_via(sac::Engine& e, SaTri* u, SaDelaunay* dt, SaVertex* x, SaTri* t, K k) {
    (void)t;  // part of the memo key only
    walk_at(e, dt, x, u, k);
  }

  /// A boundary edge a→b of the cavity (counter-clockwise around it).
  struct Boundary {
    SaVertex* a;
    SaVertex* b;
    SaEdge* edge;
  };

  /// The breadth-first search of the cavity so far (Delaunay::cavity's order).
  struct Cavity {
    std::vector<SaTri*> members;     // in order of discovery
    std::size_t at;                  // the member whose edges are examined
    int edge;                        // its next edge
    std::vector<Boundary> boundary;  // in order of discovery
  };

  /// Runs the search until it needs the triangle beyond an edge (then reads it and
  /// continues in the body), and fans the cavity when it is complete. Edges on the box and
  /// edges shared with a member need no read. The closures copy the search: a body may run
  /// again, so it must not consume what it captured.
  template <class K>
  static void cavity_step(sac::Engine& e, SaDelaunay* dt, SaVertex* x, Cavity w, const K& k) {
    using sa_index::at;
    using sa_index::next;
    using sa_index::prev;
    for (; w.at < w.members.size(); ++w.at, w.edge = 0) {
      for (; w.edge < 3; ++w.edge) {
        const SaTri* m = w.members[w.at];
        SaEdge* ed = m->e[at(w.edge)];
        if (ed->box_side) {
          w.boundary.push_back(Boundary{m->v[at(next(w.edge))], m->v[at(prev(w.edge))], ed});
          continue;
        }
        // Members are few (O(1) expected): a linear scan.
        const auto shares = [&](const SaTri* q) {
          return q != m && std::find(q->e.begin(), q->e.end(), ed) != q->e.end();
        };
        if (std::any_of(w.members.begin(), w.members.end(), shares)) continue;
        e.read(m->across(w.edge), [dt, x, w, k](sac::Engine& e2, SaTri* u) {
          Cavity c = w;
          const SaTri* q = c.members[c.at];
          // u's corners are fixed: the test needs no read.
          if (u->in_conflict(x->p)) c.members.push_back(u);
          else c.boundary.push_back(Boundary{q->v[at(next(c.edge))], q->v[at(prev(c.edge))], q->e[at(c.edge)]});
          ++c.edge;
          cavity_step(e2, dt, x, std::move(c), k);
        });
        return;
      }
    }
    k(e, dt, x, std::as_const(w));
  }

  /// Replaces the cavity by the fan of x: keyed allocations and memoized writes only (no
  /// read), in an order that is a function of the cavity.
  static void fan(sac::Engine& e, SaDelaunay* dt, SaVertex* x, const Cavity& w, const void* token = nullptr) {
    // The edges from x to the fan's corners, in order of first appearance.
    std::vector<std::pair<SaVertex*, SaEdge*>> spokes;
    const auto spoke = [&](SaVertex* c) {
      for (const auto& [v, ed] : spokes)
        if (v == c) return ed;
      return spokes.emplace_back(c, edge(e, dt, x, c)).second;
    };
    SaTriList made;
    for (const Boundary& bd : w.boundary) {
      // x on a box side: that side's edge is not fanned (the triangle would be flat).
      if (orient2d(bd.a->p, bd.b->p, x->p) <= 0) {
        if (!bd.edge->box_side)
          throw InvariantError("dynmesh: SaDelaunay: x is on an inner edge of its cavity's boundary");
        continue;
      }
      // (a, b, x): opposite a the edge b-x, opposite b the edge x-a, opposite x the boundary.
      SaEdge* xa = spoke(bd.a);
      SaEdge* bx = spoke(bd.b);
      made.t.push_back(triangle(e, dt, {bd.a, bd.b, x}, {bx, xa, bd.edge}));
    }
    if (made.t.empty()) throw InvariantError("dynmesh: SaDelaunay: an empty fan");
    // Memoized on what they write (a function of the triangle alone), with x in each key
    // (see the header).
    for (SaTri* t : made.t) e.memo(sac::fn<&put_fan_triangle>(x, t, token));
    for (SaTri* t : w.members) e.memo(sac::fn<&kill>(x, t, token));
    // x's triangle: the fan triangle of the (x, y)-smallest corner (a function of the
    // fan, not of where the search started).
    const auto a_of = [x](const SaTri* t) { return t->v[sa_index::at(sa_index::next(t->index_of(x)))]; };
    SaTri* low = made.t.front();
    for (SaTri* t : made.t)
      if (xy_less(a_of(t)->p, a_of(low)->p)) low = t;
    e.memo(sac::fn<&put_vertex>(x, low, token));
  }

  /// The fan triangle t = (a, b, x) takes its sides, and gives a a live triangle; also b,
  /// when b-x is a half of a split box side (no fan triangle starts at b then).
  static void put_fan_triangle(sac::Engine& e, SaVertex* x, SaTri* t, const void*) {
    using sa_index::at;
    using sa_index::next;
    using sa_index::prev;
    put_sides(e, t);
    e.make<SaTriEvent>(t->registry, t, +1);
    const int ix = t->index_of(x);
    e.write(t->v[at(next(ix))]->tri, t);
    if (t->e[at(next(ix))]->box_side) e.write(t->v[at(prev(ix))]->tri, t);
  }

  static void kill(sac::Engine& e, SaVertex* x, SaTri* t, const void*) {
    (void)x;
    e.write(t->dead, true);
    e.make<SaTriEvent>(t->registry, t, -1);
  }
  static void put_vertex(sac::Engine& e, SaVertex* v, SaTri* t, const void*) { e.write(v->tri, t); }

  // ------------------------------------------------------------------ stars

  template <class K>
  struct Star {
    SaVertex* v;
    InlineVec<SaTri*, 8> ccw;     // from v.tri (ccw[0], where the turn starts), counter-clockwise
    InlineVec<SaTri*, 2> cw;      // before ccw[0], clockwise (a boundary vertex)
    K k;
  };

  /// Reads v's star and calls k(Engine&, std::span<SaVertex* const> ring,
  /// std::span<SaTri* const> tris, bool interior): v's neighbours counter-clockwise — a
  /// cycle for an interior vertex, from one box side to the other for a vertex on the
  /// boundary (Delaunay::star's order) — and the triangles between them, tris[i] =
  /// (v, ring[i], ring[i + 1 mod d]). Reads v.tri, then one edge side per triangle around v:
  /// counter-clockwise from v.tri, then, when a box side stops the turn, clockwise from
  /// v.tri. The closures carry only the triangles seen, inline up to 8 (the mean degree is
  /// 6; 12 inline cost 11% more trace memory for no measurable time). k must be copyable;
  /// it runs in the last read's body (a change of the star re-runs it).
  template <class K>
  static void read_star(sac::Engine& e, SaVertex* v, const K& k) {
    e.read(v->tri, [v, k](sac::Engine& e2, SaTri* first) {
      if (first->index_of(v) < 0) throw InvariantError("dynmesh: SaDelaunay: a vertex's triangle lacks it");
      star_ccw(e2, Star<K>{v, {}, {}, k}, first);
    });
  }

  /// At t = (v, a, b) going counter-clockwise: cross v-b.
  template <class K>
  static void star_ccw(sac::Engine& e, Star<K> w, SaTri* t) {
    using sa_index::at;
    using sa_index::next;
    const int i = t->index_of(w.v);
    w.ccw.push_back(t);
    if (t->e[at(next(i))]->box_side) return star_turn(e, std::move(w));
    e.read(t->across(next(i)), [w](sac::Engine& e2, SaTri* u) {
      if (u != w.ccw[0]) return star_ccw(e2, Star<K>(w), u);
      star_done(e2, w, true);  // all the way round
    });
  }

  /// A box side stopped the counter-clockwise turn: turn clockwise from first = (v, a, b)
  /// across v-a, unless that is a box side too.
  template <class K>
  static void star_turn(sac::Engine& e, Star<K> w) {
    SaTri* first = w.ccw[0];
    const int j = sa_index::prev(first->index_of(w.v));
    if (first->e[sa_index::at(j)]->box_side) return star_done(e, w, false);
    e.read(first->across(j), [w](sac::Engine& e2, SaTri* u) { star_cw(e2, Star<K>(w), u); });
  }

  /// At t = (v, a, b) going clockwise: cross v-a.
  template <class K>
  static void star_cw(sac::Engine& e, Star<K> w, SaTri* t) {
    using sa_index::at;
    using sa_index::prev;
    const int i = t->index_of(w.v);
    w.cw.push_back(t);
    if (!t->e[at(prev(i))]->box_side)
      return e.read(t->across(prev(i)), [w](sac::Engine& e2, SaTri* u) { star_cw(e2, Star<K>(w), u); });
    star_done(e, w, false);
  }

  /// The triangles in counter-clockwise order (the clockwise part reversed, then the rest)
  /// and the ring they define: the first triangle's a, then every triangle's b (for an
  /// interior vertex the last b is the first a again).
  template <class K>
  static void star_done(sac::Engine& e, const Star<K>& w, bool interior) {
    using sa_index::at;
    using sa_index::next;
    using sa_index::prev;
    InlineVec<SaTri*, 24> tris;
    for (std::size_t k = w.cw.size(); k-- > 0;) tris.push_back(w.cw[k]);
    for (std::size_t k = 0; k < w.ccw.size(); ++k) tris.push_back(w.ccw[k]);
    InlineVec<SaVertex*, 24> ring;
    ring.push_back(tris[0]->v[at(next(tris[0]->index_of(w.v)))]);
    for (std::size_t k = 0; k < tris.size(); ++k) ring.push_back(tris[k]->v[at(prev(tris[k]->index_of(w.v)))]);
    if (interior) ring.pop_back();
    w.k(e, ring.span(), tris.span(), interior);
  }
};

// ------------------------------------------------------------------ the program

/// A cell of the input list (mutator-owned): the point and the rest of the list.
struct SaInputNode {
  explicit SaInputNode(const Point<2>& x) : point(x) {}
  SaInputNode(const SaInputNode&) = delete;
  SaInputNode& operator=(const SaInputNode&) = delete;
  Point<2> point;
  sac::Mod<SaInputNode*> next;
};

/// The Delaunay triangulation of the box and the input list's points, inserted in list
/// order, each from the triangle of the point before it. Run with
/// e.run([&](sac::Engine& r) { SaDelaunayProgram::main(r, &program); }); the mutator then
/// inserts and deletes points by relinking the list with Engine::set and calls propagate().
struct SaDelaunayProgram {
  SaDelaunay* dt;
  sac::Mod<SaInputNode*>* input;

  static void main(sac::Engine& e, SaDelaunayProgram* pg) {
    const std::array<SaVertex*, 4> corners = SaDelaunay::init_box(e, pg->dt);
    e.memo_read(*pg->input, sac::fn<&place>(pg, corners[0]));
  }

  /// Inserts n's point from prev's triangle, then the rest of the list. The next step is
  /// memoized on (n.next, n's vertex): after a change earlier in the list the re-execution
  /// re-joins the old trace once it has re-inserted the node after the change.
  static void place(sac::Engine& e, SaInputNode* n, SaDelaunayProgram* pg, SaVertex* prev) {
    if (!n) return;
    SaVertex* x = SaDelaunay::vertex(e, n->point);
    SaDelaunay::insert_near(e, pg->dt, x, prev);
    e.memo_read(n->next, sac::fn<&place>(pg, x));
  }
};

}  // namespace dynmesh::detail
