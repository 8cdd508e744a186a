// star_ledger.hpp (private) — what stars kept up to date by the walks would answer: a
// measurement of the cell refiner (cell_refiner.hpp, CellRefineOptions::maintained_stars).
//
// Purpose: the design of stars held by the cells (docs/HPU_ON_CELLS.md, "Open") stores, for
// each vertex, the triangles at it that some walk has met, and keeps them up to date as
// vertices arrive: every walk writes the triangles it meets into the stars of their three
// corners, and an insertion removes the triangles whose circles hold the new vertex. A
// collect then needs no left search when its walk can be replayed from what is held. The
// ledger follows that design beside the refiner, without changing a question:
//   - a shadow Delaunay triangulation (geometry/delaunay.hpp) of the same vertices, inserted
//     in the refiner's order, tells which triangles are alive;
//   - a triangle is *held* once a walk has met it while it was alive (a collect's or a
//     final walk's actual runs): the walk writes it into the stars of its three corners,
//     and the insertion of a vertex inside its circle removes it;
//   - a walk that stops at its cap leaves a *certificate* on the triangle there: its
//     circumradius exceeds that cap (a triangle's certificates die with it). Caps are the
//     continuation rule's classes, sized by its own test (circumradius_above);
//   - a collect is answered *by the design* when its walk's runs are held and each run
//     ends at a box side or at a triangle that is held (its circle is known) or certified
//     for at least the collect's cap: a held star then replays the walk. It is answered
//     *by the oracle* when every triangle at its vertex within its cap is held: what the
//     shadow triangulation knows, an upper bound.
// Invariants (check_invariants()): the shadow triangulation's, each refiner vertex is the
// shadow vertex at its point, and every triangle slot has a held flag and certificates;
// check_mesh() compares the shadow's triangles with the refiner's mesh.
// Complexity: each insertion the shadow triangulation's (O(1) expected near its hint); each
// collect and final walk a star of the shadow triangulation. A measurement: off unless asked
// for.
// Paper: Acar & Hudson, Figure 5 (the collects); docs/HPU_ON_CELLS.md, "A vertex's star".
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"
#include "geometry/delaunay.hpp"
#include "hpu/hpu_geometry.hpp"  // circumradius_above, kGoOnReach

namespace dynmesh::detail {

/// The ledger's counts (CellRefinement::maintained).
struct MaintainedStarStats {
  std::size_t collects = 0, collect_asks = 0;  // every collect, and its left searches
  // Those whose triangles within the cap were all held (what the shadow triangulation
  // knows: an upper bound), and those a held star can answer knowing only what walks left
  // (the walk's runs held, and at each gap a held triangle or a certificate of the cap).
  std::size_t answered = 0, answered_asks = 0;
  std::size_t answered_design = 0, answered_design_asks = 0;
  std::size_t needed_triangles = 0, unheld_triangles = 0;  // triangles within their caps, and not held
  // Of those, the first collects of vertices the refinement inserted, and those replayed.
  std::size_t births = 0, birth_asks = 0, births_design = 0, births_design_asks = 0;
  // Final walks whose emitted triangles were all held, and those whose whole star was.
  std::size_t finals = 0, final_asks = 0, answered_finals = 0, answered_final_asks = 0;
  std::size_t whole_finals = 0, whole_final_asks = 0;
};

class StarLedger {
 public:
  using Vid = std::uint32_t;

  explicit StarLedger(const Box<2>& box)
      : dt_(box), held_(dt_.num_slots(), 0), certs_(dt_.num_slots(), kNoCerts) {}

  static constexpr Vid kNone = Delaunay::kNone;

  /// Vertex v (the refiner's number, given in order 0, 1, ...) at p arrives; `near`: a
  /// vertex of the refiner close to p (a locating hint), or kNone.
  void add(Vid v, const Point<2>& p, Vid near) {
    if (v != to_dt_.size()) throw InvariantError("dynmesh: star ledger: vertices out of order");
    created_.clear();
    point_.push_back(p);
    // A live triangle near p: one at `near`, else at the vertex added last.
    const Tid hint = near != kNone ? dt_.incident(to_dt_[near]) : to_dt_.empty() ? dt_.any_live() : dt_.incident(to_dt_.back());
    if (const auto dv = dt_.insert(p, hint, created_)) {
      to_dt_.push_back(*dv);
    } else {  // a box corner: the shadow triangulation starts with them
      Vid found = kNone;
      for (Vid k = 0; k < 4; ++k)
        if (dt_.point(k) == p) found = k;
      if (found == kNone) throw InvariantError("dynmesh: star ledger: a vertex added twice");
      to_dt_.push_back(found);
    }
    held_.resize(dt_.num_slots(), 0);
    certs_.resize(dt_.num_slots(), kNoCerts);
    for (const Tid t : created_) held_[t] = 0, certs_[t] = kNoCerts;  // new triangles in reused slots
  }

  /// Caps are classes, as the continuation rule's: cap c means circumradius up to 2^(c+1)
  /// (circumradius_above, hpu_geometry.hpp); a collect of class j walks with cap
  /// j + kGoOnReach. kNoCap: every triangle.
  static constexpr int kNoCap = 4000;
  static constexpr int kNoCert = -4000;

  /// Are all triangles at v within cap c held? Counts them into `needed` and the unheld
  /// ones into `unheld`. `emitted`: only those v emits in the final mesh (v is their (x,
  /// y)-smallest corner), whatever their size.
  bool all_held(Vid v, int c, std::size_t& needed, std::size_t& unheld, bool emitted = false) {
    const Vid dv = to_dt_[v];
    dt_.star(dv, nb_, left_);
    bool all = true;
    for (const Tid t : left_) {
      if (t == kNone) continue;
      if (emitted) {
        const Point<2>& p = dt_.point(dv);
        const auto& T = dt_.tri(t);
        bool smallest = true;
        for (const Vid w : T.v)
          if (w != dv && !xy_less(p, dt_.point(w))) smallest = false;
        if (!smallest) continue;
      } else if (beyond(t, c)) {
        continue;
      }
      ++needed;
      if (!held_[t]) ++unheld, all = false;
    }
    return all;
  }

  /// Could a held star replay the walk of v with cap c whose runs are `star` (as
  /// CellQuestions::star() leaves them; `whole`: no gap; `closed`: an interior vertex's
  /// whole cycle)? Its triangles must be held, and each end at a gap held or certified.
  bool replays(Vid v, const std::vector<Vid>& star, bool whole, bool closed, int c) const {
    bool all = true;
    for_each_walked(v, star, whole, closed, [&](Tid t) { all = all && held_[t]; },
                    [&](Tid t, int k) { all = all && (held_[t] || certs_[t][k] >= c); });
    return all;
  }

  /// The walk of v with cap c whose runs are `star` (see replays()): its triangles become
  /// held, and the triangles at its gap ends certified.
  void walked(Vid v, const std::vector<Vid>& star, bool whole, bool closed, int c) {
    for_each_walked(v, star, whole, closed, [&](Tid t) { held_[t] = 1; },
                    [&](Tid t, int k) { certs_[t][k] = std::max(certs_[t][k], c); });
  }

  /// The final walk of v met the triangles (v, a, b) of `tris`: they become held.
  void walked_triangles(Vid v, const std::vector<std::array<Vid, 2>>& tris) {
    for (const auto& [a, b] : tris) held_[triangle(to_dt_[v], to_dt_[a], to_dt_[b])] = 1;
  }

  /// The shadow triangulation's invariants, and a held flag and certificates for each of
  /// its triangle slots; throws InvariantError.
  void check_invariants() const {
    dt_.check_invariants();
    if (held_.size() != dt_.num_slots() || certs_.size() != dt_.num_slots())
      throw InvariantError("dynmesh: star ledger: the held flags do not cover the triangle slots");
    for (std::size_t v = 0; v < to_dt_.size(); ++v)
      if (to_dt_[v] >= dt_.num_vertices() || dt_.point(to_dt_[v]) != point_[v])
        throw InvariantError("dynmesh: star ledger: vertex " + std::to_string(v) + " is not where it was added");
  }

  /// Throws InvariantError unless the shadow triangulation is `mesh` (canonical, sorted).
  void check_mesh(const std::vector<Triangle>& mesh) const {
    if (dt_.triangles() != mesh) throw InvariantError("dynmesh: star ledger: the shadow triangulation differs from the mesh");
  }

 private:
  using Tid = Delaunay::Tid;
  static constexpr std::array<int, 3> kNoCerts{kNoCert, kNoCert, kNoCert};

  /// Is t's circumradius above cap c? The continuation rule's own test, so that the ledger
  /// sizes triangles as the refinement does.
  bool beyond(Tid t, int c) const {
    const auto& T = dt_.tri(t);
    return circumradius_above(dt_.point(T.v[0]), dt_.point(T.v[1]), dt_.point(T.v[2]), c);
  }
  /// The live triangle (v, a, b), counter-clockwise.
  Tid triangle(Vid v, Vid a, Vid b) const {
    const auto e = dt_.left_of(v, a);
    if (!e || dt_.tri(e->first).v[static_cast<std::size_t>(e->second)] != b)
      throw InvariantError("dynmesh: star ledger: a walked triangle the shadow triangulation lacks");
    return e->first;
  }
  /// Calls on_run(t) for each triangle t of the walk's runs, and on_end(t, k) for the
  /// triangle t at each gap end, k the walk's vertex's corner number in t.
  template <class Run, class End>
  void for_each_walked(Vid v, const std::vector<Vid>& star, bool whole, bool closed, Run on_run, End on_end) const {
    const Vid dv = to_dt_[v];
    const std::size_t d = star.size();
    for (std::size_t i = 0; i + 1 < d || (closed && d > 2 && i < d); ++i)
      on_run(triangle(dv, to_dt_[star[i]], to_dt_[star[(i + 1) % d]]));
    if (whole || d == 0) return;
    for (const auto& e : {dt_.left_of(dv, to_dt_[star.back()]), dt_.left_of(to_dt_[star.front()], dv)}) {
      if (!e) continue;
      const auto& T = dt_.tri(e->first);
      for (int k = 0; k < 3; ++k)
        if (T.v[static_cast<std::size_t>(k)] == dv) on_end(e->first, k);
    }
  }

  Delaunay dt_;
  std::vector<Vid> to_dt_;          // the refiner's vertex → the shadow triangulation's
  std::vector<Point<2>> point_;     // the refiner's vertex → where it was added
  std::vector<std::uint8_t> held_;  // by triangle slot: met by a walk since it was made
  // By triangle slot and corner: the largest cap that corner's walks certified the triangle
  // beyond (kNoCert: none).
  std::vector<std::array<int, 3>> certs_;
  std::vector<Tid> created_, left_;
  std::vector<Vid> nb_;
};

}  // namespace dynmesh::detail
