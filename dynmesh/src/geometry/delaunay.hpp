// delaunay.hpp (private) — the Delaunay triangulation of points in a box, built by insertion.
//
// Purpose: the triangulation DynHPU's static twin refines (hpu_mesh.cpp). It starts as the
// box's two triangles and grows by Bowyer–Watson insertion: locate the point by a visibility
// walk, collect the triangles whose circumcircle holds it (the cavity), and fan the cavity's
// boundary from it. A point on a side of the box splits that side's edge. Callers may look
// at the cavity before committing (the refinement refuses candidates that encroach a side).
//
// Degeneracy: cocircular points get one answer through a symbolic perturbation of the lifted
// points (each point lifted by ε^rank, rank its (x, y) order, the largest perturbed most), so
// the triangulation is unique: a function of the point set, whatever the insertion order.
// That is what lets a mesh be a function of the point set. Derivation: with z_i lifted by
// ε_i, the in-circle determinant of (a, b, c, d) gains Σ ε_i·C_i with C_d = −orient(a, b, c),
// C_a = orient(d, b, c), C_b = orient(a, d, c), C_c = orient(a, b, d); the first non-zero C_i
// in decreasing rank decides. C_d ≠ 0 for a real triangle, so the test always decides.
//
// Invariants (check_invariants()): every live triangle is strictly counter-clockwise and its
// neighbour links are mutual, across the same edge; an edge without a neighbour lies on a
// side of the box; no vertex is strictly inside the (perturbed) circumcircle of a triangle
// across an edge from it (locally Delaunay, hence Delaunay); t = 2v − h − 2 for v vertices,
// h of them on the box's sides (Euler's formula for a triangulated convex polygon).
// Complexity: insert O(walk + cavity): O(1) expected for points inserted in spatial order or
// near their hint; check_invariants O(t).
// Paper: Bowyer (1981), Watson (1981); Edelsbrunner & Mücke, "Simulation of simplicity"
// (1990) and Devillers & Teillaud (2011) for the lifted perturbation; Guibas & Stolfi for
// the walk's termination in a Delaunay triangulation.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh::detail {

class Delaunay {
 public:
  using Vid = std::uint32_t;
  using Tid = std::uint32_t;
  static constexpr std::uint32_t kNone = 0xffff'ffffu;

  // 32 bytes, aligned: a star or a walk loads one cache line per triangle, never two.
  struct alignas(32) Tri {
    std::array<Vid, 3> v;  // counter-clockwise
    std::array<Tid, 3> n;  // n[i]: the triangle across the edge opposite v[i] (kNone: a box side)
    mutable std::uint32_t mark = 0;  // == the epoch of the cavity that holds it
    bool alive = false;
  };
  static_assert(sizeof(Tri) == 32);

  /// Where a walk towards x ended.
  struct Walk {
    Tid t = kNone;
    int exit_edge = -1;  // ≥ 0: x lies beyond this box-side edge of t (outside the box)
  };

  /// The box's four corners and two triangles.
  explicit Delaunay(const Box<2>& box);

  const Point<2>& point(Vid v) const noexcept { return pts_[v]; }
  std::size_t num_vertices() const noexcept { return pts_.size(); }
  const Tri& tri(Tid t) const noexcept { return tris_[t]; }
  std::size_t num_slots() const noexcept { return tris_.size(); }
  std::size_t num_live() const noexcept { return live_; }
  /// Triangles made since construction (the work of all insertions).
  std::size_t num_made() const noexcept { return made_; }
  /// The largest cavity an insertion has replaced (the quadratic risk of degenerate input).
  std::size_t max_cavity() const noexcept { return max_cavity_; }
  /// Any live triangle (a walk's default start).
  Tid any_live() const noexcept;
  /// A live triangle with corner v.
  Tid incident(Vid v) const noexcept { return vtri_[v]; }

  /// The neighbours of v in counter-clockwise order (a cycle for an interior vertex; from
  /// one box side to the other for a vertex on the boundary).
  void star(Vid v, std::vector<Vid>& out) const { star(v, out, nullptr); }
  /// star(), and in `left` the triangle on the left of v→out[i] for each i (kNone: the
  /// outside of the box, for a boundary vertex's last neighbour).
  void star(Vid v, std::vector<Vid>& out, std::vector<Tid>& left) const { star(v, out, &left); }
  /// The stars of several vertices at once (at most kStarsAtOnce): star(vs[i], out[i],
  /// left[i]) for each i. A star walk is a chain of dependent loads, one cache miss per
  /// triangle; these walks advance in turn, so that their misses overlap.
  static constexpr std::size_t kStarsAtOnce = 16;
  void stars(std::span<const Vid> vs, std::span<std::vector<Vid>> out, std::span<std::vector<Tid>> left) const;
  /// The live triangle with the directed edge p→q (q follows p counter-clockwise in it),
  /// and the index of its third corner; nullopt when p→q is not an edge or the outside of
  /// the box lies on its left.
  std::optional<std::pair<Tid, int>> left_of(Vid p, Vid q) const noexcept;
  /// left_of(p, q), answered by `hint` when that is a live triangle holding p→q (the one
  /// triangle that can: so any hint, stale or not, gives left_of's answer).
  std::optional<std::pair<Tid, int>> left_of(Vid p, Vid q, Tid hint) const noexcept;

  /// Walks from `start` (live) towards x: the triangle holding x in its closure, or the box
  /// side crossed when x is outside the box. Deterministic for a given triangulation: at each
  /// step it leaves through the edge x is strictly beyond whose vertex pair is smallest in
  /// (x, y) order, so the walk does not depend on how the triangles were stored.
  Walk walk(Tid start, const Point<2>& x) const;

  /// The vertex of t equal to x, if any.
  std::optional<Vid> vertex_at(Tid t, const Point<2>& x) const noexcept;

  /// The cavity of x (not a vertex) found from t, which holds x in its closure: the live
  /// triangles whose perturbed circumcircle contains x, in a deterministic order.
  void cavity(Tid t, const Point<2>& x, std::vector<Tid>& out) const;

  /// The cavity's boundary edges that lie on a box side, as (a, b) vertex pairs.
  void cavity_box_edges(std::span<const Tid> cavity, std::vector<std::array<Vid, 2>>& out) const;

  /// Inserts x (in the closed box, not a vertex) whose cavity is `cavity`, the result of the
  /// last cavity() call (its members are marked); appends the new triangles to `created` and
  /// returns x's vertex.
  Vid insert(const Point<2>& x, std::span<const Tid> cavity, std::vector<Tid>& created);

  /// Locates and inserts x; nullopt (nothing changes) when x is already a vertex.
  std::optional<Vid> insert(const Point<2>& x, Tid hint, std::vector<Tid>& created);

  /// The edge (a, b) of the box boundary as a triangle and edge index, or nullopt.
  std::optional<std::pair<Tid, int>> box_edge_of(Tid t, Vid a, Vid b) const noexcept;

  /// Perturbed in-circle: true when x is inside the circumcircle of live triangle t.
  bool in_conflict(Tid t, const Point<2>& x) const noexcept;

  /// The live triangles, canonical (for Mesh).
  std::vector<Triangle> triangles() const;

  /// Throws InvariantError naming the first broken rule (see the header).
  void check_invariants() const;

 private:
  Tid new_tri(Vid a, Vid b, Vid c);
  void star(Vid v, std::vector<Vid>& out, std::vector<Tid>* left) const;

  Box<2> box_;
  double hi_[2];  // fl(o + L) per axis: the box's far sides
  std::vector<Point<2>> pts_;
  std::vector<Tri> tris_;
  std::vector<Tid> free_;
  std::size_t live_ = 0;
  std::size_t made_ = 0;
  std::size_t max_cavity_ = 0;
  mutable std::uint32_t epoch_ = 0;  // the last cavity()'s mark
  // Scratch of insert(), kept so that an insertion allocates nothing: the cavity of the
  // locating insert(), the cavity's boundary edges, and by vertex the new triangle starting
  // or ending there (all kNone between calls).
  struct Edge {
    Vid a, b;
    Tid outside;
  };
  std::vector<Tid> cavity_;
  std::vector<Edge> edges_;
  std::vector<Tid> vtri_;  // by vertex: a live triangle with that corner
  std::vector<Tid> first_of_, second_of_;
};

/// The perturbed in-circle decision for counter-clockwise a, b, c: is d inside? (See the
/// header's derivation.) Exposed for the tests.
bool perturbed_incircle(const Point<2>& a, const Point<2>& b, const Point<2>& c, const Point<2>& d) noexcept;

}  // namespace dynmesh::detail
