// dynmesh/tools/number_options.hpp — range checks for the command's whole-number options.
//
// Purpose: CLI11 2.1 converts an unsigned option with strtoull(…, 0), so on its own it takes
// "-1" as 2^64 − 1, a value above 2^64 as 2^64 − 1, "0x10" as 16 and "010" as 8. whole_number()
// accepts only a plain decimal within [lo, hi] and hands CLI11 its canonical digits.
// Invariants: a value that passes converts to exactly the number written, within [lo, hi].
// Complexity: O(length of the value).
#pragma once

#include <charconv>
#include <cstdint>
#include <string>
#include <system_error>

#include <CLI/CLI.hpp>

namespace dynmesh::tool {

/// A CLI11 validator: a decimal whole number from lo to hi, digits only (no sign).
inline CLI::Validator whole_number(std::uint64_t lo, std::uint64_t hi) {
  const std::string range = std::to_string(lo) + " to " + std::to_string(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& value) -> std::string {
        std::uint64_t v = 0;
        const char* end = value.data() + value.size();
        const bool digits = !value.empty() && value.find_first_not_of("0123456789") == std::string::npos;
        const auto [ptr, ec] = std::from_chars(value.data(), end, v);
        if (!digits || ec != std::errc{} || ptr != end || v < lo || v > hi)
          return "must be a whole number from " + range + ", got '" + value + "'";
        value = std::to_string(v);  // no leading zeros: CLI11 would read "010" as octal
        return {};
      },
      "INT " + range);
}

}  // namespace dynmesh::tool
