// same_triangles.hpp — a gtest assertion shared by the tests of the self-adjusting meshes
// (hpu_cells_program_test.cpp): two sorted triangle lists
// are equal, or the failure names the counts and the first few differences.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <iterator>
#include <string>
#include <vector>

#include "dynmesh/mesh.hpp"
#include "dynmesh/point.hpp"

namespace dynmesh_test {

inline std::string tri_string(const dynmesh::Triangle& t) {
  return dynmesh::to_string(t.v[0]) + " " + dynmesh::to_string(t.v[1]) + " " + dynmesh::to_string(t.v[2]);
}

/// Equal triangle lists (both sorted), or the counts and the first few differences.
inline testing::AssertionResult same_triangles(const std::vector<dynmesh::Triangle>& got,
                                               const std::vector<dynmesh::Triangle>& want) {
  if (got == want) return testing::AssertionSuccess();
  std::vector<dynmesh::Triangle> extra, missing;
  std::set_difference(got.begin(), got.end(), want.begin(), want.end(), std::back_inserter(extra));
  std::set_difference(want.begin(), want.end(), got.begin(), got.end(), std::back_inserter(missing));
  auto r = testing::AssertionFailure() << got.size() << " triangles, the static twin has " << want.size() << "; "
                                       << extra.size() << " extra, " << missing.size() << " missing";
  for (std::size_t i = 0; i < std::min<std::size_t>(3, extra.size()); ++i) r << "\n  extra   " << tri_string(extra[i]);
  for (std::size_t i = 0; i < std::min<std::size_t>(3, missing.size()); ++i)
    r << "\n  missing " << tri_string(missing[i]);
  return r;
}

}  // namespace dynmesh_test
