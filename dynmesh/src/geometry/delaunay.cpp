// delaunay.cpp — Bowyer–Watson insertion with a perturbed in-circle test (see delaunay.hpp).
#include "geometry/delaunay.hpp"

#include <algorithm>
#include <string>

#include "dynmesh/errors.hpp"
#include "dynmesh/predicates.hpp"

namespace dynmesh::detail {

namespace {

constexpr int next(int i) noexcept { return i == 2 ? 0 : i + 1; }
constexpr int prev(int i) noexcept { return i == 0 ? 2 : i - 1; }
/// The index of v among T's corners (T has corner v).
int corner(const Delaunay::Tri& T, Delaunay::Vid v) noexcept { return T.v[0] == v ? 0 : T.v[1] == v ? 1 : 2; }

}  // namespace

bool perturbed_incircle(const Point<2>& a, const Point<2>& b, const Point<2>& c, const Point<2>& d) noexcept {
  if (const int s = incircle(a, b, c, d); s != 0) return s > 0;
  // Decreasing rank: the point perturbed most decides first.
  const Point<2>* order[4] = {&a, &b, &c, &d};
  std::sort(order, order + 4, [](const Point<2>* u, const Point<2>* v) { return xy_less(*v, *u); });
  for (const Point<2>* p : order) {
    int coef;
    if (p == &d) coef = -orient2d(a, b, c);
    else if (p == &a) coef = orient2d(d, b, c);
    else if (p == &b) coef = orient2d(a, d, c);
    else coef = orient2d(a, b, d);
    if (coef != 0) return coef > 0;
  }
  return false;  // unreachable for a real triangle a, b, c
}

Delaunay::Delaunay(const Box<2>& box) : box_(box) {
  hi_[0] = box.origin[0] + box.side;
  hi_[1] = box.origin[1] + box.side;
  const double x0 = box.origin[0], y0 = box.origin[1];
  pts_ = {Point<2>{x0, y0}, Point<2>{hi_[0], y0}, Point<2>{hi_[0], hi_[1]}, Point<2>{x0, hi_[1]}};
  // The four corners are cocircular: the perturbation picks the diagonal.
  if (!perturbed_incircle(pts_[0], pts_[1], pts_[2], pts_[3])) {
    const Tid s = new_tri(0, 1, 2), t = new_tri(0, 2, 3);
    tris_[s].n = {kNone, t, kNone};  // edge 2-0 (opposite 1) is shared
    tris_[t].n = {kNone, kNone, s};  // edge 0-2 (opposite 3)
  } else {
    const Tid s = new_tri(0, 1, 3), t = new_tri(1, 2, 3);
    tris_[s].n = {t, kNone, kNone};  // edge 1-3 (opposite 0)
    tris_[t].n = {kNone, s, kNone};  // edge 3-1 (opposite 2)
  }
}

Delaunay::Tid Delaunay::new_tri(Vid a, Vid b, Vid c) {
  Tid t;
  if (!free_.empty()) {
    t = free_.back();
    free_.pop_back();
  } else {
    t = static_cast<Tid>(tris_.size());
    tris_.emplace_back();
  }
  Tri& T = tris_[t];
  T.v = {a, b, c};
  T.n = {kNone, kNone, kNone};
  T.alive = true;
  if (vtri_.size() < pts_.size()) vtri_.resize(pts_.size() + pts_.size() / 2, kNone);
  vtri_[a] = vtri_[b] = vtri_[c] = t;
  ++live_;
  ++made_;
  return t;
}

void Delaunay::star(Vid v, std::vector<Vid>& out, std::vector<Tid>* left) const {
  out.clear();
  if (left) left->clear();
  const Tid t0 = vtri_[v];
  const auto at = [&](Tid t) { return corner(tris_[t], v); };
  // Back up clockwise to a box side, if v is on one: across the edge v→a of (v, a, b).
  Tid t = t0;
  const Point<2>& p = pts_[v];
  const bool boundary = p[0] == box_.origin[0] || p[1] == box_.origin[1] || p[0] == hi_[0] || p[1] == hi_[1];
  while (boundary) {
    const Tid u = tris_[t].n[prev(at(t))];
    if (u == kNone || u == t0) break;
    t = u;
  }
  const Tid first = t;
  out.push_back(tris_[t].v[next(at(t))]);
  for (;;) {  // counter-clockwise: across the edge v→b of (v, a, b)
    const int i = at(t);
    if (left) left->push_back(t);  // (v, a, b) is on the left of v→a, a = out.back()
    out.push_back(tris_[t].v[prev(i)]);
    t = tris_[t].n[next(i)];
    if (t == kNone) {
      if (left) left->push_back(kNone);  // v→b runs along a box side
      return;
    }
    if (t == first) {
      out.pop_back();  // an interior vertex: the last neighbour is the first
      return;
    }
  }
}

void Delaunay::stars(std::span<const Vid> vs, std::span<std::vector<Vid>> out, std::span<std::vector<Tid>> left) const {
  if (vs.size() > kStarsAtOnce || out.size() < vs.size() || left.size() < vs.size())
    throw InvariantError("dynmesh: Delaunay::stars: too many vertices or too few outputs");
  // Counter-clockwise from each vertex's triangle, as star() does for an interior vertex. A
  // walk that meets a box side belongs to a boundary vertex, which star() redoes from its
  // clockwise end: knowing that needs no load of the vertex's point.
  struct Cursor {
    Tid t, first;
    std::uint32_t k;
  };
  std::array<Cursor, kStarsAtOnce> w;
  std::size_t n = 0;
  for (std::uint32_t k = 0; k < vs.size(); ++k) {
    out[k].clear();
    left[k].clear();
    const Tid t = vtri_[vs[k]];
    __builtin_prefetch(&tris_[t]);
    w[n++] = Cursor{t, t, k};
  }
  while (n > 0) {
    for (std::size_t i = 0; i < n;) {
      Cursor& x = w[i];
      const Vid v = vs[x.k];
      const Tri& T = tris_[x.t];
      const int a = corner(T, v);
      std::vector<Vid>& o = out[x.k];
      if (o.empty()) o.push_back(T.v[next(a)]);
      left[x.k].push_back(x.t);
      o.push_back(T.v[prev(a)]);
      x.t = T.n[next(a)];
      if (x.t == kNone || x.t == x.first) {
        if (x.t == kNone) star(v, o, &left[x.k]);  // a boundary vertex
        else o.pop_back();                         // the last neighbour is the first
        x = w[--n];
        continue;
      }
      __builtin_prefetch(&tris_[x.t]);
      ++i;
    }
  }
}

std::optional<std::pair<Delaunay::Tid, int>> Delaunay::left_of(Vid p, Vid q) const noexcept {
  const Tid t0 = vtri_[p];
  // Counter-clockwise around p, then clockwise from t0 when a box side stopped the first turn.
  for (int dir = 0; dir < 2; ++dir) {
    Tid t = t0;
    for (;;) {
      const Tri& T = tris_[t];
      const int i = corner(T, p);
      if (T.v[next(i)] == q) return std::pair{t, prev(i)};
      const Tid u = dir == 0 ? T.n[next(i)] : T.n[prev(i)];
      if (u == t0) return std::nullopt;  // all the way round: not a neighbour
      if (u == kNone) break;
      t = u;
    }
  }
  return std::nullopt;
}

std::optional<std::pair<Delaunay::Tid, int>> Delaunay::left_of(Vid p, Vid q, Tid hint) const noexcept {
  if (hint < tris_.size() && tris_[hint].alive) {
    const Tri& T = tris_[hint];
    for (int i = 0; i < 3; ++i)
      if (T.v[i] == p && T.v[next(i)] == q) return std::pair{hint, prev(i)};
  }
  return left_of(p, q);
}

Delaunay::Tid Delaunay::any_live() const noexcept {
  for (Tid t = 0; t < tris_.size(); ++t)
    if (tris_[t].alive) return t;
  return kNone;
}

Delaunay::Walk Delaunay::walk(Tid start, const Point<2>& x) const {
  Tid t = start;
  // A visibility walk ends in a Delaunay triangulation; the cap is a guard, not a bound.
  for (std::size_t steps = 0; steps <= 4 * tris_.size() + 16; ++steps) {
    const Tri& T = tris_[t];
    int exit = -1;
    for (int i = 0; i < 3; ++i) {
      const Point<2>& a = pts_[T.v[next(i)]];
      const Point<2>& b = pts_[T.v[prev(i)]];
      if (orient2d(a, b, x) >= 0) continue;
      if (exit < 0) {
        exit = i;
        continue;
      }
      // Two edges face x: leave through the one whose smaller end is smaller.
      const auto key = [&](int e) {
        const Point<2>& u = pts_[T.v[next(e)]];
        const Point<2>& w = pts_[T.v[prev(e)]];
        return xy_less(u, w) ? std::pair{u, w} : std::pair{w, u};
      };
      const auto ki = key(i), ke = key(exit);
      if (xy_less(ki.first, ke.first) || (ki.first == ke.first && xy_less(ki.second, ke.second))) exit = i;
    }
    if (exit < 0) return Walk{t, -1};
    if (T.n[exit] == kNone) return Walk{t, exit};
    t = T.n[exit];
  }
  throw InvariantError("dynmesh: Delaunay walk did not end");
}

std::optional<Delaunay::Vid> Delaunay::vertex_at(Tid t, const Point<2>& x) const noexcept {
  for (Vid v : tris_[t].v)
    if (pts_[v] == x) return v;
  return std::nullopt;
}

bool Delaunay::in_conflict(Tid t, const Point<2>& x) const noexcept {
  const Tri& T = tris_[t];
  return perturbed_incircle(pts_[T.v[0]], pts_[T.v[1]], pts_[T.v[2]], x);
}

void Delaunay::cavity(Tid t, const Point<2>& x, std::vector<Tid>& out) const {
  if (++epoch_ == 0) {  // wrapped: no stale mark may equal the new epoch
    for (const Tri& T : tris_) T.mark = 0;
    epoch_ = 1;
  }
  out.clear();
  out.push_back(t);
  tris_[t].mark = epoch_;
  // Breadth first; members are marked with the epoch, so each test is O(1) (cavities of
  // nearly collinear points can hold thousands of slivers).
  for (std::size_t i = 0; i < out.size(); ++i) {
    for (Tid u : tris_[out[i]].n) {
      if (u == kNone || tris_[u].mark == epoch_) continue;
      if (in_conflict(u, x)) {
        tris_[u].mark = epoch_;
        out.push_back(u);
      }
    }
  }
}

void Delaunay::cavity_box_edges(std::span<const Tid> cav, std::vector<std::array<Vid, 2>>& out) const {
  out.clear();
  for (Tid t : cav) {
    const Tri& T = tris_[t];
    for (int i = 0; i < 3; ++i)
      if (T.n[i] == kNone) out.push_back({T.v[next(i)], T.v[prev(i)]});
  }
}

Delaunay::Vid Delaunay::insert(const Point<2>& x, std::span<const Tid> cav, std::vector<Tid>& created) {
  const Vid xv = static_cast<Vid>(pts_.size());
  pts_.push_back(x);
  max_cavity_ = std::max(max_cavity_, cav.size());
  const auto in_cavity = [&](Tid u) { return tris_[u].mark == epoch_; };
  if (first_of_.size() < pts_.size()) {
    first_of_.resize(pts_.size() + pts_.size() / 2, kNone);
    second_of_.resize(first_of_.size(), kNone);
  }
  const std::size_t first_new = created.size();
  // The boundary edges first, read before any slot is reused.
  std::vector<Edge>& edges = edges_;
  edges.clear();
  for (Tid t : cav) {
    const Tri& T = tris_[t];
    for (int i = 0; i < 3; ++i)
      if (T.n[i] == kNone || !in_cavity(T.n[i])) edges.push_back({T.v[next(i)], T.v[prev(i)], T.n[i]});
  }
  for (Tid t : cav) {
    tris_[t].alive = false;
    free_.push_back(t);
    --live_;
  }
  for (const Edge& e : edges) {
    // x on a box side: the side's edge through x is not fanned (it would be flat); its two
    // halves become box edges of the neighbouring new triangles.
    if (orient2d(pts_[e.a], pts_[e.b], x) <= 0) continue;
    const Tid t = new_tri(e.a, e.b, xv);
    tris_[t].n[2] = e.outside;
    if (e.outside != kNone) {
      Tri& O = tris_[e.outside];
      for (int j = 0; j < 3; ++j)
        if (O.v[next(j)] == e.b && O.v[prev(j)] == e.a) O.n[j] = t;
    }
    first_of_[e.a] = t;
    second_of_[e.b] = t;
    created.push_back(t);
  }
  for (std::size_t i = first_new; i < created.size(); ++i) {
    Tri& T = tris_[created[i]];
    T.n[0] = first_of_[T.v[1]];   // edge b→x: the new triangle starting at b (kNone: a box side)
    T.n[1] = second_of_[T.v[0]];  // edge x→a: the new triangle ending at a
  }
  for (std::size_t i = first_new; i < created.size(); ++i) {  // leave the scratch all kNone
    first_of_[tris_[created[i]].v[0]] = kNone;
    second_of_[tris_[created[i]].v[1]] = kNone;
  }
  return xv;
}

std::optional<Delaunay::Vid> Delaunay::insert(const Point<2>& x, Tid hint, std::vector<Tid>& created) {
  const Walk w = walk(hint, x);
  if (w.exit_edge >= 0) throw InvariantError("dynmesh: Delaunay insertion outside the box");
  if (vertex_at(w.t, x)) return std::nullopt;
  cavity(w.t, x, cavity_);
  return insert(x, cavity_, created);
}

std::optional<std::pair<Delaunay::Tid, int>> Delaunay::box_edge_of(Tid t, Vid a, Vid b) const noexcept {
  const Tri& T = tris_[t];
  for (int i = 0; i < 3; ++i)
    if (T.n[i] == kNone && T.v[next(i)] == a && T.v[prev(i)] == b) return std::pair{t, i};
  return std::nullopt;
}

std::vector<Triangle> Delaunay::triangles() const {
  // Sorted as std::sort of the canonical triangles would (Triangle's <=>, which is the
  // (x, y) order of v[0], then v[1], then v[2]), but through the vertices' ranks in (x, y)
  // order: the points are distinct, so ranks compare as the corners do. Sorting the 16-byte
  // vertices once and bucketing the triangles by their smallest corner is cheaper than
  // sorting the 48-byte triangles (bench/RESULTS.md, "The in-circle filter's subnormal room").
  const std::size_t nv = pts_.size();
  std::vector<std::pair<Point<2>, Vid>> by_xy(nv);
  for (Vid v = 0; v < nv; ++v) by_xy[v] = {pts_[v], v};
  std::sort(by_xy.begin(), by_xy.end(),
            [](const auto& a, const auto& b) { return xy_less(a.first, b.first); });
  std::vector<Vid> rank(nv);
  for (Vid r = 0; r < nv; ++r) rank[by_xy[r].second] = r;
  // Each live triangle as its corners' ranks, rotated to start at the smallest (the
  // rotation keeps the counter-clockwise order, as canonical_triangle's does).
  std::vector<std::array<Vid, 3>> keys;
  keys.reserve(live_);
  std::vector<Vid> start(nv + 1, 0);  // counts by smallest corner, then bucket starts
  for (const Tri& T : tris_) {
    if (!T.alive) continue;
    std::array<Vid, 3> r{rank[T.v[0]], rank[T.v[1]], rank[T.v[2]]};
    const int lo = r[1] < r[0] ? (r[2] < r[1] ? 2 : 1) : (r[2] < r[0] ? 2 : 0);
    std::rotate(r.begin(), r.begin() + lo, r.end());
    keys.push_back(r);
    ++start[r[0] + 1];
  }
  for (std::size_t i = 0; i < nv; ++i) start[i + 1] += start[i];
  std::vector<std::array<Vid, 3>> sorted(keys.size());
  for (const auto& k : keys) sorted[start[k[0]]++] = k;
  // A bucket holds the few triangles of one smallest corner: insertion sort by the rest.
  for (std::size_t b = 0, i = 0; b < nv; ++b) {
    const std::size_t end = start[b];  // now the bucket's end
    for (std::size_t k = i + 1; k < end; ++k)
      for (std::size_t m = k; m > i && sorted[m] < sorted[m - 1]; --m) std::swap(sorted[m], sorted[m - 1]);
    i = end;
  }
  std::vector<Triangle> out(sorted.size());
  for (std::size_t i = 0; i < sorted.size(); ++i)
    out[i] = Triangle{{by_xy[sorted[i][0]].first, by_xy[sorted[i][1]].first, by_xy[sorted[i][2]].first}};
  return out;
}

void Delaunay::check_invariants() const {
  const auto fail = [](const std::string& what) { throw InvariantError("dynmesh: Delaunay: " + what); };
  const auto on_side = [&](const Point<2>& a, const Point<2>& b) {
    return (a[0] == b[0] && (a[0] == box_.origin[0] || a[0] == hi_[0])) ||
           (a[1] == b[1] && (a[1] == box_.origin[1] || a[1] == hi_[1]));
  };
  std::size_t live = 0;
  for (Tid t = 0; t < tris_.size(); ++t) {
    const Tri& T = tris_[t];
    if (!T.alive) continue;
    ++live;
    if (orient2d(pts_[T.v[0]], pts_[T.v[1]], pts_[T.v[2]]) <= 0) fail("triangle " + std::to_string(t) + " is not ccw");
    for (int i = 0; i < 3; ++i) {
      const Vid a = T.v[next(i)], b = T.v[prev(i)];
      if (T.n[i] == kNone) {
        if (!on_side(pts_[a], pts_[b])) fail("an edge without a neighbour is not on a box side");
        continue;
      }
      const Tri& U = tris_[T.n[i]];
      if (!U.alive) fail("neighbour link to a dead triangle");
      int j = -1;
      for (int k = 0; k < 3; ++k)
        if (U.v[next(k)] == b && U.v[prev(k)] == a) j = k;
      if (j < 0 || U.n[j] != t) fail("neighbour links are not mutual");
      if (perturbed_incircle(pts_[T.v[0]], pts_[T.v[1]], pts_[T.v[2]], pts_[U.v[j]]))
        fail("not locally Delaunay across an edge");
    }
  }
  if (live != live_) fail("live count is off");
  std::size_t h = 0;
  for (const Point<2>& p : pts_)
    if (p[0] == box_.origin[0] || p[0] == hi_[0] || p[1] == box_.origin[1] || p[1] == hi_[1]) ++h;
  if (live_ + h + 2 != 2 * pts_.size()) fail("Euler's formula fails: the triangles do not tile the box");
}

}  // namespace dynmesh::detail
