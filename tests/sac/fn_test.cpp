// fn_test.cpp — sac/fn.hpp: closures compare and hash by their stored arguments, stored as
// the parameter types of f for numbers, enums and pointers, so equal calls match; a memo
// lookup with a differently typed but equal argument is reused.
#include "sac/fn.hpp"

#include <gtest/gtest.h>

#include <span>
#include <type_traits>
#include <vector>

#include "sac/engine.hpp"

namespace {

enum class Side : unsigned char { Left, Right };

int takes_long(int x, long y) { return x + static_cast<int>(y); }
int takes_const_ptr(const int* p) { return *p; }
int takes_enum_and_double(Side s, double d) { return s == Side::Left ? static_cast<int>(d) : 0; }
int takes_span(std::span<const int> v) { return static_cast<int>(v.size()); }

TEST(Fn, NumbersAreStoredAsTheParameterType) {
  const auto a = sac::fn<takes_long>(0);
  const auto b = sac::fn<takes_long>(0L);
  static_assert(std::is_same_v<decltype(a), decltype(b)>);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.hash(), b.hash());
  EXPECT_EQ(a(2), 2);
  EXPECT_NE(sac::fn<takes_long>(1), sac::fn<takes_long>(2L));
  // 1.0f and 1 for a double parameter, an enum as itself.
  EXPECT_EQ(sac::fn<takes_enum_and_double>(Side::Left, 1.0f), sac::fn<takes_enum_and_double>(Side::Left, 1));
}

TEST(Fn, PointersAreStoredAsTheParameterType) {
  int x = 5;
  int* p = &x;
  const int* q = &x;
  const auto a = sac::fn<takes_const_ptr>(p);
  const auto b = sac::fn<takes_const_ptr>(q);
  static_assert(std::is_same_v<decltype(a), decltype(b)>);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.hash(), b.hash());
  EXPECT_EQ(a(), 5);
}

TEST(Fn, ViewParametersStoreTheOwningArgument) {
  // A span parameter must not store a span of the caller's temporary.
  const auto f = sac::fn<takes_span>(std::vector<int>{1, 2, 3});
  static_assert(std::is_same_v<decltype(f), const sac::Fn<takes_span, std::vector<int>>>);
  EXPECT_EQ(f(), 3);
}

// A memoized call with an int argument is reused by a re-execution that passes a long.
int calls = 0;
void count_step(sac::Engine& rt, long k, sac::Mod<long>* out) {
  ++calls;
  rt.write(*out, k * 2);
}

TEST(Fn, MemoMatchesAcrossArgumentTypes) {
  sac::Engine rt;
  sac::Mod<int> in;
  sac::Mod<long> out, other;
  rt.set(in, 0);
  calls = 0;
  rt.run([&](sac::Engine& rt2) {
    rt2.read(in, [&out, &other](sac::Engine& rt3, const int& v) {
      // Before the change an int 7; after it a long 7: the same memoized call.
      if (v == 0) rt3.memo(sac::fn<count_step>(7, &out));
      else rt3.memo(sac::fn<count_step>(7L, &out));
      rt3.write(other, static_cast<long>(v));
    });
  });
  EXPECT_EQ(calls, 1);
  rt.set(in, 1);
  rt.propagate();
  EXPECT_EQ(calls, 1) << "the memo entry was not reused: the closures did not compare equal";
  rt.check_invariants();
}

}  // namespace
