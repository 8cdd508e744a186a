// sacapps/quickhull.hpp — self-adjusting convex hull (quickhull) of a list of points.
//
// Purpose: out = the convex hull of the input points, as a list of its vertices in
// counter-clockwise order starting from the lowest (then leftmost) point, kept up to date as
// points are inserted, deleted or moved. The classic quickhull over lists:
//
//   hull(S)          = lo :: chain(lo, hi, S) ++ hi :: chain(hi, lo, S)
//                      where lo, hi = the lowest and the highest point (reductions of S)
//   chain(a, b, S)   = let B = [p in S | p strictly right of a->b]          (a filter)
//                      in B empty -> []
//                         else    -> let f = the farthest point of B from a->b  (a reduction)
//                                    in chain(a, f, B) ++ f :: chain(f, b, B)
//
// written in destination-passing style (chain also takes the cell that follows its output).
// The reductions are the random list contractions of sacapps/contraction.hpp, so a changed
// point costs O(log n) in each reduction it takes part in, not O(n) as a left fold would.
//
// Output conventions: points strictly on a hull edge are not vertices; equal points count
// once (the one with the smaller id); a set of equal points has a one-point hull; collinear
// points give the two end points. Decisions use the floating-point predicates of
// sacapps/geometry.hpp, shared with the conventional twin, so both produce the same list.
//
// Invariants: an edge's node (its filtered list and farthest point) is keyed by the ids of
// its end points, filter cells by (element id, edge), a hull vertex's output cell by its id;
// every value in a memo key is a Site (point and id), never an address of a copy; so a
// re-execution finds the old trace of every edge whose end points and candidates did not
// change.
// Complexity: from scratch, each level of the recursion filters and reduces the points that
// are still outside the current polygon: O(n) for the first levels, O(n h) in the worst case
// (h = hull size). A point
// inserted or deleted inside the hull costs O(1) filter steps and one O(log n) reduction
// update per level of the recursion it survives (O(1) levels expected for random points),
// plus the two extreme-point reductions: O(log n) expected. A change of the hull itself also
// rebuilds the recursion below the changed edge.
//
// Follows Acar, Blelloch, Blume, Harper, Tangwongsan, "An experimental analysis of
// self-adjusting computation" (TOPLAS 2009), "quickhull", and the CEAL benchmark of Hammer,
// Acar, Chen (PLDI 2009).
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include <sac/sac.hpp>

#include "sacapps/geometry.hpp"
#include "sacapps/input_list_app.hpp"
#include "sacapps/list.hpp"

namespace sacapps::quickhull {

using PointCell = Cell<Point>;
using PointList = List<Point>;

inline Site site(const PointCell& c) { return Site{c.value, c.id}; }

/// Self-adjusting quickhull (call inside the computation): writes into *dst the hull of `in`.
void quickhull(sac::Engine& rt, const PointList& in, PointList* dst);

/// Conventional twin: the same recursion on vectors.
std::vector<Site> quickhull_conventional(const std::vector<Site>& points);

/// How the generated points are distributed.
enum class Distribution {
  Square,  // uniform in the unit square: hulls of O(log n) vertices
  Disk,    // uniform in the unit disk: hulls of O(n^(1/3)) vertices
};

/// The App adapter shared by quickhull and diameter: input = a list of points drawn from the
/// distribution; keeps the current input as a vector of Sites for the conventional twin.
class PointApp : public InputListApp<Point> {
 public:
  explicit PointApp(Distribution d) : distribution_(d) {}

 protected:
  Point draw(std::uint64_t seed) const override;
  void input_changed() override { plain_valid_ = false; }
  /// The current input for the conventional twin (rebuilt after changes, outside the timed
  /// run when the caller follows the suite's protocol).
  const std::vector<Site>& plain_input();

  Distribution distribution_;

 private:
  std::vector<Site> plain_;
  bool plain_valid_ = false;
};

class QuickhullApp final : public PointApp {
 public:
  explicit QuickhullApp(Distribution d = Distribution::Square) : PointApp(d) {}
  std::string_view name() const override { return "quickhull"; }
  std::unique_ptr<App> clone_current() const override;
  void run_conventional() override;
  void run_self_adjusting() override;
  bool verify() override;

  /// The hull (after run_self_adjusting()).
  const PointList& output() const { return *out_; }

 protected:
  void reset_outputs() override { out_.reset(); }

 private:
  std::unique_ptr<PointList> out_;
  std::vector<Site> conventional_;
};

}  // namespace sacapps::quickhull
