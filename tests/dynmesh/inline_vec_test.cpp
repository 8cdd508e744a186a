// inline_vec_test.cpp — inline_vec.hpp against std::vector on random pushes, pops, copies,
// moves and assignments (fixed seeds), across the spill point and back.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "hpu/inline_vec.hpp"

namespace dynmesh {
namespace {

template <std::size_t N>
void expect_same(const detail::InlineVec<int, N>& v, const std::vector<int>& want, int step) {
  ASSERT_EQ(v.size(), want.size()) << "step " << step;
  ASSERT_EQ(v.empty(), want.empty());
  for (std::size_t i = 0; i < want.size(); ++i) ASSERT_EQ(v[i], want[i]) << "step " << step << ", i " << i;
  ASSERT_EQ(std::vector<int>(v.span().begin(), v.span().end()), want);
  if (!want.empty()) {
    ASSERT_EQ(v.back(), want.back());
  }
}

template <std::size_t N>
void random_ops(std::uint64_t seed) {
  SCOPED_TRACE("N " + std::to_string(N) + ", seed " + std::to_string(seed));
  std::mt19937_64 rng(seed);
  detail::InlineVec<int, N> v;
  std::vector<int> want;
  for (int step = 0; step < 5000; ++step) {
    const unsigned op = static_cast<unsigned>(rng() % 10);
    if (op < 5 || want.empty()) {  // grow more than shrink, so sizes reach several N
      const int x = static_cast<int>(rng() % 1000);
      v.push_back(x);
      want.push_back(x);
    } else if (op < 8) {
      v.pop_back();
      want.pop_back();
    } else if (op == 8) {
      detail::InlineVec<int, N> c(v);  // a copy is equal and independent
      ASSERT_TRUE(c == v);
      c.push_back(-1);
      ASSERT_FALSE(c == v);
      detail::InlineVec<int, N> m(std::move(c));
      m.pop_back();
      ASSERT_TRUE(m == v);
      v = m;  // assignment from an equal copy
    } else {
      detail::InlineVec<int, N> other;
      for (std::size_t i = 0; i < rng() % (3 * N); ++i) other.push_back(static_cast<int>(i));
      detail::InlineVec<int, N> keep = v;
      v = other;  // assignment over a vector of another size, then back
      ASSERT_TRUE(v == other);
      v = std::move(keep);
    }
    expect_same(v, want, step);
    if (rng() % 500 == 0) {
      while (!want.empty()) {
        v.pop_back();
        want.pop_back();
      }
      expect_same(v, want, step);
    }
  }
}

TEST(InlineVec, MatchesAVectorAcrossTheSpillPoint) {
  for (std::uint64_t seed : {1u, 2u}) {
    random_ops<1>(seed);
    random_ops<2>(seed);
    random_ops<8>(seed);
  }
}

}  // namespace
}  // namespace dynmesh
