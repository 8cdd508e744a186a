// dynmesh/detail/number_on_root.hpp — the ranks' sorted, overlapping parts numbered on one rank.
//
// Purpose: writing a distributed mesh's .node and .ele. Vertices are numbered in sorted order
// over the union of the ranks' vertices, and a vertex on the boundary between ranks' regions
// is held by several ranks. The root merges the parts as a stream (as merge_on_root.hpp),
// gives equal elements one number, hands the distinct elements to a sink in chunks (the
// .node lines), and sends each rank the numbers of its own elements, in its order (so the
// rank can renumber its triangles). The root holds its own part and its numbers, one chunk
// and one reply per other rank, and one output chunk; no rank holds the union.
// Protocol: the parts' sizes meet on the root (MPI_Gather). Each other rank then alternates:
// it sends chunk c of at most `chunk` elements (blocking MPI_Send, tag kChunkTag), receives
// the numbers of chunk c (exactly its length, tag kReplyTag), and only then sends chunk c+1.
// The root replies to a chunk once it has merged all of it, and only then receives that
// rank's next one. A rank waits only on the root, and the root only on a rank that is sending
// the chunk it asks for or waiting for the reply it sends, so no order of arrival (and no
// rendezvous MPI_Send) can deadlock. The union's size ends the call (MPI_Bcast). The root's
// own part takes no messages.
// Invariants (checked on the root): each rank's part strictly increases by `less`;
// InvariantError otherwise. Equality is equivalence under `less`, which must be a strict weak
// order (no NaN). Of equal elements the sink gets the copy of the lowest rank holding one:
// ties in the merge are broken by rank, so the output and the numbers are the same whatever
// the arrival order or the chunk size.
// Errors: a chunk of 0 elements, or of more bytes than an MPI count holds, throws
// std::invalid_argument on every rank before any message. A failure on the root (a part that
// does not increase, a sink that throws) stops the sink being called, but the root still
// takes every chunk, sends every reply and broadcasts the size, then rethrows; the other ranks
// return normally (their numbers are right after a sink's failure, meaningless after an
// invariant's), so a caller agrees on the failure afterwards (the tool's shared_failure).
// Complexity: O(N lg P) comparisons on the root for N elements held in all (duplicates
// counted); O(N/chunk) messages each way; memory on the root O(own part + P * chunk).
// Paper: none (a k-way merge that numbers runs of the global order, duplicates dropped).
#pragma once

#include <algorithm>
#include <climits>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <mpi.h>

#include "dynmesh/errors.hpp"

namespace dynmesh::detail {

/// Collective over comm. Every rank's `local` is sorted strictly increasing by `less` (equal
/// elements may appear on several ranks). On `root`, calls sink(std::span<const T>) with the
/// distinct elements of the union in increasing order, a chunk at a time. On every rank,
/// returns numbers[i] = the 0-based position of local[i] in that distinct union. Returns the
/// union's size on every rank via `total` (MPI_Bcast at the end).
template <class T, class Less, class Sink>
std::vector<std::uint64_t> number_on_root(MPI_Comm comm, std::span<const T> local, int root, Less less,
                                          Sink&& sink, std::uint64_t& total,
                                          std::size_t chunk = std::size_t{1} << 16) {
  static_assert(std::is_trivially_copyable_v<T>, "the parts travel as bytes");
  // 'nc' and 'nr': apart from merge_on_root's 0x6d65 and from each other, so a reply can never
  // be taken for a chunk.
  constexpr int kChunkTag = 0x6e63;
  constexpr int kReplyTag = 0x6e72;
  // Every rank is given the same chunk, so every rank refuses it alike, before any message. A
  // reply's count (chunk elements of uint64) is then within an int too.
  if (chunk == 0 || chunk > static_cast<std::size_t>(INT_MAX) / sizeof(T))
    throw std::invalid_argument("dynmesh: number on root: a chunk must hold 1 to INT_MAX bytes' worth of elements");
  int rank = 0, nranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &nranks);
  const std::uint64_t mine = local.size();
  std::vector<std::uint64_t> sizes(rank == root ? static_cast<std::size_t>(nranks) : 0);
  MPI_Gather(&mine, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, root, comm);
  std::vector<std::uint64_t> numbers(local.size());
  if (rank != root) {
    for (std::size_t at = 0; at < local.size(); at += chunk) {
      const std::size_t k = std::min(chunk, local.size() - at);
      MPI_Send(local.data() + at, static_cast<int>(k * sizeof(T)), MPI_BYTE, root, kChunkTag, comm);
      MPI_Recv(numbers.data() + at, static_cast<int>(k), MPI_UINT64_T, root, kReplyTag, comm, MPI_STATUS_IGNORE);
    }
    MPI_Bcast(&total, 1, MPI_UINT64_T, root, comm);
    return numbers;
  }

  // A cursor per rank: the root's own part in place, numbered into `numbers`; another rank's
  // current chunk, numbered into the reply for it.
  struct Cursor {
    std::vector<T> buffer;
    std::span<const T> now;  // what is left of the current chunk
    std::vector<std::uint64_t> reply;
    std::uint64_t* next = nullptr;  // where the number of now.front() goes
    std::uint64_t unread = 0;       // elements not yet received
    std::optional<T> prev;          // the rank's last element merged, across chunks
  };
  std::vector<Cursor> cursors(static_cast<std::size_t>(nranks));
  const auto refill = [&](int r) {
    Cursor& c = cursors[static_cast<std::size_t>(r)];
    const std::size_t k = static_cast<std::size_t>(std::min<std::uint64_t>(chunk, c.unread));
    c.buffer.resize(k);
    MPI_Recv(c.buffer.data(), static_cast<int>(k * sizeof(T)), MPI_BYTE, r, kChunkTag, comm, MPI_STATUS_IGNORE);
    c.unread -= k;
    c.now = std::span<const T>(c.buffer);
    c.reply.resize(k);
    c.next = c.reply.data();
  };
  // The heap holds the ranks whose cursor has an element, least (head, rank) on top: the rank
  // breaks ties so that the order of equal elements, and which copy the sink gets, is fixed.
  std::vector<int> heap;
  const auto head_greater = [&](int a, int b) {
    const T& x = cursors[static_cast<std::size_t>(a)].now.front();
    const T& y = cursors[static_cast<std::size_t>(b)].now.front();
    return less(y, x) || (!less(x, y) && a > b);
  };
  for (int r = 0; r < nranks; ++r) {
    Cursor& c = cursors[static_cast<std::size_t>(r)];
    if (r == root) {
      c.now = local;
      c.next = numbers.data();
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
  std::uint64_t count = 0;  // distinct elements so far
  std::optional<T> last;    // the last distinct one
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), head_greater);
    const int r = heap.back();
    Cursor& c = cursors[static_cast<std::size_t>(r)];
    const T x = c.now.front();
    c.now = c.now.subspan(1);
    if (c.prev && !less(*c.prev, x) && !failed)
      failed = std::make_exception_ptr(InvariantError("dynmesh: number on root: the part of rank " +
                                                      std::to_string(r) + " does not strictly increase"));
    c.prev = x;
    // With every part increasing, x is at least `last`, so "not greater" means equal. (A part
    // that is not has already failed; the numbers only have to stay in range.)
    if (!last || less(*last, x)) {
      last = x;
      ++count;
      out.push_back(x);
      if (out.size() == chunk) emit();
    }
    *c.next++ = count - 1;
    if (c.now.empty() && r != root) {
      // Every reply is sent and every chunk received, whatever failed.
      MPI_Send(c.reply.data(), static_cast<int>(c.reply.size()), MPI_UINT64_T, r, kReplyTag, comm);
      if (c.unread) refill(r);
    }
    if (c.now.empty()) heap.pop_back();
    else std::push_heap(heap.begin(), heap.end(), head_greater);
  }
  emit();
  total = count;
  MPI_Bcast(&total, 1, MPI_UINT64_T, root, comm);
  if (failed) std::rethrow_exception(failed);
  return numbers;
}

}  // namespace dynmesh::detail
