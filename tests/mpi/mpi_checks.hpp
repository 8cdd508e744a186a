// mpi_checks.hpp — what the plain-main MPI tests share (tests/mpi/): each rank counts its
// failed checks and prints them on stderr; at the end every rank learns the total, rank 0
// prints one verdict line, and the exit status is that total's.
#pragma once

#include <cstdio>
#include <string>

#include <mpi.h>

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
