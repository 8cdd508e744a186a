// mpi_mesh_test — the differential test of MpiMesh (the quadtree mesh in 2D, the octree's
// tetrahedra in 3D), run under mpiexec on 2 and 3 ranks (tests/mpi/CMakeLists.txt). A plain
// main, as mpi_quadtree_test. Every rank draws the same random batches (fixed seeds) and
// passes its own slice of each; after every batch the ranks' owned simplices, merged on
// rank 0, must be the static twin's (QuadtreeMesh, OctreeMesh) on the current points, and
// check_invariants() must pass. Also: a refused batch changes nothing; emptying a region
// moves the partition level up to T*'s coarsest leaf and stays exact; a ghost ring narrower
// than docs/DISTRIBUTED.md derives gives a wrong mesh on some input; repartitioning keeps the
// mesh exact.
// Exit status 0 when every check passed on every rank, 1 otherwise.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include <mpi.h>

#include "mpi_checks.hpp"

#include "dynmesh/box.hpp"
#include "dynmesh/detail/merge_on_root.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/mpi_mesh.hpp"
#include "dynmesh/octree_mesh.hpp"
#include "dynmesh/quadtree_mesh.hpp"

namespace {

using namespace dynmesh;

using mpi_checks::check;
using mpi_checks::g_rank;
using mpi_checks::g_ranks;
using mpi_checks::random_batch;
using mpi_checks::share;

std::vector<Triangle> twin(const Box<2>& box, const std::vector<Point<2>>& points) {
  return QuadtreeMesh(box, points).triangles();
}
std::vector<Tetrahedron> twin(const Box<3>& box, const std::vector<Point<3>>& points) {
  return OctreeMesh(box, points).tetrahedra();
}

Mesh canonical(const std::vector<Triangle>& t) { return make_mesh(t); }
TetMesh canonical(const std::vector<Tetrahedron>& t) { return make_tet_mesh(t); }

/// The ranks' owned simplices, merged on rank 0, equal the static twin's on `points`, and
/// each rank's index form is its simplices' (agreed).
template <std::size_t d>
bool exact(const MpiMesh<d>& mesh, const std::vector<Point<d>>& points) {
  using Simplex = MeshSimplex<d>;
  const std::vector<Simplex> mine = mesh.local_simplices();
  check(canonical(mine) == mesh.owned_mesh(), "owned_mesh() is not the owned simplices' index form");
  std::vector<Simplex> all;
  int ok = 1;
  try {
    detail::merge_on_root<Simplex>(MPI_COMM_WORLD, std::span<const Simplex>(mine), 0,
                                   [](const Simplex& a, const Simplex& b) { return a < b; },
                                   [&](std::span<const Simplex> run) { all.insert(all.end(), run.begin(), run.end()); });
  } catch (const std::exception&) {
    ok = 0;  // two ranks own one simplex: the merge refuses
  }
  if (g_rank == 0 && ok) ok = all == twin(mesh.box(), points) ? 1 : 0;
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return ok != 0;
}

/// Random batches on `dist`, checked after every batch.
template <std::size_t d>
void differential(Distribution dist, std::uint64_t seed, std::size_t n, const MpiQuadtreeOptions& options,
                  const Box<d>* fixed_box = nullptr) {
  const std::string label = std::string(distribution_name(dist)) + " " + std::to_string(d) + "D seed " +
                            std::to_string(seed);
  std::vector<Point<d>> pool = generate<d>(dist, n + n / 2, seed, 0x1p20);
  std::vector<Point<d>> points(pool.begin(), pool.begin() + static_cast<std::ptrdiff_t>(n));
  std::vector<Point<d>> spare(pool.begin() + static_cast<std::ptrdiff_t>(n), pool.end());
  const Box<d> box = fixed_box ? *fixed_box : derive_box<d>(pool);
  MpiMesh<d> mesh(MPI_COMM_WORLD, box, share(points), options);
  check(exact(mesh, points), label + ": after construction");
  Rng rng(seed * 31 + 7);
  for (int b = 0; b < 12; ++b) {
    const std::size_t k = 1 + static_cast<std::size_t>(rng.below(b % 4 == 0 ? 20 : 4));
    const std::vector<Edit<d>> batch = random_batch<d>(rng, k, points, spare);
    mesh.apply(share(batch));
    if (!exact(mesh, points)) {
      check(false, label + ": batch " + std::to_string(b) + " differs from the static twin");
      return;
    }
  }
  mesh.check_invariants();

  // A bad batch: the same error on every rank, naming the last edit; nothing changes.
  std::vector<Edit<d>> bad;
  for (std::size_t i = 0; i < 4 && i < points.size(); ++i) bad.push_back(Edit<d>{EditOp::Delete, points[i]});
  Point<d> absent = points[0];
  absent[0] = std::nextafter(absent[0], 1e9);
  bad.push_back(Edit<d>{EditOp::Delete, absent});
  std::size_t index = 0;
  bool refused = false;
  try {
    mesh.apply(share(bad));
  } catch (const InputError& e) {
    refused = true;
    index = e.point_indices().empty() ? 999 : e.point_indices().back();
  }
  check(refused && index == bad.size() - 1, label + ": the bad batch was not refused at its last edit");
  check(exact(mesh, points), label + ": a refused batch changed the mesh");
}

/// Points filling the unit box (no leaf of T* above level 3), then a region emptied: the
/// partition level must move up to the new coarsest leaf, and the mesh stay exact.
void level_moves() {
  const Box<2> box{{0.0, 0.0}, 1.0};
  std::vector<Point<2>> points = generate<2>(Distribution::Uniform, 1500, 21);
  MpiQuadtreeOptions options = mpi_mesh_defaults();
  options.partition_level = 5;
  MpiMesh<2> mesh(MPI_COMM_WORLD, box, share(points), options);
  const int before = mesh.partition_level();
  check(exact(mesh, points), "level_moves: after construction");
  std::vector<Edit<2>> gone;
  std::vector<Point<2>> kept;
  for (const Point<2>& p : points) {
    if (p[0] < 0.5 && p[1] < 0.5) gone.push_back(Edit<2>{EditOp::Delete, p});
    else kept.push_back(p);
  }
  mesh.apply(share(gone));
  check(exact(mesh, kept), "level_moves: after emptying a quarter");
  check(mesh.partition_level() < before, "level_moves: the partition level did not move (" +
                                             std::to_string(before) + " -> " +
                                             std::to_string(mesh.partition_level()) + ")");
  mesh.check_invariants();
}

/// Some input on which a ghost ring of width 1 gives a mesh other than the twin's.
bool narrow_ring_fails() {
  const Box<2> box{{0.0, 0.0}, 1.0};
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const std::vector<Point<2>> points = generate<2>(Distribution::Uniform, 3000, seed);
    MpiQuadtreeOptions narrow = mpi_mesh_defaults();
    narrow.ghost_ring = 1;
    narrow.partition_level = 6;
    MpiMesh<2> mesh(MPI_COMM_WORLD, box, share(points), narrow);
    if (!exact(mesh, points)) return true;
  }
  return false;
}

/// Moving every point of one half into the other makes the ranks repartition; exact throughout.
void repartition() {
  const std::vector<Point<2>> points = generate<2>(Distribution::Uniform, 600, 11);
  MpiQuadtreeOptions options = mpi_mesh_defaults();
  options.rebalance_factor = 1.2;
  MpiMesh<2> mesh(MPI_COMM_WORLD, Box<2>{{0.0, 0.0}, 1.0}, share(points), options);
  mpi_checks::check_repartition(mesh, points, 100, exact<2>, "the twin");
}

}  // namespace

int main(int argc, char** argv) {
  mpi_checks::start(&argc, &argv);
  try {
    const Box<2> unit2{{0.0, 0.0}, 1.0};
    const Box<3> unit3{{0.0, 0.0, 0.0}, 1.0};
    MpiQuadtreeOptions fine = mpi_mesh_defaults();
    fine.partition_level = 6;  // lowered as far as T* needs
    for (const Distribution dist : {Distribution::Uniform, Distribution::Clusters, Distribution::Shrinking})
      differential<2>(dist, 1, 400, fine);
    differential<2>(Distribution::Uniform, 2, 1500, fine, &unit2);
    differential<2>(Distribution::Spiral, 3, 400, fine);
    differential<2>(Distribution::Boundary, 4, 400, fine);
    MpiQuadtreeOptions fine3 = mpi_mesh_defaults();
    fine3.partition_level = 4;
    differential<3>(Distribution::Uniform, 5, 300, fine3, &unit3);
    differential<3>(Distribution::Clusters, 6, 150, fine3);
    level_moves();
    check(g_ranks == 1 || narrow_ring_fails(), "a ghost ring of width 1 gave the twin's mesh on every input tried");
    repartition();
  } catch (const std::exception& e) {
    check(false, std::string("exception: ") + e.what());
  }
  return mpi_checks::finish("mpi_mesh_test");
}
