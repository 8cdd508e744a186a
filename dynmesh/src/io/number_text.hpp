// number_text.hpp (private) — the one formatter of a non-negative integer in the text formats.
//
// Purpose: every writer of a count, an index or a level (.cells in io.cpp; .node/.ele, VTK,
// MSH, the feed and the SVG in mesh_text.hpp and mesh_io.cpp) appends it with append_number,
// so all of them print integers the same way.
// Invariants: plain decimal digits, no sign, no padding, no grouping, whatever the locale
// (std::to_chars); nothing else is appended.
// Complexity: O(digits).
// Paper: none.
#pragma once

#include <charconv>
#include <cstddef>
#include <string>

namespace dynmesh::detail {

/// Appends n in decimal.
inline void append_number(std::string& out, std::size_t n) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, n);
  out.append(buf, r.ptr);
}

}  // namespace dynmesh::detail
