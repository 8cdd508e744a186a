// dynmesh/point.hpp — input points and their exact integer positions.
//
// Purpose: the two representations of a point that every dynmesh component shares.
//   Point<d>    – the coordinates as read (IEEE double), d = 2 or 3.
//   Position<d> – the integer position q of docs/DESIGN.md, "The quadtree contract": per axis
//                 q = floor((x − o) · (2^52 / L)) in [0, 2^52), computed by locate() in
//                 box.hpp. Every decision of the quadtree (which cell holds a point, whether
//                 two points are duplicates) is made on q alone, so all implementations
//                 (the static oracle, the self-adjusting tree) agree bit for bit.
// Invariants: a Position's coordinates are < 2^kResolutionBits. Two input points with equal
// Position are duplicates and are rejected.
// Complexity: value types, O(d) per operation.
// Paper: Acar & Hudson, Section 2 (cells of the quadtree over the box [0, L]^d); the 2^52
// grid is this project's exact rendering of it.
#pragma once

#include <array>
#include <cstddef>
#include <charconv>
#include <cstdint>
#include <string>

namespace dynmesh {

/// Bits of the integer grid per axis: cells exist at levels 0..kResolutionBits, and a cell of
/// level kResolutionBits holds exactly one integer position.
inline constexpr int kResolutionBits = 52;
inline constexpr int kMaxLevel = kResolutionBits;
inline constexpr std::uint64_t kResolution = std::uint64_t{1} << kResolutionBits;

template <std::size_t d>
concept SupportedDim = (d == 2 || d == 3);

template <std::size_t d>
  requires SupportedDim<d>
using Point = std::array<double, d>;

template <std::size_t d>
  requires SupportedDim<d>
using Position = std::array<std::uint64_t, d>;

/// A double as printf("%.17g") prints it in the C locale (round-trips exactly), independent of
/// the current locale. Used for every number dynmesh prints; appended in place where a long
/// text is built (the change feed), so that a number costs no string of its own.
inline void append_exact(std::string& out, double x) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general, 17);
  out.append(buf, r.ptr);
}
inline std::string format_exact(double x) {
  std::string out;
  append_exact(out, x);
  return out;
}

/// A double to `digits` significant digits (%g style, C locale), for sizes and ratios in
/// messages where every digit of format_exact would only get in the way.
inline std::string format_brief(double x, int digits = 6) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general, digits);
  return std::string(buf, r.ptr);
}

/// "(x, y[, z])" with format_exact coordinates, for messages.
template <std::size_t d>
  requires SupportedDim<d>
std::string to_string(const Point<d>& p) {
  std::string s = "(";
  for (std::size_t a = 0; a < d; ++a) {
    if (a) s += ", ";
    s += format_exact(p[a]);
  }
  return s + ")";
}

}  // namespace dynmesh
