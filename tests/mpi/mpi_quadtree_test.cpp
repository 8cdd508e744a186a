// mpi_quadtree_test — the differential test of MpiQuadtree, run under mpiexec on 2 and 3
// ranks (tests/mpi/CMakeLists.txt). A plain main: GoogleTest's output from several ranks
// would interleave. Every rank draws the same random batches (fixed seeds, printed on
// failure) and passes its own contiguous slice of each batch, so the global order is the
// batch's order; after every batch the gathered leaves must equal StaticQuadtree's on the
// current point set, and check_invariants() must pass. Also: a failing batch (an absent
// deletion in the last rank's slice) throws the same InputError on every rank and changes
// nothing; a ghost ring one narrower than docs/DISTRIBUTED.md derives gives a wrong tree on
// some input; repartitioning keeps the tree exact.
// Exit status 0 when every check passed on every rank, 1 otherwise.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include <mpi.h>

#include "mpi_checks.hpp"

#include "dynmesh/box.hpp"
#include "dynmesh/distributions.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/mpi_quadtree.hpp"
#include "dynmesh/static_quadtree.hpp"

namespace {

using namespace dynmesh;

using mpi_checks::check;
using mpi_checks::g_rank;
using mpi_checks::g_ranks;
using mpi_checks::random_batch;
using mpi_checks::share;

/// Rank r's contiguous share of v.
/// The gathered leaves equal the static oracle's on `points` (checked on rank 0, agreed).
template <std::size_t d>
bool exact(const MpiQuadtree<d>& tree, const std::vector<Point<d>>& points) {
  const std::vector<Leaf<d>> leaves = tree.gather_leaves(0);
  int ok = 1;
  if (g_rank == 0) {
    const auto oracle = StaticQuadtree<d>::from_points(tree.box(), points);
    ok = std::equal(leaves.begin(), leaves.end(), oracle.leaves().begin(), oracle.leaves().end()) ? 1 : 0;
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return ok != 0;
}

/// Random batches of insertions and deletions on `dist`, checked after every batch.
template <std::size_t d>
void differential(Distribution dist, std::uint64_t seed, const MpiQuadtreeOptions& options) {
  const std::string label = std::string(distribution_name(dist)) + " " + std::to_string(d) + "D seed " +
                            std::to_string(seed);
  std::vector<Point<d>> pool = generate<d>(dist, 900, seed, 0x1p24);
  std::vector<Point<d>> points(pool.begin(), pool.begin() + 500), spare(pool.begin() + 500, pool.end());
  const Box<d> box = derive_box<d>(pool);
  MpiQuadtree<d> tree(MPI_COMM_WORLD, box, share(points), options);
  check(exact(tree, points), label + ": after construction");
  Rng rng(seed * 31 + 7);
  for (int b = 0; b < 25; ++b) {
    const std::size_t k = 1 + static_cast<std::size_t>(rng.below(b % 5 == 0 ? 40 : 6));
    const std::vector<Edit<d>> batch = random_batch<d>(rng, k, points, spare);
    tree.apply(share(batch));
    if (!exact(tree, points)) {
      check(false, label + ": batch " + std::to_string(b) + " differs from StaticQuadtree");
      return;
    }
    if (b % 8 == 0) tree.check_invariants();
  }
  tree.check_invariants();

  // A bad batch: every rank gets the same error naming the global edit index; nothing changes.
  std::vector<Edit<d>> bad;
  for (std::size_t i = 0; i < 6 && i < points.size(); ++i) bad.push_back(Edit<d>{EditOp::Delete, points[i]});
  Point<d> absent = points[0];
  absent[0] = std::nextafter(absent[0], 1e9);
  bad.push_back(Edit<d>{EditOp::Delete, absent});
  std::string message;
  std::size_t index = 0;
  try {
    tree.apply(share(bad));
  } catch (const InputError& e) {
    message = e.text();
    index = e.point_indices().empty() ? 999 : e.point_indices().back();
  }
  check(!message.empty() && index == bad.size() - 1, label + ": the bad batch was not refused at its last edit");
  std::vector<char> all(static_cast<std::size_t>(g_ranks) * 512, 0);
  message.resize(511);
  MPI_Allgather(message.data(), 512, MPI_CHAR, all.data(), 512, MPI_CHAR, MPI_COMM_WORLD);
  for (int r = 0; r < g_ranks; ++r)
    check(std::string(all.data() + 512 * r) == std::string(message.c_str()), label + ": ranks disagree on the error");
  check(exact(tree, points), label + ": a refused batch changed the tree");
}

/// Some input on which a ghost ring of width 0 gives a tree other than T*.
bool narrow_ring_fails() {
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const std::vector<Point<2>> points = generate<2>(Distribution::Uniform, 400, seed);
    MpiQuadtreeOptions narrow;
    narrow.ghost_ring = 0;
    MpiQuadtree<2> tree(MPI_COMM_WORLD, derive_box<2>(points), share(points), narrow);
    if (!exact(tree, points)) return true;
  }
  return false;
}

/// Emptying half of the box makes the ranks repartition; the tree stays exact throughout.
void repartition() {
  const std::vector<Point<2>> points = generate<2>(Distribution::Uniform, 800, 11);
  MpiQuadtreeOptions options;
  options.rebalance_factor = 1.2;
  MpiQuadtree<2> tree(MPI_COMM_WORLD, Box<2>{{0.0, 0.0}, 1.0}, share(points), options);
  mpi_checks::check_repartition(tree, points, 60, exact<2>, "StaticQuadtree");
}

}  // namespace

int main(int argc, char** argv) {
  mpi_checks::start(&argc, &argv);
  try {
    for (const Distribution dist : {Distribution::Uniform, Distribution::Clusters, Distribution::Shrinking}) {
      differential<2>(dist, 1, {});
      differential<3>(dist, 2, {});
    }
    MpiQuadtreeOptions fine;
    fine.partition_level = 5;  // many small root cells: most leaves' neighbours are ghosts
    differential<2>(Distribution::Spiral, 3, fine);
    differential<2>(Distribution::Boundary, 4, fine);
    check(g_ranks == 1 || narrow_ring_fails(), "a ghost ring of width 0 gave T* on every input tried");
    repartition();
  } catch (const std::exception& e) {
    check(false, std::string("exception: ") + e.what());
  }
  return mpi_checks::finish("mpi_quadtree_test");
}
