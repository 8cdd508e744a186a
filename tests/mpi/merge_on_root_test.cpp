// merge_on_root_test — dynmesh/detail/merge_on_root.hpp under mpiexec (1 and 3 ranks;
// tests/mpi/CMakeLists.txt). A plain main, as mpi_quadtree_test. Each case gives every rank a
// sorted part of a random set (sizes uneven, some parts empty, the root's too) and merges
// with chunks of 1, 3 and the default, so that every rank's part arrives in many messages:
// the root must see the sorted union, in chunks of at most the chunk size, and the other
// ranks nothing. Then the failures: a chunk of 0 elements is refused on every rank; parts
// that overlap give InvariantError on the root; a sink that throws stops being called, the
// root still takes every chunk (no rank is left sending) and rethrows; the other ranks
// return normally.
// Exit status 0 when every check passed on every rank, 1 otherwise.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <random>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <mpi.h>

#include "mpi_checks.hpp"

#include "dynmesh/detail/merge_on_root.hpp"
#include "dynmesh/errors.hpp"

namespace {

using mpi_checks::check;
using mpi_checks::g_rank;
using mpi_checks::g_ranks;

struct Item {
  std::uint64_t key;
  std::uint32_t from;  // the rank that held it
};
bool less(const Item& a, const Item& b) { return a.key < b.key; }

/// The same random keys on every rank (seed), dealt to the ranks by a second draw, so each
/// rank's part is a sorted subsequence; rank `empty` gets none.
std::vector<Item> part_of(std::uint64_t seed, std::size_t n, int empty, std::vector<std::uint64_t>& all) {
  std::mt19937_64 rng(seed);
  std::set<std::uint64_t> keys;
  while (keys.size() < n) keys.insert(rng() % (4 * n + 1));
  all.assign(keys.begin(), keys.end());
  std::vector<Item> mine;
  for (const std::uint64_t k : all) {
    int r = static_cast<int>(rng() % static_cast<std::uint64_t>(g_ranks));
    if (r == empty) r = (r + 1) % g_ranks;
    if (g_ranks == 1) r = 0;
    if (r == g_rank) mine.push_back(Item{k, static_cast<std::uint32_t>(r)});
  }
  return mine;
}

void merges(std::uint64_t seed, std::size_t n, int empty, std::size_t chunk) {
  const std::string what = "seed " + std::to_string(seed) + ", n " + std::to_string(n) + ", chunk " +
                           std::to_string(chunk) + ", empty part on rank " + std::to_string(empty);
  std::vector<std::uint64_t> all;
  const std::vector<Item> mine = part_of(seed, n, empty, all);
  std::vector<std::uint64_t> got;
  std::size_t calls = 0;
  bool small = true;
  dynmesh::detail::merge_on_root<Item>(MPI_COMM_WORLD, std::span<const Item>(mine), 0, less,
                                       [&](std::span<const Item> part) {
                                         ++calls;
                                         small = small && !part.empty() && part.size() <= chunk;
                                         for (const Item& x : part) got.push_back(x.key);
                                       },
                                       chunk);
  if (g_rank == 0) {
    check(got == all, what + ": the root did not get the sorted union");
    check(small, what + ": a chunk handed to the sink was empty or over the chunk size");
  } else {
    check(calls == 0, what + ": a rank other than the root called the sink");
  }
}

void overlapping_parts_fail() {
  // Every rank holds key 7: the parts are not disjoint.
  const std::vector<Item> mine{{static_cast<std::uint64_t>(g_rank), 0}, {7, 0}, {100 + static_cast<std::uint64_t>(g_rank), 0}};
  bool threw = false;
  try {
    dynmesh::detail::merge_on_root<Item>(MPI_COMM_WORLD, std::span<const Item>(mine), 0, less,
                                         [](std::span<const Item>) {}, 2);
  } catch (const dynmesh::InvariantError&) {
    threw = true;
  }
  check(threw == (g_rank == 0 && g_ranks > 1), "overlapping parts: InvariantError expected on the root only");
}

void throwing_sink_drains() {
  std::vector<std::uint64_t> all;
  const std::vector<Item> mine = part_of(99, 5000, -1, all);
  std::size_t calls = 0;
  bool threw = false;
  try {
    dynmesh::detail::merge_on_root<Item>(MPI_COMM_WORLD, std::span<const Item>(mine), 0, less,
                                         [&](std::span<const Item>) {
                                           if (++calls == 2) throw std::runtime_error("disk full");
                                         },
                                         16);
  } catch (const std::runtime_error& e) {
    threw = std::string(e.what()) == "disk full";
  }
  check(threw == (g_rank == 0), "a sink that throws: the root rethrows, the others return");
  check(g_rank != 0 || calls == 2, "a sink that threw was called again");
  // Every rank is past the merge: a barrier that returns shows no rank was left sending.
  MPI_Barrier(MPI_COMM_WORLD);
}

}  // namespace

int main(int argc, char** argv) {
  mpi_checks::start(&argc, &argv);
  try {
    for (const std::size_t chunk : {std::size_t{1}, std::size_t{3}, std::size_t{1} << 16}) {
      merges(1, 2000, -1, chunk);
      merges(2, 2000, 0, chunk);  // the root holds nothing
      merges(3, 1, -1, chunk);
      merges(4, 0, -1, chunk);
      if (g_ranks > 2) merges(5, 300, 2, chunk);
    }
    overlapping_parts_fail();
    bool refused = false;
    try {
      dynmesh::detail::merge_on_root<Item>(MPI_COMM_WORLD, std::span<const Item>(), 0, less, [](std::span<const Item>) {}, 0);
    } catch (const std::invalid_argument&) {
      refused = true;
    }
    check(refused, "a chunk of 0 elements was not refused");
    throwing_sink_drains();
  } catch (const std::exception& e) {
    check(false, std::string("exception: ") + e.what());
  }
  return mpi_checks::finish("merge_on_root_test");
}
