// cell_index_test.cpp — cell_index.hpp: the directory's index of slots, against a std::map
// oracle on random operations (fixed seeds), with its checker after every operation; and
// the checker catches an entry whose cell changed under it.
#include <gtest/gtest.h>

#include <cstdint>
#include <deque>
#include <map>
#include <random>
#include <string>
#include <tuple>

#include "quadtree/cell_index.hpp"
#include "dynmesh/errors.hpp"

namespace dynmesh {
namespace {

template <std::size_t d>
struct Obj {
  explicit Obj(const CellId<d>& c) : key(detail::pack_cell<d>(c)) {}
  detail::PackedCell<d> key;
};

template <std::size_t d>
auto as_tuple(const CellId<d>& c) {
  return std::tuple{c.level, c.index};
}

/// Cells of a few levels in a small region, so that blocks, clusters and wrap-around occur.
template <std::size_t d>
CellId<d> random_cell(std::mt19937_64& rng) {
  CellId<d> c;
  c.level = static_cast<int>(rng() % 6) + 3;
  for (std::size_t a = 0; a < d; ++a) c.index[a] = rng() % (std::uint64_t{1} << c.level);
  return c;
}

template <class D>
class CellIndexTest : public testing::Test {};
using Dims = testing::Types<std::integral_constant<std::size_t, 2>, std::integral_constant<std::size_t, 3>>;
TYPED_TEST_SUITE(CellIndexTest, Dims);

TYPED_TEST(CellIndexTest, MatchesAMapOnRandomOperations) {
  constexpr std::size_t d = TypeParam::value;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    std::deque<Obj<d>> store;
    std::map<decltype(as_tuple(CellId<d>{})), Obj<d>*> oracle;
    detail::CellIndex<d, Obj<d>> index;
    for (int step = 0; step < 4000; ++step) {
      const CellId<d> c = random_cell<d>(rng);
      const auto k = as_tuple(c);
      const unsigned op = static_cast<unsigned>(rng() % 3);
      if (op == 0) {
        if (!oracle.count(k)) {
          Obj<d>* o = &store.emplace_back(c);
          index.insert(o);
          oracle[k] = o;
        }
      } else if (op == 1) {
        ASSERT_EQ(index.erase(c), oracle.erase(k) == 1) << "step " << step;
      }
      const auto it = oracle.find(k);
      ASSERT_EQ(index.find(c), it == oracle.end() ? nullptr : it->second) << "step " << step;
      ASSERT_EQ(index.size(), oracle.size());
      ASSERT_NO_THROW(index.check_invariants()) << "step " << step;
    }
    std::size_t seen = 0;
    index.for_each([&](Obj<d>* o) {
      ++seen;
      EXPECT_EQ(oracle.at(as_tuple(detail::unpack_cell<d>(o->key))), o);
    });
    EXPECT_EQ(seen, oracle.size());
    EXPECT_EQ(index.bytes() % sizeof(void*), 0u);
    EXPECT_GE(3 * index.bytes(), 4 * oracle.size() * sizeof(void*)) << "load factor at most 3/4";
  }
}

TYPED_TEST(CellIndexTest, CheckerCatchesAnEntryWhoseCellChanged) {
  constexpr std::size_t d = TypeParam::value;
  std::mt19937_64 rng(7);
  std::deque<Obj<d>> store;
  detail::CellIndex<d, Obj<d>> index;
  std::map<decltype(as_tuple(CellId<d>{})), Obj<d>*> seen;
  while (seen.size() < 200) {
    const CellId<d> c = random_cell<d>(rng);
    if (seen.count(as_tuple(c))) continue;
    Obj<d>* o = &store.emplace_back(c);
    index.insert(o);
    seen[as_tuple(c)] = o;
  }
  ASSERT_NO_THROW(index.check_invariants());
  // Give one entry the cell of another: its entry's tag is no longer its cell's (and it is
  // indexed twice, or out of its home's reach).
  const auto message = [&] {
    try {
      index.check_invariants();
    } catch (const InvariantError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  Obj<d>* a = seen.begin()->second;
  Obj<d>* b = std::next(seen.begin(), 100)->second;
  const detail::PackedCell<d> keep = a->key;
  a->key = b->key;
  EXPECT_NE(message().find("tag is not its cell's"), std::string::npos) << message();
  a->key = keep;
  EXPECT_NO_THROW(index.check_invariants());
  // A cell far from every indexed one (level 30).
  CellId<d> far;
  far.level = 30;
  for (std::size_t k = 0; k < d; ++k) far.index[k] = (std::uint64_t{1} << 29) + 12345 * (k + 1);
  a->key = detail::pack_cell<d>(far);
  EXPECT_NE(message().find("tag is not its cell's"), std::string::npos) << message();
  a->key = keep;
  EXPECT_NO_THROW(index.check_invariants());
}

}  // namespace
}  // namespace dynmesh
