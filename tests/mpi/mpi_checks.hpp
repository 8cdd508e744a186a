// mpi_checks.hpp — what the plain-main MPI tests share (tests/mpi/): each rank counts its
// failed checks and prints them on stderr; at the end every rank learns the total, rank 0
// prints one verdict line, and the exit status is that total's. Also each rank's slice of a
// batch, and the random batches of the differential tests.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include <mpi.h>

#include "dynmesh/distributions.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/point.hpp"

namespace mpi_checks {

inline int g_rank = 0, g_ranks = 1, g_failures = 0;

/// MPI_Init, and this rank's number and the number of ranks.
inline void start(int* argc, char*** argv) {
  MPI_Init(argc, argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_ranks);
}

inline void check(bool ok, const std::string& what) {
  if (ok) return;
  ++g_failures;
  std::fprintf(stderr, "FAIL (rank %d): %s\n", g_rank, what.c_str());
}

/// Rank r's contiguous share of v: every rank passes its own slice of the same batch, so
/// the global order (rank 0's slice first) is the batch's order.
template <class T>
std::span<const T> share(const std::vector<T>& v) {
  const std::size_t lo = v.size() * static_cast<std::size_t>(g_rank) / static_cast<std::size_t>(g_ranks);
  const std::size_t hi = v.size() * static_cast<std::size_t>(g_rank + 1) / static_cast<std::size_t>(g_ranks);
  return std::span<const T>(v).subspan(lo, hi - lo);
}

/// A batch of about k random edits (the same on every rank for the same rng): each deletes a
/// present point or inserts a spare one, half and half while both last; `points` and
/// `spare` follow.
template <std::size_t d>
std::vector<dynmesh::Edit<d>> random_batch(dynmesh::Rng& rng, std::size_t k, std::vector<dynmesh::Point<d>>& points,
                                           std::vector<dynmesh::Point<d>>& spare) {
  using dynmesh::EditOp;
  std::vector<dynmesh::Edit<d>> batch;
  for (std::size_t i = 0; i < k; ++i) {
    if ((rng.below(2) == 0 || spare.empty()) && !points.empty()) {
      const std::size_t j = static_cast<std::size_t>(rng.below(points.size()));
      batch.push_back(dynmesh::Edit<d>{EditOp::Delete, points[j]});
      spare.push_back(points[j]);
      points[j] = points.back();
      points.pop_back();
    } else if (!spare.empty()) {
      const std::size_t j = static_cast<std::size_t>(rng.below(spare.size()));
      batch.push_back(dynmesh::Edit<d>{EditOp::Insert, spare[j]});
      points.push_back(spare[j]);
      spare[j] = spare.back();
      spare.pop_back();
    }
  }
  return batch;
}

/// The repartition check of the differential tests: every point of `points` below y = 0.5
/// (the last axis: the Morton order's first halving) moves to y/2 + 0.5, deleted then
/// inserted, in batches of `batch` edits; after each, exact(structure, current points) must
/// hold; at the end check_invariants() passes and some rank has repartitioned.
template <class Structure, class Exact>
void check_repartition(Structure& structure, std::vector<dynmesh::Point<2>> points, std::size_t batch, Exact&& exact,
                       const std::string& against) {
  using dynmesh::Edit;
  using dynmesh::EditOp;
  std::vector<Edit<2>> moves;
  std::vector<dynmesh::Point<2>> now = points;
  for (dynmesh::Point<2>& p : points)
    if (p[1] < 0.5) {
      moves.push_back(Edit<2>{EditOp::Delete, p});
      p[1] = p[1] / 2 + 0.5;
      moves.push_back(Edit<2>{EditOp::Insert, p});
    }
  for (std::size_t i = 0; i < moves.size(); i += batch) {
    const std::vector<Edit<2>> part(moves.begin() + static_cast<std::ptrdiff_t>(i),
                                    moves.begin() + static_cast<std::ptrdiff_t>(std::min(moves.size(), i + batch)));
    for (const Edit<2>& e : part) {
      if (e.op == EditOp::Delete)
        now.erase(std::find(now.begin(), now.end(), e.point));
      else
        now.push_back(e.point);
    }
    structure.apply(share(part));
    check(exact(structure, now), "repartition: batch at edit " + std::to_string(i) + " differs from " + against);
  }
  structure.check_invariants();
  unsigned long mine = structure.rank_stats().repartitions, most = 0;
  MPI_Allreduce(&mine, &most, 1, MPI_UNSIGNED_LONG, MPI_MAX, MPI_COMM_WORLD);
  check(g_ranks == 1 || most > 0, "repartition: no repartition happened");
}

/// Collective: the verdict of every rank's checks (rank 0 prints it), then MPI_Finalize;
/// returns the exit status, 0 when no rank failed a check.
inline int finish(const char* name) {
  int mine = g_failures, total = 0;
  MPI_Allreduce(&mine, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (g_rank == 0) std::printf("%s on %d ranks: %s\n", name, g_ranks, total ? "FAILED" : "passed");
  MPI_Finalize();
  return total ? 1 : 0;
}

}  // namespace mpi_checks
