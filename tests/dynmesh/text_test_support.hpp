// text_test_support.hpp — helpers shared by the tests of the text writers and readers
// (mesh_io_test.cpp, tet_mesh_io_test.cpp): a text's lines, and the kind of the InputError a
// call throws.
#pragma once

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "dynmesh/errors.hpp"

namespace dynmesh_test {

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

/// The kind of the InputError f() throws; a test failure (and Io) when it throws none.
template <class F>
dynmesh::InputError::Kind input_error_kind(F&& f) {
  try {
    f();
  } catch (const dynmesh::InputError& e) {
    return e.kind();
  }
  ADD_FAILURE() << "no InputError thrown";
  return dynmesh::InputError::Kind::Io;
}

}  // namespace dynmesh_test
