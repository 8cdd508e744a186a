// distinct_paths.hpp (private to the command) — no output may overwrite an input.
//
// Purpose: `dynmesh mesh pts.txt -o out --vtk pts.txt` would replace the point file by the
// mesh; `-o pts` does the same to `pts.node`. Every command compares its output paths with
// its input paths before reading anything, and a clash is a malformed command line.
// Invariants: two paths clash when they name the same existing file (same device and inode,
// through links and `..`), or, when either does not exist yet, the same normalised absolute
// path. "-" (standard input) and empty paths (an option not given) never clash.
// Complexity: O(inputs × outputs) file-system lookups; a handful.
// Paper: none.
#pragma once

#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace dynmesh::tool {

/// An option and the path it names ("--vtk", "out.vtk"); for POINTS the option is "POINTS".
using NamedPath = std::pair<std::string, std::string>;

/// Do `a` and `b` name the same file (see the invariants above)?
inline bool same_file(const std::string& a, const std::string& b) {
  if (a.empty() || b.empty() || a == "-" || b == "-") return false;
  std::error_code ec;
  if (std::filesystem::exists(a, ec) && std::filesystem::exists(b, ec)) {
    const bool same = std::filesystem::equivalent(a, b, ec);
    if (!ec) return same;
  }
  const auto full = [](const std::string& p) {
    std::error_code e;
    auto canonical = std::filesystem::weakly_canonical(std::filesystem::absolute(p, e), e);
    return e ? std::filesystem::absolute(p, e).lexically_normal() : canonical;
  };
  return full(a) == full(b);
}

/// The message for the first output that names an input file, or "" when none does.
inline std::string output_overwrites_input(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs) {
  for (const auto& [out_option, out_path] : outputs)
    for (const auto& [in_option, in_path] : inputs)
      if (same_file(out_path, in_path))
        return out_option + " " + out_path + " is the input file " + in_path + " (" + in_option +
               "): an output may not overwrite an input";
  return {};
}

}  // namespace dynmesh::tool
