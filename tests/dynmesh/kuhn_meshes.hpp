// kuhn_meshes.hpp — small valid tetrahedral meshes built by hand, shared by the tests of the
// 3D checker (tet_mesh_check_test.cpp) and the 3D writers (tet_mesh_io_test.cpp).
//
// Kuhn's six tetrahedra of a box [lo, hi]: for each permutation π of the axes, the path from
// lo that raises axis π1, then π2, then π3 to hi, with the last two corners swapped when π is
// odd (so that each is positively oriented). They share the diagonal lo-hi, tile the box,
// and split each of its faces by the diagonal through the face's lowest corner, so
// translated copies match across shared faces: a grid of Kuhn cubes is a conforming mesh.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <random>
#include <utility>
#include <vector>

#include "dynmesh/box.hpp"
#include "dynmesh/point.hpp"
#include "dynmesh/predicates.hpp"
#include "dynmesh/tet_mesh.hpp"

namespace dynmesh_test {

inline dynmesh::Box<3> cube(double o1, double o2, double o3, double side) {
  return dynmesh::Box<3>{{o1, o2, o3}, side};
}

inline std::vector<dynmesh::Tetrahedron> kuhn(const dynmesh::Point<3>& lo, const dynmesh::Point<3>& hi) {
  constexpr std::array<std::array<int, 3>, 6> kPermutations{
      {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}}};  // the even ones first
  std::vector<dynmesh::Tetrahedron> out;
  for (std::size_t k = 0; k < kPermutations.size(); ++k) {
    std::array<dynmesh::Point<3>, 4> path{lo, lo, lo, lo};
    for (int step = 0; step < 3; ++step)
      for (int after = step + 1; after < 4; ++after) path[after][kPermutations[k][step]] = hi[kPermutations[k][step]];
    if (k >= 3) std::swap(path[2], path[3]);
    EXPECT_EQ(dynmesh::orient3d(path[0], path[1], path[2], path[3]), 1) << "permutation " << k;
    out.push_back(dynmesh::canonical_tetrahedron(path[0], path[1], path[2], path[3]));
  }
  return out;
}

inline dynmesh::TetMesh kuhn_cube() { return dynmesh::make_tet_mesh(kuhn({0, 0, 0}, {1, 1, 1})); }

/// The n x n x n grid of unit cubes on [0, n]^3, each split into Kuhn's six tetrahedra.
/// `jitter` moves the interior vertices by up to that much per axis (the tetrahedra stay
/// positive for jitter up to 0.1).
inline dynmesh::TetMesh kuhn_grid(int n, double jitter = 0, unsigned seed = 1) {
  using dynmesh::Point;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> shift(-jitter, jitter);
  const auto index = [n](int i, int j, int k) { return static_cast<std::size_t>((i * (n + 1) + j) * (n + 1) + k); };
  std::vector<Point<3>> at(static_cast<std::size_t>((n + 1) * (n + 1) * (n + 1)));
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= n; ++k) {
        Point<3> p{double(i), double(j), double(k)};
        const bool inside = i > 0 && i < n && j > 0 && j < n && k > 0 && k < n;
        if (jitter > 0 && inside) p = {p[0] + shift(rng), p[1] + shift(rng), p[2] + shift(rng)};
        at[index(i, j, k)] = p;
      }
  // Kuhn's tetrahedra of the unit cube, moved to each cube and onto its (jittered) vertices.
  const std::vector<dynmesh::Tetrahedron> unit = kuhn({0, 0, 0}, {1, 1, 1});
  std::vector<dynmesh::Tetrahedron> ts;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const dynmesh::Tetrahedron& u : unit) {
          std::array<Point<3>, 4> v;
          for (std::size_t c = 0; c < 4; ++c)
            v[c] = at[index(i + int(u.v[c][0]), j + int(u.v[c][1]), k + int(u.v[c][2]))];
          ts.push_back(dynmesh::canonical_tetrahedron(v[0], v[1], v[2], v[3]));
        }
  return dynmesh::make_tet_mesh(ts);
}

}  // namespace dynmesh_test
