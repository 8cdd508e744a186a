// agreed_error.hpp (private) — one error for all ranks, agreed before anyone moves on.
//
// Purpose: a rank that finds bad input must not leave the others waiting in a collective it
// will never enter. Every phase of MpiQuadtree that can fail ends in agree(): the ranks'
// failures (if any) are reduced to the one with the least key (an input or edit index, so
// the first failure in input order wins), ties to the lowest rank; its kind, indices and
// message are broadcast, and every rank gets the same Failure back to throw.
// Invariants: agree() is collective; it returns the same value on every rank.
// Complexity: two MPI_Allreduce; when a failure exists, three MPI_Bcast of its size.
// Paper: none.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <mpi.h>

#include "dynmesh/errors.hpp"

namespace dynmesh::detail {

struct Failure {
  static constexpr std::uint64_t kNoKey = std::numeric_limits<std::uint64_t>::max() - 1;
  std::uint64_t key = kNoKey;  // what orders failures: the first in input order wins
  bool invariant = false;      // an InvariantError rather than an InputError
  InputError::Kind kind = InputError::Kind::Malformed;
  std::string text;
  std::vector<std::size_t> indices;

  [[noreturn]] void raise() const {
    if (invariant) throw InvariantError(text);
    throw InputError(kind, text).with_points(indices);
  }
};

inline std::optional<Failure> agree(MPI_Comm comm, const std::optional<Failure>& mine) {
  constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t key = mine ? mine->key : kNone, least = kNone;
  MPI_Allreduce(&key, &least, 1, MPI_UINT64_T, MPI_MIN, comm);
  if (least == kNone) return std::nullopt;
  int rank = 0, nranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &nranks);
  int candidate = key == least ? rank : nranks, winner = nranks;
  MPI_Allreduce(&candidate, &winner, 1, MPI_INT, MPI_MIN, comm);
  Failure f;
  if (rank == winner) f = *mine;
  std::uint64_t head[4] = {f.invariant ? 1u : 0u, static_cast<std::uint64_t>(f.kind), f.text.size(), f.indices.size()};
  MPI_Bcast(head, 4, MPI_UINT64_T, winner, comm);
  f.invariant = head[0] != 0;
  f.kind = static_cast<InputError::Kind>(head[1]);
  f.text.resize(head[2]);
  std::vector<std::uint64_t> idx(f.indices.begin(), f.indices.end());
  idx.resize(head[3]);
  MPI_Bcast(f.text.data(), static_cast<int>(head[2]), MPI_CHAR, winner, comm);
  MPI_Bcast(idx.data(), static_cast<int>(head[3]), MPI_UINT64_T, winner, comm);
  f.indices.assign(idx.begin(), idx.end());
  f.key = least;
  return f;
}

/// agree(), then throw the agreed failure on every rank.
inline void agree_or_throw(MPI_Comm comm, const std::optional<Failure>& mine) {
  if (const auto f = agree(comm, mine)) f->raise();
}

}  // namespace dynmesh::detail
