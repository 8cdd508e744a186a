// dynmesh/detail/merge_on_root.hpp — the ranks' sorted parts merged on one rank as a stream.
//
// Purpose: rank 0 writes the canonical files of dynmesh-mpi (docs/DISTRIBUTED.md, "Writing
// the output") without holding all of what they list: each rank keeps its own sorted part,
// and the root takes the parts a chunk at a time, merging them as they arrive and handing
// the merged sequence to a sink in chunks. The root holds its own part plus one chunk per
// other rank and one for the output; the other ranks hold their parts, as they did anyway.
// Protocol: the parts' sizes meet on the root (MPI_Gather); then each rank sends its part in
// chunks of at most `chunk` elements, in order, by blocking MPI_Send to the root, which
// receives a rank's next chunk when it has merged the last one. A rank waits only on the
// root, and the root only on a rank that is sending exactly the chunk it asks for, so no
// order of arrival can deadlock.
// Invariants (checked on the root): each part is sorted by `less` and the parts are
// disjoint, i.e. the merged sequence is strictly increasing; InvariantError otherwise.
// Errors: a chunk of 0 elements, or of more bytes than an MPI count holds, throws
// std::invalid_argument on every rank before any message. A sink that throws stops being
// called, but the root still receives every chunk (no rank is left in MPI_Send), then
// rethrows; other ranks return normally, so a caller agrees on the failure afterwards (the
// tool's shared_failure).
// Complexity: O(N lg P) comparisons on the root for N elements in all; O(N/chunk) messages.
// Paper: none (a k-way merge; the ranks' parts are runs of the global order).
#pragma once

#include <algorithm>
#include <climits>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include <mpi.h>

#include "dynmesh/errors.hpp"

namespace dynmesh::detail {

/// Collective over `comm`. On `root`, calls sink(std::span<const T>) with the elements of
/// every rank's `local` in merged order (a chunk of at most `chunk` at a time); elsewhere,
/// sends `local` to the root and never calls sink.
template <class T, class Less, class Sink>
void merge_on_root(MPI_Comm comm, std::span<const T> local, int root, Less less, Sink&& sink,
                   std::size_t chunk = std::size_t{1} << 16) {
  static_assert(std::is_trivially_copyable_v<T>, "the parts travel as bytes");
  constexpr int kTag = 0x6d65;  // 'me': the merge's messages, apart from any other traffic
  // Every rank is given the same chunk, so every rank refuses it alike, before any message.
  if (chunk == 0 || chunk > static_cast<std::size_t>(INT_MAX) / sizeof(T))
    throw std::invalid_argument("dynmesh: merge on root: a chunk must hold 1 to INT_MAX bytes' worth of elements");
  int rank = 0, nranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &nranks);
  const std::uint64_t mine = local.size();
  std::vector<std::uint64_t> sizes(rank == root ? static_cast<std::size_t>(nranks) : 0);
  MPI_Gather(&mine, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, root, comm);
  if (rank != root) {
    for (std::size_t at = 0; at < local.size(); at += chunk) {
      const std::size_t k = std::min(chunk, local.size() - at);
      MPI_Send(local.data() + at, static_cast<int>(k * sizeof(T)), MPI_BYTE, root, kTag, comm);
    }
    return;
  }

  // A cursor per rank: the root's own part in place, the others' current chunk.
  struct Cursor {
    std::vector<T> buffer;
    std::span<const T> now;    // what is left of the current chunk
    std::uint64_t unread = 0;  // elements not yet received
  };
  std::vector<Cursor> cursors(static_cast<std::size_t>(nranks));
  const auto refill = [&](int r) {
    Cursor& c = cursors[static_cast<std::size_t>(r)];
    const std::size_t k = static_cast<std::size_t>(std::min<std::uint64_t>(chunk, c.unread));
    c.buffer.resize(k);
    MPI_Recv(c.buffer.data(), static_cast<int>(k * sizeof(T)), MPI_BYTE, r, kTag, comm, MPI_STATUS_IGNORE);
    c.unread -= k;
    c.now = std::span<const T>(c.buffer);
  };
  // The heap holds the ranks whose cursor has an element, least head on top.
  std::vector<int> heap;
  const auto head_greater = [&](int a, int b) {
    return less(cursors[static_cast<std::size_t>(b)].now.front(), cursors[static_cast<std::size_t>(a)].now.front());
  };
  for (int r = 0; r < nranks; ++r) {
    Cursor& c = cursors[static_cast<std::size_t>(r)];
    if (r == root) {
      c.now = local;
    } else {
      c.unread = sizes[static_cast<std::size_t>(r)];
      if (c.unread) refill(r);
    }
    if (!c.now.empty()) heap.push_back(r);
  }
  std::make_heap(heap.begin(), heap.end(), head_greater);

  std::vector<T> out;
  out.reserve(chunk);
  std::exception_ptr failed;
  bool have_last = false;
  T last{};
  const auto emit = [&] {
    if (!failed && !out.empty()) {
      try {
        sink(std::span<const T>(out));
      } catch (...) {
        failed = std::current_exception();
      }
    }
    out.clear();
  };
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), head_greater);
    const int r = heap.back();
    Cursor& c = cursors[static_cast<std::size_t>(r)];
    const T x = c.now.front();
    c.now = c.now.subspan(1);
    if (have_last && !less(last, x) && !failed)
      failed = std::make_exception_ptr(
          InvariantError("dynmesh: merge on root: the ranks' parts are not sorted and disjoint"));
    last = x;
    have_last = true;
    out.push_back(x);
    if (out.size() == chunk) emit();
    if (c.now.empty() && c.unread) refill(r);  // every chunk is received, whatever failed
    if (c.now.empty()) heap.pop_back();
    else std::push_heap(heap.begin(), heap.end(), head_greater);
  }
  emit();
  if (failed) std::rethrow_exception(failed);
}

}  // namespace dynmesh::detail
