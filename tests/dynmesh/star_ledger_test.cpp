// star_ledger_test.cpp — src/hpu/star_ledger.hpp: a walk holds the triangles it met, an
// insertion inside their circles drops them, a gap's certificate answers caps up to its own;
// and the cell refiner's maintained-stars count leaves the mesh alone, with each count a
// part of its whole.
#include "hpu/star_ledger.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <set>
#include <vector>

#include "dynamic_test_support.hpp"
#include "dynmesh/distributions.hpp"
#include "hpu/cell_refiner.hpp"

namespace {

using namespace dynmesh;
using detail::StarLedger;
using dynmesh_test::kSanitized;
constexpr int kNoCap = StarLedger::kNoCap;  // every triangle

/// The unit box's corners as vertices 0-3 (counter-clockwise from the origin) and its
/// centre as vertex 4, whose star is the four corners.
StarLedger centre_of_the_box() {
  StarLedger ledger(Box<2>{{0, 0}, 1});
  const Point<2> corners[] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (StarLedger::Vid v = 0; v < 4; ++v) ledger.add(v, corners[v], StarLedger::kNone);
  ledger.add(4, {0.5, 0.5}, StarLedger::kNone);
  ledger.check_invariants();
  return ledger;
}

TEST(StarLedger, AWalkHoldsItsTrianglesUntilAnInsertionInTheirCirclesDropsThem) {
  StarLedger ledger = centre_of_the_box();
  std::size_t needed = 0, unheld = 0;
  EXPECT_FALSE(ledger.all_held(4, kNoCap, needed, unheld));
  EXPECT_EQ(needed, 4u);
  EXPECT_EQ(unheld, 4u);
  const std::vector<StarLedger::Vid> star{0, 1, 2, 3};
  EXPECT_FALSE(ledger.replays(4, star, true, true, kNoCap));
  ledger.walked(4, star, true, true, kNoCap);
  EXPECT_TRUE(ledger.replays(4, star, true, true, kNoCap));
  needed = unheld = 0;
  EXPECT_TRUE(ledger.all_held(4, kNoCap, needed, unheld));
  EXPECT_EQ(unheld, 0u);
  // A vertex near the bottom side lies in the circle of (4, 0, 1) only: the centre's other
  // three triangles stay held, and the two new ones at it are not.
  ledger.add(5, {0.5, 0.1}, 4);
  ledger.check_invariants();
  needed = unheld = 0;
  EXPECT_FALSE(ledger.all_held(4, kNoCap, needed, unheld));
  EXPECT_EQ(needed, 5u);
  EXPECT_EQ(unheld, 2u);
}

TEST(StarLedger, AGapsCertificateAnswersCapsUpToItsOwn) {
  // The centre's four triangles have circumradius 1/2 = 2^(−2+1), within cap −2. A walk
  // capped at −3 (circumradius up to 1/4) meets none of them: a run of one vertex, with both
  // ends at the same gap.
  StarLedger ledger = centre_of_the_box();
  const std::vector<StarLedger::Vid> run{0};
  ledger.walked(4, run, false, false, -3);
  EXPECT_TRUE(ledger.replays(4, run, false, false, -3));
  EXPECT_TRUE(ledger.replays(4, run, false, false, -4));
  EXPECT_FALSE(ledger.replays(4, run, false, false, -2));  // beyond what the walk certified
  // A vertex inside the gap's triangles makes new ones, which carry no certificate.
  ledger.add(5, {0.5, 0.2}, 4);
  EXPECT_FALSE(ledger.replays(4, run, false, false, -4));
}

TEST(StarLedger, TheMaintainedStarsCountLeavesTheMeshAloneAndCountsPartsOfWholes) {
  for (const Distribution dist : {Distribution::Uniform, Distribution::Curves}) {
    const auto pts = generate<2>(dist, kSanitized ? 100 : 600, 3);
    const Box<2> box = derive_box<2>(pts);
    const auto plain = detail::cell_refine(box, pts, 20.7);
    // The ledger's shadow triangulation must be the refiner's mesh (check_mesh throws).
    const auto counted = detail::cell_refine(box, pts, 20.7, detail::CellRefineOptions{.maintained_stars = true});
    EXPECT_EQ(counted.triangles, plain.triangles);
    const detail::MaintainedStarStats& m = counted.maintained;
    EXPECT_EQ(m.collects, counted.stats.entries);
    EXPECT_LE(m.collect_asks + m.final_asks, counted.questions.neighbour_asks);
    // Some collects come after walks that met their whole neighbourhood, others not.
    EXPECT_GT(m.answered_design, 0u);
    EXPECT_LT(m.answered_design, m.collects);
    EXPECT_LE(m.answered_design_asks, m.collect_asks);
    EXPECT_LE(m.answered, m.collects);
    EXPECT_LE(m.unheld_triangles, m.needed_triangles);
    EXPECT_LE(m.births, m.collects);
    EXPECT_LE(m.births_design, m.births);
    std::set<std::array<double, 2>> vertices;
    for (const Triangle& t : counted.triangles)
      for (const Point<2>& p : t.v) vertices.insert({p[0], p[1]});
    EXPECT_EQ(m.finals, vertices.size());
    EXPECT_LE(m.answered_finals, m.finals);
    EXPECT_LE(m.whole_finals, m.answered_finals);
    EXPECT_EQ(plain.maintained.collects, 0u);  // counted only when asked
  }
}

}  // namespace
