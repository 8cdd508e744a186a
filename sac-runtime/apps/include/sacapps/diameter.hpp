// sacapps/diameter.hpp — self-adjusting diameter of a point set, and its twin.
//
// Purpose: out = the largest squared distance between two input points (0 for fewer than
// two), kept up to date as points are inserted, deleted or moved. The two farthest points
// are hull vertices, so:
//
//   diameter(S) = max over hull vertices v of (max over hull vertices w of |v - w|^2)
//
// on top of the self-adjusting quickhull (sacapps/quickhull.hpp): a map over the hull gives
// every vertex v an RCell whose value is the reduction "farthest distance from v" over the
// hull, and a last reduction takes the largest of those. All reductions are the random
// list contractions of sacapps/contraction.hpp. Squared distances are exact functions of the
// coordinates (geom::dist2, shared with the twin), and max is exact, so both agree bit for bit.
//
// Invariants: the per-vertex cell is keyed by the vertex's id; each per-vertex reduction is
// keyed by the vertex (a Site), so a hull vertex that stays keeps its reduction; the hull's
// output cells are stable (quickhull keys them by id), so an update that leaves the hull
// alone stops at quickhull's output (its writes are cut off as equal).
// Complexity: from scratch O(n log h + h^2) expected (h = hull size; O(log n) for points in a
// square, O(n^(1/3)) in a disk). An update inside the hull costs what quickhull's does; one
// that changes the hull also updates the h per-vertex reductions, O(h log h).
//
// Follows Acar, Blelloch, Blume, Harper, Tangwongsan, "An experimental analysis of
// self-adjusting computation" (TOPLAS 2009), "diameter", and the CEAL benchmark of Hammer,
// Acar, Chen (PLDI 2009).
#pragma once

#include <memory>
#include <string_view>
#include <vector>

#include <sac/sac.hpp>

#include "sacapps/geometry.hpp"
#include "sacapps/quickhull.hpp"

namespace sacapps::diameter {

/// Self-adjusting diameter (call inside the computation): writes into *dst the largest
/// squared distance between two points of `in`.
void diameter(sac::Engine& rt, const quickhull::PointList& in, sac::Mod<double>* dst);

/// Conventional twin: quickhull, then all pairs of hull vertices.
double diameter_conventional(const std::vector<Site>& points);

class DiameterApp final : public quickhull::PointApp {
 public:
  explicit DiameterApp(quickhull::Distribution d = quickhull::Distribution::Square) : PointApp(d) {}
  std::string_view name() const override { return "diameter"; }
  std::unique_ptr<App> clone_current() const override;
  void run_conventional() override;
  void run_self_adjusting() override;
  bool verify() override;

  /// The squared diameter (after run_self_adjusting()).
  const sac::Mod<double>& output() const { return *out_; }

 protected:
  void reset_outputs() override { out_.reset(); }

 private:
  std::unique_ptr<sac::Mod<double>> out_;
  double conventional_ = 0;
};

}  // namespace sacapps::diameter
