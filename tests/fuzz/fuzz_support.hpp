// tests/fuzz/fuzz_support.hpp — what the libFuzzer targets share: failing loudly, reading
// text through the library's readers, and decoding fuzz bytes into boxes and points.
//
// Purpose: a target checks properties and compares against an oracle; any broken property
// is a finding, so check() prints what broke and aborts (libFuzzer saves the input).
// Points are decoded so that the interesting cases come up often: most lie on a coarse
// dyadic grid of the box (2^4 steps per axis, both ends included, so equal points, touching
// cells and the upper edge, which is outside the half-open box, are common); some lie on a
// finer grid down to the 2^52 resolution; some are a known point nudged by an ulp, a grid
// unit (L/2^52) or a dyadic step, or with its zeros negated; a few are special (NaN, ±inf,
// the box's edges and their neighbours in double); a few are arbitrary doubles.
// Invariants: decoding is a function of the bytes (FuzzedDataProvider) and never fails;
// an exhausted input decodes to zeros (grid points at the box's origin).
// Complexity: O(d) per point.
// Paper: none.
#pragma once

#include <fuzzer/FuzzedDataProvider.h>

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh_fuzz {

using namespace dynmesh;

/// A broken property: say which, then abort so that libFuzzer keeps the input.
[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "dynmesh fuzz check failed: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}
inline void check(bool ok, const char* what) {
  if (!ok) fail(what);
}

/// Exactly the same bits (so that −0.0 and 0.0, or two NaNs, are told apart).
template <std::size_t d>
bool same_bits(const Point<d>& a, const Point<d>& b) noexcept {
  for (std::size_t k = 0; k < d; ++k)
    if (std::bit_cast<std::uint64_t>(a[k]) != std::bit_cast<std::uint64_t>(b[k])) return false;
  return true;
}

template <std::size_t d>
bool finite(const Point<d>& p) noexcept {
  for (std::size_t k = 0; k < d; ++k)
    if (!std::isfinite(p[k])) return false;
  return true;
}

/// The properties every reader error has: the file is named, the line (when given) exists,
/// and what() is one line, as the command prints it.
inline void check_reader_error(const InputError& e, const std::string& name, std::string_view text) {
  check(e.file() == name, "a reader error does not name the file");
  check(std::string_view(e.what()).starts_with(name + ":"), "a reader error's message does not start with the file");
  std::size_t lines = 1;
  for (char c : text) lines += c == '\n';
  check(e.line() <= lines, "a reader error names a line beyond the end of the input");
  check(std::string_view(e.what()).find_first_of("\n\r") == std::string_view::npos,
        "a reader error's message is not one line");
  using Kind = InputError::Kind;
  // Unsupported: plain text shaped like Triangle's numbered rows (a .node or .ele file).
  check(e.kind() == Kind::Malformed || e.kind() == Kind::NotFinite || e.kind() == Kind::Count ||
            e.kind() == Kind::Unsupported,
        "a reader error of a kind other than Malformed, NotFinite, Count or Unsupported");
}

/// Line numbers of a successful read: one per item, strictly increasing, within the input.
inline void check_lines(std::span<const std::size_t> lines, std::size_t items, std::string_view text) {
  check(lines.size() == items, "one line number per item");
  std::size_t total = 1;
  for (char c : text) total += c == '\n';
  for (std::size_t i = 0; i < lines.size(); ++i) {
    check(lines[i] >= 1 && lines[i] <= total, "a line number outside the input");
    check(i == 0 || lines[i] > lines[i - 1], "line numbers not strictly increasing");
  }
}

/// Decodes boxes and points from the fuzz bytes (see the header comment).
template <std::size_t d>
class PointSource {
 public:
  PointSource(FuzzedDataProvider& in, const Box<d>& box) : in_(in), box_(box) {}

  void set_box(const Box<d>& box) { box_ = box; }

  /// A box: mostly one of a few fixed ones (dyadic, non-dyadic, far from the origin with a
  /// small side, which the mesh cannot resolve deeply), sometimes arbitrary doubles (which
  /// validate_box may refuse).
  static Box<d> decode_box(FuzzedDataProvider& in) {
    Box<d> box;
    switch (in.ConsumeIntegralInRange<int>(0, 4)) {
      case 0:
        box.side = 1.0;
        break;
      case 1:
        box.origin.fill(-1.0);
        box.side = 4.0;
        break;
      case 2:
        for (std::size_t a = 0; a < d; ++a) box.origin[a] = 0.1 + 0.2 * static_cast<double>(a);
        box.side = 3.0;
        break;
      case 3:
        for (std::size_t a = 0; a < d; ++a) box.origin[a] = (a % 2 ? -2e6 : 1e6) + 0.5;
        box.side = 1e-3;
        break;
      default:
        for (std::size_t a = 0; a < d; ++a) box.origin[a] = raw(in);
        box.side = raw(in);
        break;
    }
    return box;
  }

  /// A point; `known` are points seen before (present or not), for near-collisions.
  Point<d> next(std::span<const Point<d>> known) {
    const auto mode = in_.ConsumeIntegral<std::uint8_t>();
    Point<d> p{};
    if (mode < 128) return grid(4);
    if (mode < 176) return grid(1 + mode % 8);
    if (mode < 192) {
      constexpr int kFine[] = {12, 20, 30, 40, 50, 51, 52, 52};
      return grid(kFine[mode % 8]);
    }
    if (mode < 224 && !known.empty()) {
      p = known[in_.ConsumeIntegralInRange<std::size_t>(0, known.size() - 1)];
      for (std::size_t a = 0; a < d; ++a) p[a] = nudge(p[a]);
      return p;
    }
    if (mode < 244) {
      for (std::size_t a = 0; a < d; ++a) p[a] = special(a);
      return p;
    }
    for (std::size_t a = 0; a < d; ++a) p[a] = raw(in_);
    return p;
  }

 private:
  static double raw(FuzzedDataProvider& in) { return std::bit_cast<double>(in.ConsumeIntegral<std::uint64_t>()); }

  /// o + k·(L/2^level) per axis, k in [0, 2^level]: k = 2^level is the upper edge.
  Point<d> grid(int level) {
    const std::uint64_t steps = std::uint64_t{1} << level;
    const double step = std::ldexp(box_.side, -level);
    Point<d> p;
    for (std::size_t a = 0; a < d; ++a)
      p[a] = box_.origin[a] + static_cast<double>(in_.ConsumeIntegralInRange<std::uint64_t>(0, steps)) * step;
    return p;
  }

  double nudge(double x) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    const double unit = std::ldexp(box_.side, -kResolutionBits);
    switch (in_.ConsumeIntegralInRange<int>(0, 7)) {
      case 0: return x;
      case 1: return std::nextafter(x, inf);
      case 2: return std::nextafter(x, -inf);
      case 3: return x + unit;
      case 4: return x - unit;
      case 5: return x + std::ldexp(box_.side, -in_.ConsumeIntegralInRange<int>(2, kResolutionBits));
      case 6: return x - std::ldexp(box_.side, -in_.ConsumeIntegralInRange<int>(2, kResolutionBits));
      default: return x == 0.0 ? -x : x;  // ±0: equal as numbers, different bits
    }
  }

  double special(std::size_t axis) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    const double lo = box_.origin[axis], hi = box_.origin[axis] + box_.side;
    switch (in_.ConsumeIntegralInRange<int>(0, 11)) {
      case 0: return std::numeric_limits<double>::quiet_NaN();
      case 1: return inf;
      case 2: return -inf;
      case 3: return lo;
      case 4: return std::nextafter(lo, -inf);
      case 5: return std::nextafter(lo, inf);
      case 6: return hi;
      case 7: return std::nextafter(hi, -inf);
      case 8: return std::nextafter(hi, inf);
      case 9: return -0.0;
      case 10: return std::numeric_limits<double>::max();
      default: return std::numeric_limits<double>::denorm_min();
    }
  }

  FuzzedDataProvider& in_;
  Box<d> box_;
};

}  // namespace dynmesh_fuzz
