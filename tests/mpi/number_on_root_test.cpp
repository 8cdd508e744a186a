// number_on_root_test — dynmesh/detail/number_on_root.hpp under mpiexec (1 and 3 ranks;
// tests/mpi/CMakeLists.txt). A plain main, as merge_on_root_test. Every rank draws every
// rank's part from the same seed, so each can build the serial oracle: the sorted, deduplicated
// union, and each element's position in it. The parts overlap heavily (each rank takes a random
// subset of 0..K, with uneven densities), one or all of them may be empty, and the elements
// are keys tagged with their rank (the sink must get the lowest rank's copy of a shared key)
// or pairs of doubles, as the mesh's vertices, where 0 and -0 are the same vertex. Chunks of
// 1, 3 and 65,536 elements. Then the failures: a chunk of 0 or of too many bytes is refused on
// every rank; a part that does not strictly increase gives InvariantError on the root; a sink
// that throws after its first chunk is rethrown on the root, the others' numbers are right.
// A barrier after each failure shows that no rank was left in the protocol.
// Exit status 0 when every check passed on every rank, 1 otherwise.
#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <mpi.h>

#include "mpi_checks.hpp"

#include "dynmesh/detail/number_on_root.hpp"
#include "dynmesh/errors.hpp"

namespace {

using mpi_checks::check;
using mpi_checks::g_rank;
using mpi_checks::g_ranks;

struct Item {
  std::uint64_t key;
  std::uint32_t from;  // the rank that held it
};
bool item_less(const Item& a, const Item& b) { return a.key < b.key; }

using Pair = std::array<double, 2>;
bool pair_less(const Pair& a, const Pair& b) { return a < b; }  // lexicographic

/// Every rank's part of a random cover of 0..k (seed): rank r takes each value with a
/// probability of its own, so sizes are uneven and most values are shared; rank `empty`
/// takes none (-1: none empty; -2: all empty).
std::vector<std::vector<std::uint64_t>> parts_of(std::uint64_t seed, std::uint64_t k, int empty) {
  std::mt19937_64 rng(seed);
  std::vector<std::vector<std::uint64_t>> parts(static_cast<std::size_t>(g_ranks));
  for (std::uint64_t v = 0; v <= k; ++v)
    for (int r = 0; r < g_ranks; ++r) {
      const bool take = rng() % 8 < static_cast<std::uint64_t>(2 + 2 * (r % 3));  // 1/4, 1/2, 3/4
      if (take && r != empty && empty != -2) parts[static_cast<std::size_t>(r)].push_back(v);
    }
  return parts;
}

/// The oracle: the sorted distinct union, and this rank's numbers in it.
template <class T, class Less>
std::vector<T> union_of(const std::vector<std::vector<T>>& parts, Less less) {
  std::vector<T> all;
  for (const auto& p : parts) all.insert(all.end(), p.begin(), p.end());
  std::stable_sort(all.begin(), all.end(), less);  // stable: the lowest rank's copy first
  all.erase(std::unique(all.begin(), all.end(), [&](const T& a, const T& b) { return !less(a, b) && !less(b, a); }),
            all.end());
  return all;
}
template <class T, class Less>
std::vector<std::uint64_t> numbers_in(const std::vector<T>& all, const std::vector<T>& mine, Less less) {
  std::vector<std::uint64_t> n;
  for (const T& x : mine)
    n.push_back(static_cast<std::uint64_t>(std::lower_bound(all.begin(), all.end(), x, less) - all.begin()));
  return n;
}

/// Runs number_on_root on this rank's part of `parts` and checks it against the oracle: the
/// root's sink gets the union, every chunk non-empty and within the chunk size; other ranks'
/// sinks are never called; numbers and total are right everywhere. `same` compares the sink's
/// elements with the oracle's bit for bit (which copy of equal elements).
template <class T, class Less, class Same>
void numbers(const std::string& what, const std::vector<std::vector<T>>& parts, Less less, Same same,
             std::size_t chunk) {
  const std::vector<T>& mine = parts[static_cast<std::size_t>(g_rank)];
  const std::vector<T> all = union_of(parts, less);
  std::vector<T> got;
  std::size_t calls = 0;
  bool small = true;
  std::uint64_t total = ~std::uint64_t{0};
  const std::vector<std::uint64_t> n = dynmesh::detail::number_on_root<T>(
      MPI_COMM_WORLD, std::span<const T>(mine), 0, less,
      [&](std::span<const T> part) {
        ++calls;
        small = small && !part.empty() && part.size() <= chunk;
        got.insert(got.end(), part.begin(), part.end());
      },
      total, chunk);
  const std::string at = what + ", chunk " + std::to_string(chunk);
  check(n == numbers_in(all, mine, less), at + ": wrong numbers");
  check(total == all.size(), at + ": wrong total");
  if (g_rank == 0) {
    check(got.size() == all.size() && std::equal(got.begin(), got.end(), all.begin(), same),
          at + ": the root's sink did not get the distinct union (lowest rank's copies)");
    check(small, at + ": a chunk handed to the sink was empty or over the chunk size");
  } else {
    check(calls == 0, at + ": a rank other than the root called the sink");
  }
}

std::vector<std::vector<Item>> items_of(std::uint64_t seed, std::uint64_t k, int empty) {
  std::vector<std::vector<Item>> parts(static_cast<std::size_t>(g_ranks));
  const auto keys = parts_of(seed, k, empty);
  for (int r = 0; r < g_ranks; ++r)
    for (const std::uint64_t v : keys[static_cast<std::size_t>(r)])
      parts[static_cast<std::size_t>(r)].push_back(Item{v, static_cast<std::uint32_t>(r)});
  return parts;
}
bool same_item(const Item& a, const Item& b) { return a.key == b.key && a.from == b.from; }

/// Points of a 30 x 30 grid around 0, as pairs of doubles; odd ranks write 0 as -0, which
/// compares equal. The sink must get rank 0's copy, +0, when rank 0 holds the point.
std::vector<std::vector<Pair>> pairs_of(std::uint64_t seed, int empty) {
  std::vector<std::vector<Pair>> parts(static_cast<std::size_t>(g_ranks));
  const auto keys = parts_of(seed, 30 * 30 - 1, empty);
  for (int r = 0; r < g_ranks; ++r)
    for (const std::uint64_t v : keys[static_cast<std::size_t>(r)]) {
      double x = 0.5 * (static_cast<double>(v / 30) - 15), y = 0.5 * (static_cast<double>(v % 30) - 15);
      if (r % 2) {
        if (x == 0) x = -0.0;
        if (y == 0) y = -0.0;
      }
      parts[static_cast<std::size_t>(r)].push_back(Pair{x, y});
    }
  return parts;
}
bool same_pair(const Pair& a, const Pair& b) {
  return a == b && std::signbit(a[0]) == std::signbit(b[0]) && std::signbit(a[1]) == std::signbit(b[1]);
}

/// A part that does not strictly increase, on the last rank (the root itself on 1 rank): a
/// repeat across a chunk's boundary, or a descent. InvariantError on the root only.
void bad_part_fails() {
  const std::vector<std::vector<std::uint64_t>> bad{{1, 2, 2, 3}, {1, 5, 4}};
  for (const auto& b : bad) {
    std::vector<Item> mine{{static_cast<std::uint64_t>(g_rank), 0}, {7, 0}};  // 7 shared, which is fine
    if (g_rank == g_ranks - 1) {
      mine.clear();
      for (const std::uint64_t k : b) mine.push_back(Item{k, 0});
    }
    bool threw = false;
    std::uint64_t total = 0;
    try {
      dynmesh::detail::number_on_root<Item>(MPI_COMM_WORLD, std::span<const Item>(mine), 0, item_less,
                                            [](std::span<const Item>) {}, total, 2);
    } catch (const dynmesh::InvariantError&) {
      threw = true;
    }
    check(threw == (g_rank == 0), "a part that does not strictly increase: InvariantError expected on the root only");
    MPI_Barrier(MPI_COMM_WORLD);
  }
}

void bad_chunks_refused() {
  for (const std::size_t chunk : {std::size_t{0}, static_cast<std::size_t>(INT_MAX) / sizeof(Item) + 1}) {
    bool refused = false;
    std::uint64_t total = 0;
    try {
      dynmesh::detail::number_on_root<Item>(MPI_COMM_WORLD, std::span<const Item>(), 0, item_less,
                                            [](std::span<const Item>) {}, total, chunk);
    } catch (const std::invalid_argument&) {
      refused = true;
    }
    check(refused, "a chunk of " + std::to_string(chunk) + " elements was not refused");
  }
}

void throwing_sink_drains() {
  const auto parts = items_of(99, 3000, -1);
  const std::vector<Item>& mine = parts[static_cast<std::size_t>(g_rank)];
  const std::vector<Item> all = union_of(parts, item_less);
  std::size_t calls = 0;
  bool threw = false;
  std::uint64_t total = 0;
  std::vector<std::uint64_t> n;
  try {
    n = dynmesh::detail::number_on_root<Item>(MPI_COMM_WORLD, std::span<const Item>(mine), 0, item_less,
                                              [&](std::span<const Item>) {
                                                if (++calls == 1) throw std::runtime_error("disk full");
                                              },
                                              total, 16);
  } catch (const std::runtime_error& e) {
    threw = std::string(e.what()) == "disk full";
  }
  check(threw == (g_rank == 0), "a sink that throws: the root rethrows, the others return");
  check(g_rank != 0 || calls == 1, "a sink that threw was called again");
  check(g_rank == 0 || n == numbers_in(all, mine, item_less), "a sink that throws: wrong numbers");
  check(total == all.size(), "a sink that throws: wrong total");
  MPI_Barrier(MPI_COMM_WORLD);
}

}  // namespace

int main(int argc, char** argv) {
  mpi_checks::start(&argc, &argv);
  try {
    for (const std::size_t chunk : {std::size_t{1}, std::size_t{3}, std::size_t{1} << 16}) {
      numbers("keys, none empty", items_of(1, 2000, -1), item_less, same_item, chunk);
      numbers("keys, root empty", items_of(2, 2000, 0), item_less, same_item, chunk);
      if (g_ranks > 2) numbers("keys, rank 2 empty", items_of(3, 500, 2), item_less, same_item, chunk);
      numbers("keys, all empty", items_of(4, 100, -2), item_less, same_item, chunk);
      numbers("keys, one value", items_of(5, 0, -1), item_less, same_item, chunk);
      numbers("pairs, none empty", pairs_of(6, -1), pair_less, same_pair, chunk);
      numbers("pairs, root empty", pairs_of(7, 0), pair_less, same_pair, chunk);
    }
    bad_chunks_refused();
    bad_part_fails();
    throwing_sink_drains();
  } catch (const std::exception& e) {
    check(false, std::string("exception: ") + e.what());
  }
  return mpi_checks::finish("number_on_root_test");
}
