// geometry_test.cpp — point.hpp, box.hpp, cell.hpp, detail/cell_table.hpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/detail/cell_table.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"

namespace {

using namespace dynmesh;
using Kind = InputError::Kind;

template <class F>
Kind input_error_kind(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.kind();
  }
  ADD_FAILURE() << "no InputError thrown";
  return Kind::Io;
}

// --- derive_box ---------------------------------------------------------------------------------

TEST(DeriveBox, UnitSquare) {
  const std::vector<Point<2>> pts = {{0, 0}, {1, 1}, {0.5, 0.25}};
  const Box<2> box = derive_box<2>(pts);
  EXPECT_EQ(box.origin[0], -1.0);
  EXPECT_EQ(box.origin[1], -1.0);
  EXPECT_EQ(box.side, 3.0);
}

TEST(DeriveBox, WidestAxisDecides) {
  const std::vector<Point<2>> pts = {{0, 0}, {2, 1}};
  const Box<2> box = derive_box<2>(pts);  // w = 2
  EXPECT_EQ(box.origin[0], 1.0 - 3.0);
  EXPECT_EQ(box.origin[1], 0.5 - 3.0);
  EXPECT_EQ(box.side, 6.0);
}

TEST(DeriveBox, SinglePointUsesWidthOne) {
  const std::vector<Point<2>> pts = {{5, 7}};
  const Box<2> box = derive_box<2>(pts);
  EXPECT_EQ(box.origin[0], 3.5);
  EXPECT_EQ(box.origin[1], 5.5);
  EXPECT_EQ(box.side, 3.0);
}

TEST(DeriveBox, ThreeD) {
  const std::vector<Point<3>> pts = {{0, 0, 0}, {1, 2, 4}, {0.5, 1, 1}};
  const Box<3> box = derive_box<3>(pts);  // w = 4
  EXPECT_EQ(box.origin[0], -5.5);
  EXPECT_EQ(box.origin[1], -5.0);
  EXPECT_EQ(box.origin[2], -4.0);
  EXPECT_EQ(box.side, 12.0);
}

TEST(DeriveBox, IeeeExactlyAsWritten) {
  // x in [0.1, 0.7], y in [0.2, 0.3]: w = 0.7 − 0.1 = 0x1.3333333333333p-1 (0.6 rounded).
  // o_x = (0.1 + 0.7) / 2 − 1.5·w = -0x1.fffffffffffffp-2, whereas the algebraically equal
  // 0.1 + (0.7 − 0.1)/2 − 1.5·w would give -0x1.ffffffffffffep-2: the order matters.
  const std::vector<Point<2>> pts = {{0.1, 0.2}, {0.7, 0.3}};
  const Box<2> box = derive_box<2>(pts);
  EXPECT_EQ(box.origin[0], -0x1.fffffffffffffp-2);
  EXPECT_EQ(box.origin[1], -0x1.4ccccccccccccp-1);
  EXPECT_EQ(box.side, 0x1.cccccccccccccp+0);
  EXPECT_EQ(format_exact(box.origin[0]), "-0.49999999999999994");
  EXPECT_EQ(format_exact(box.origin[1]), "-0.64999999999999991");
  EXPECT_EQ(format_exact(box.side), "1.7999999999999998");
}

TEST(DeriveBox, InputPointsLieInTheMiddleThird) {
  std::mt19937_64 gen(7);
  std::uniform_real_distribution<double> u(-1e6, 1e6);
  for (int t = 0; t < 100; ++t) {
    std::vector<Point<3>> pts(20);
    for (auto& p : pts)
      for (auto& x : p) x = u(gen);
    const Box<3> box = derive_box<3>(pts);
    for (const auto& p : pts) {
      const auto q = try_locate(box, p);
      ASSERT_TRUE(q.has_value());
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE((*q)[static_cast<std::size_t>(a)], kResolution / 3 - 2);
        EXPECT_LE((*q)[static_cast<std::size_t>(a)], 2 * (kResolution / 3) + 2);
      }
    }
  }
}

TEST(DeriveBox, Errors) {
  EXPECT_EQ(input_error_kind([] { (void)derive_box<2>(std::vector<Point<2>>{}); }), Kind::Empty);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(input_error_kind([&] { (void)derive_box<2>(std::vector<Point<2>>{{0, 0}, {nan, 1}}); }), Kind::NotFinite);
  EXPECT_EQ(input_error_kind([&] { (void)derive_box<2>(std::vector<Point<2>>{{0, inf}}); }), Kind::NotFinite);
  // max − min overflows: the box would be infinite.
  EXPECT_EQ(input_error_kind([] { (void)derive_box<2>(std::vector<Point<2>>{{-1e308, 0}, {1e308, 0}}); }),
            Kind::OutsideBox);
  // w is the smallest subnormal: 2^52 / L overflows.
  EXPECT_EQ(input_error_kind([] { (void)derive_box<2>(std::vector<Point<2>>{{0, 0}, {5e-324, 0}}); }),
            Kind::OutsideBox);
}

// --- location -----------------------------------------------------------------------------------

TEST(Locate, UnitBoxEdges) {
  const Box<2> box{{0.0, 0.0}, 1.0};
  EXPECT_EQ(locate(box, Point<2>{0.0, 0.0}), (Position<2>{0, 0}));
  EXPECT_EQ(locate(box, Point<2>{-0.0, 0.5}), (Position<2>{0, std::uint64_t{1} << 51}));
  // The last representable position: the largest double below o + L.
  const double last = std::nextafter(1.0, 0.0);
  EXPECT_EQ(locate(box, Point<2>{last, last}), (Position<2>{kResolution - 1, kResolution - 1}));
  EXPECT_FALSE(try_locate(box, Point<2>{1.0, 0.5}).has_value());
  EXPECT_FALSE(try_locate(box, Point<2>{0.5, -std::numeric_limits<double>::denorm_min()}).has_value());
  EXPECT_FALSE(try_locate(box, Point<2>{std::numeric_limits<double>::quiet_NaN(), 0.5}).has_value());
  EXPECT_EQ(input_error_kind([&] { (void)locate(box, Point<2>{1.0, 0.5}); }), Kind::OutsideBox);
  EXPECT_EQ(input_error_kind([&] { (void)locate(box, Point<2>{std::numeric_limits<double>::infinity(), 0.5}); }),
            Kind::NotFinite);
  // The smallest positive coordinate lands in q = 0.
  EXPECT_EQ(locate(box, Point<2>{std::numeric_limits<double>::denorm_min(), 0.0}), (Position<2>{0, 0}));
}

TEST(Locate, RuleIsOneSubtractionOneMultiplicationOneFloor) {
  // L = 3: the factor 2^52/3 is rounded (to 1501199875790165.25); the rule uses the rounded
  // factor, so positions are floor((x − o) · fl(2^52/3)), not floor((x − o) · 2^52 / 3).
  const Box<2> box{{0.0, 0.0}, 3.0};
  EXPECT_EQ(box.scale(), 1501199875790165.25);
  const double last = std::nextafter(3.0, 0.0);
  EXPECT_EQ(locate(box, Point<2>{last, 0.0})[0], kResolution - 1);
  EXPECT_FALSE(try_locate(box, Point<2>{3.0, 0.0}).has_value());  // rounds to exactly 2^52
  // 1.0 maps to 1501199875790165.25 → 1501199875790165.
  EXPECT_EQ(locate(box, Point<2>{1.0, 0.0})[0], 1501199875790165u);
}

TEST(Locate, BoundaryMayRoundIntoTheLowerCell) {
  // W = 593738·2^-19 (the `boundary` distribution's extent): box o = −W, L = 3W. The level-1
  // boundary x = o + L/2 is an exact double, but fl(fl(L/2) · fl(2^52/L)) < 2^51, so the
  // rule places it at q = 2^51 − 1, in the lower level-1 cell.
  const double w = 593738.0 / 524288.0;
  const Box<2> box{{-w, -w}, 3.0 * w};
  const double mid = -w + 1.5 * w;
  const Position<2> q = locate(box, Point<2>{mid, -w});
  EXPECT_EQ(q[0], (std::uint64_t{1} << 51) - 1);
  EXPECT_EQ(q[1], 0u);
  EXPECT_EQ(cell_of(q, 1).index[0], 0u);
  // With L = 3 the same boundary rounds up onto the boundary (upper cell).
  const Box<2> three{{-1.0, -1.0}, 3.0};
  EXPECT_EQ(locate(three, Point<2>{0.5, -1.0})[0], std::uint64_t{1} << 51);
}

TEST(Locate, CellOfLevel) {
  const Box<3> box{{0, 0, 0}, 1.0};
  const Position<3> q = locate(box, Point<3>{0.75, 0.25, 0.5});
  EXPECT_EQ(cell_of(q, 0), CellId<3>::root());
  EXPECT_EQ(cell_of(q, 1), (CellId<3>{1, {1, 0, 1}}));
  EXPECT_EQ(cell_of(q, 2), (CellId<3>{2, {3, 1, 2}}));
  EXPECT_EQ(cell_of(q, kMaxLevel).index, q);
}

TEST(ValidateBox, RejectsUnusableBoxes) {
  EXPECT_NO_THROW(validate_box(Box<2>{{0, 0}, 1}));
  EXPECT_EQ(input_error_kind([] { validate_box(Box<2>{{0, 0}, 0}); }), Kind::OutsideBox);
  EXPECT_EQ(input_error_kind([] { validate_box(Box<2>{{0, 0}, -1}); }), Kind::OutsideBox);
  EXPECT_EQ(input_error_kind([] { validate_box(Box<2>{{std::numeric_limits<double>::quiet_NaN(), 0}, 1}); }),
            Kind::OutsideBox);
  EXPECT_EQ(input_error_kind([] { validate_box(Box<2>{{1e308, 0}, 1e308}); }), Kind::OutsideBox);
}

// --- cells ----------------------------------------------------------------------------------

TEST(Cell, TreeStructure) {
  const CellId<2> c{3, {5, 2}};
  EXPECT_TRUE(valid(c));
  EXPECT_FALSE(valid(CellId<2>{3, {8, 0}}));
  EXPECT_FALSE(valid(CellId<2>{53, {0, 0}}));
  EXPECT_EQ(parent(c), (CellId<2>{2, {2, 1}}));
  EXPECT_EQ(ancestor(c, 1), (CellId<2>{1, {1, 0}}));
  EXPECT_EQ(ancestor(c, 3), c);
  const auto ks = children(c);
  EXPECT_EQ(ks[0], (CellId<2>{4, {10, 4}}));
  EXPECT_EQ(ks[1], (CellId<2>{4, {11, 4}}));
  EXPECT_EQ(ks[2], (CellId<2>{4, {10, 5}}));
  EXPECT_EQ(ks[3], (CellId<2>{4, {11, 5}}));
  for (const auto& k : ks) {
    EXPECT_EQ(parent(k), c);
    EXPECT_TRUE(contains(c, k));
    EXPECT_FALSE(contains(k, c));
  }
  EXPECT_TRUE(contains(c, c));
  EXPECT_TRUE(contains(CellId<2>::root(), c));
  const Position<2> inside{(std::uint64_t{5} << 49) + 17, (std::uint64_t{2} << 49)};
  const Position<2> outside{(std::uint64_t{6} << 49), (std::uint64_t{2} << 49)};
  EXPECT_TRUE(contains(c, inside));
  EXPECT_FALSE(contains(c, outside));
  EXPECT_EQ(children(CellId<3>::root()).size(), 8u);
}

TEST(Cell, OrderIsLevelThenIndices) {
  std::vector<CellId<3>> cs = {{2, {0, 0, 1}}, {1, {1, 1, 1}}, {2, {0, 1, 0}}, {2, {1, 0, 0}}, {0, {0, 0, 0}}};
  std::sort(cs.begin(), cs.end());
  const std::vector<CellId<3>> want = {{0, {0, 0, 0}}, {1, {1, 1, 1}}, {2, {0, 0, 1}}, {2, {0, 1, 0}}, {2, {1, 0, 0}}};
  EXPECT_EQ(cs, want);
}

/// Closed boxes in units of 2^-6 (exact for levels ≤ 6): the geometric definition.
template <std::size_t d>
bool touches_geometric(const CellId<d>& a, const CellId<d>& b) {
  for (std::size_t k = 0; k < d; ++k) {
    const double alo = std::ldexp(static_cast<double>(a.index[k]), -a.level);
    const double ahi = std::ldexp(static_cast<double>(a.index[k] + 1), -a.level);
    const double blo = std::ldexp(static_cast<double>(b.index[k]), -b.level);
    const double bhi = std::ldexp(static_cast<double>(b.index[k] + 1), -b.level);
    if (std::max(alo, blo) > std::min(ahi, bhi)) return false;
  }
  return true;
}

template <std::size_t d>
std::vector<CellId<d>> all_cells(int level) {
  std::vector<CellId<d>> out;
  const std::uint64_t n = cells_per_axis(level);
  std::uint64_t total = 1;
  for (std::size_t a = 0; a < d; ++a) total *= n;
  for (std::uint64_t t = 0; t < total; ++t) {
    CellId<d> c;
    c.level = level;
    std::uint64_t r = t;
    for (std::size_t a = 0; a < d; ++a) {
      c.index[a] = r % n;
      r /= n;
    }
    out.push_back(c);
  }
  return out;
}

TEST(Cell, TouchesMatchesGeometry2D) {
  std::vector<CellId<2>> cells;
  for (int l = 0; l <= 4; ++l) {
    auto v = all_cells<2>(l);
    cells.insert(cells.end(), v.begin(), v.end());
  }
  for (const auto& a : cells)
    for (const auto& b : cells) ASSERT_EQ(touches(a, b), touches_geometric(a, b)) << to_string(a) << " " << to_string(b);
}

TEST(Cell, TouchesMatchesGeometry3D) {
  std::vector<CellId<3>> cells;
  for (int l = 0; l <= 3; ++l) {
    auto v = all_cells<3>(l);
    cells.insert(cells.end(), v.begin(), v.end());
  }
  for (const auto& a : cells)
    for (const auto& b : cells) ASSERT_EQ(touches(a, b), touches_geometric(a, b)) << to_string(a) << " " << to_string(b);
}

TEST(Cell, TouchesExamples) {
  EXPECT_TRUE(touches(CellId<2>{2, {1, 1}}, CellId<2>{2, {2, 2}}));   // vertex contact
  EXPECT_TRUE(touches(CellId<2>{2, {1, 1}}, CellId<2>{2, {2, 1}}));   // edge contact
  EXPECT_FALSE(touches(CellId<2>{2, {1, 1}}, CellId<2>{2, {3, 1}}));  // a gap of one cell
  EXPECT_TRUE(touches(CellId<2>{1, {0, 0}}, CellId<2>{4, {8, 8}}));   // corner of a small cell
  EXPECT_FALSE(touches(CellId<2>{1, {0, 0}}, CellId<2>{4, {9, 8}}));
  EXPECT_TRUE(touches(CellId<3>{1, {0, 0, 0}}, CellId<3>{1, {1, 1, 1}}));  // 3D vertex contact
  // Deep levels: the level-52 cells on either side of the level-1 boundary touch.
  EXPECT_TRUE(touches(CellId<2>{52, {(std::uint64_t{1} << 51) - 1, 0}}, CellId<2>{1, {1, 0}}));
  EXPECT_FALSE(touches(CellId<2>{52, {(std::uint64_t{1} << 51) - 2, 0}}, CellId<2>{1, {1, 0}}));
}

TEST(Cell, Neighbourhood) {
  EXPECT_EQ(neighbourhood(CellId<2>::root()).size(), 1);
  EXPECT_EQ(neighbourhood(CellId<2>{1, {0, 1}}).size(), 4);
  EXPECT_EQ(neighbourhood(CellId<3>{1, {0, 1, 1}}).size(), 8);
  EXPECT_EQ(neighbourhood(CellId<2>{3, {4, 5}}).size(), 9);
  EXPECT_EQ(neighbourhood(CellId<3>{3, {4, 5, 6}}).size(), 27);
  EXPECT_EQ(neighbourhood(CellId<2>{3, {0, 5}}).size(), 6);
  // N(c) = the same-level cells touching c, c included.
  for (int l = 0; l <= 3; ++l)
    for (const auto& c : all_cells<3>(l)) {
      std::vector<CellId<3>> want;
      for (const auto& x : all_cells<3>(l))
        if (touches(c, x)) want.push_back(x);
      std::sort(want.begin(), want.end());
      auto got = neighbourhood(c);
      std::vector<CellId<3>> have(got.begin(), got.end());
      std::sort(have.begin(), have.end());
      ASSERT_EQ(have, want) << to_string(c);
      EXPECT_NE(std::find(have.begin(), have.end(), c), have.end());
    }
}

TEST(Cell, CoarserTouchingIsExactlyTheTouchingParentLevelCells) {
  for (int l = 1; l <= 4; ++l)
    for (const auto& c : all_cells<2>(l)) {
      std::vector<CellId<2>> want;
      for (const auto& u : all_cells<2>(l - 1))
        if (touches(c, u)) want.push_back(u);
      std::sort(want.begin(), want.end());
      auto got = coarser_touching(c);
      std::vector<CellId<2>> have(got.begin(), got.end());
      EXPECT_EQ(have.front(), parent(c));
      std::sort(have.begin(), have.end());
      ASSERT_EQ(have, want) << to_string(c);
    }
  for (int l = 1; l <= 3; ++l)
    for (const auto& c : all_cells<3>(l)) {
      std::vector<CellId<3>> want;
      for (const auto& u : all_cells<3>(l - 1))
        if (touches(c, u)) want.push_back(u);
      std::sort(want.begin(), want.end());
      auto got = coarser_touching(c);
      std::vector<CellId<3>> have(got.begin(), got.end());
      std::sort(have.begin(), have.end());
      ASSERT_EQ(have, want) << to_string(c);
    }
}

TEST(Cell, HashSpreadsAndAgreesWithEquality) {
  CellHash h;
  EXPECT_EQ(h(CellId<2>{3, {1, 2}}), h(CellId<2>{3, {1, 2}}));
  EXPECT_NE(h(CellId<2>{3, {1, 2}}), h(CellId<2>{3, {2, 1}}));
  EXPECT_NE(h(CellId<2>{3, {1, 2}}), h(CellId<2>{4, {1, 2}}));
  std::set<std::size_t> buckets;
  for (const auto& c : all_cells<2>(5)) buckets.insert(h(c) & 1023);
  EXPECT_GT(buckets.size(), 550u);  // 1024 cells into 1024 buckets: ~647 expected if random
}

TEST(CellTable, AgreesWithStdSet) {
  std::mt19937_64 gen(11);
  detail::CellTable<3, int> table;
  std::map<CellId<3>, int> ref;
  for (int step = 0; step < 20000; ++step) {
    CellId<3> c;
    c.level = static_cast<int>(gen() % 4);
    for (auto& i : c.index) i = gen() % cells_per_axis(c.level);
    switch (gen() % 3) {
      case 0: {
        const int v = static_cast<int>(gen() % 1000);
        const bool fresh = table.try_emplace(c, v).second;
        EXPECT_EQ(fresh, ref.emplace(c, v).second);
        break;
      }
      case 1:
        EXPECT_EQ(table.erase(c), ref.erase(c) == 1);
        break;
      default: {
        const int* v = table.find(c);
        const auto it = ref.find(c);
        ASSERT_EQ(v != nullptr, it != ref.end());
        if (v) {
          EXPECT_EQ(*v, it->second);
        }
      }
    }
    ASSERT_EQ(table.size(), ref.size());
  }
  std::size_t seen = 0;
  table.for_each([&](const CellId<3>& c, const int& v) {
    ++seen;
    EXPECT_EQ(ref.at(c), v);
  });
  EXPECT_EQ(seen, ref.size());
  table.clear();
  EXPECT_TRUE(table.empty());
  EXPECT_FALSE(table.contains(CellId<3>::root()));
}

}  // namespace
