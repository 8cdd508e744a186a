// mpi_quadtree.cpp — MpiQuadtree: partition, ghosts, routing, the coarse top, repartition
// (dynmesh/mpi_quadtree.hpp states the contract; docs/DISTRIBUTED.md the argument).
#include "dynmesh/mpi_quadtree.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstring>
#include <optional>
#include <string>
#include <utility>

#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/errors.hpp"
#include "mpi/agreed_error.hpp"
#include "mpi/morton.hpp"
#include "mpi/mpi_state.hpp"

namespace dynmesh {

template <std::size_t d>
  requires SupportedDim<d>
MpiQuadtree<d>::MpiQuadtree(MPI_Comm comm, const Box<d>& box, std::span<const Point<d>> points,
                            const MpiQuadtreeOptions& options)
    : s_(std::make_unique<detail::MpiState<d, DynamicQuadtree<d>>>()) {
  s_->construct(comm, box, points, options);
}

template <std::size_t d>
  requires SupportedDim<d>
MpiQuadtree<d>::~MpiQuadtree() = default;
template <std::size_t d>
  requires SupportedDim<d>
MpiQuadtree<d>::MpiQuadtree(MpiQuadtree&&) noexcept = default;
template <std::size_t d>
  requires SupportedDim<d>
MpiQuadtree<d>& MpiQuadtree<d>::operator=(MpiQuadtree&&) noexcept = default;

template <std::size_t d>
  requires SupportedDim<d>
void MpiQuadtree<d>::apply(std::span<const Edit<d>> edits) {
  s_->apply_batch(edits);
  s_->maybe_repartition();
}

template <std::size_t d>
  requires SupportedDim<d>
const Box<d>& MpiQuadtree<d>::box() const noexcept { return s_->box; }

template <std::size_t d>
  requires SupportedDim<d>
int MpiQuadtree<d>::partition_level() const noexcept { return s_->l0; }

template <std::size_t d>
  requires SupportedDim<d>
std::span<const std::uint64_t> MpiQuadtree<d>::starts() const noexcept { return s_->starts; }

template <std::size_t d>
  requires SupportedDim<d>
std::size_t MpiQuadtree<d>::size() const noexcept { return s_->total; }

template <std::size_t d>
  requires SupportedDim<d>
std::vector<Leaf<d>> MpiQuadtree<d>::local_leaves() const {
  using namespace detail;
  const auto& s = *s_;
  std::vector<Leaf<d>> out;
  for (std::uint64_t m = s.starts[s.rank]; m < s.starts[s.rank + 1]; ++m) {
    const CellId<d> c = from_morton<d>(m, s.l0);
    if (s.root_split[m]) {
      const std::vector<Leaf<d>> inside = s.tree->leaves_in(c);
      out.insert(out.end(), inside.begin(), inside.end());
    } else if (s.root_is_leaf(m)) {
      out.push_back(Leaf<d>{c, s.counts[m]});
    }
  }
  if (s.rank == 0)
    for (int l = 0; l < s.l0; ++l) {
      const auto& level = s.coarse[static_cast<std::size_t>(l)];
      for (std::uint64_t m = 0; m < level.size(); ++m) {
        if (level[m] & kSplit) continue;
        if (l > 0 && !(s.coarse[static_cast<std::size_t>(l - 1)][m >> d] & kSplit)) continue;
        out.push_back(Leaf<d>{from_morton<d>(m, l), static_cast<std::uint32_t>(level[m] >> kClassShift)});
      }
    }
  std::sort(out.begin(), out.end());
  return out;
}

template <std::size_t d>
std::vector<Leaf<d>> gather_leaves(MPI_Comm comm, std::span<const Leaf<d>> local, int root) {
  // Packed as d + 1 words: (level | npoints << 8), then the indices.
  std::vector<std::uint64_t> words;
  words.reserve(local.size() * (d + 1));
  for (const Leaf<d>& leaf : local) {
    words.push_back(static_cast<std::uint64_t>(leaf.cell.level) | (std::uint64_t{leaf.npoints} << 8));
    for (std::size_t a = 0; a < d; ++a) words.push_back(leaf.cell.index[a]);
  }
  int rank = 0, nranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &nranks);
  const int n = static_cast<int>(words.size());
  std::vector<int> counts(static_cast<std::size_t>(nranks)), at(static_cast<std::size_t>(nranks));
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, root, comm);
  std::size_t total = 0;
  if (rank == root)
    for (int r = 0; r < nranks; ++r) {
      at[r] = static_cast<int>(total);
      total += static_cast<std::size_t>(counts[r]);
    }
  std::vector<std::uint64_t> all(total);
  MPI_Gatherv(words.data(), n, MPI_UINT64_T, all.data(), counts.data(), at.data(), MPI_UINT64_T, root, comm);
  words.clear();
  words.shrink_to_fit();
  std::vector<Leaf<d>> out;
  out.reserve(total / (d + 1));
  for (std::size_t i = 0; i + d < total; i += d + 1) {
    Leaf<d> leaf;
    leaf.cell.level = static_cast<int>(all[i] & 0xff);
    leaf.npoints = static_cast<std::uint32_t>(all[i] >> 8);
    for (std::size_t a = 0; a < d; ++a) leaf.cell.index[a] = all[i + 1 + a];
    out.push_back(leaf);
  }
  std::sort(out.begin(), out.end());
  return out;
}

template <std::size_t d>
  requires SupportedDim<d>
std::vector<Leaf<d>> MpiQuadtree<d>::gather_leaves(int root) const {
  const std::vector<Leaf<d>> mine = local_leaves();
  return dynmesh::gather_leaves<d>(s_->comm, mine, root);
}

template <std::size_t d>
  requires SupportedDim<d>
MpiRankStats MpiQuadtree<d>::rank_stats() const {
  return s_->rank_stats();
}

template <std::size_t d>
  requires SupportedDim<d>
void MpiQuadtree<d>::check_invariants() const {
  using namespace detail;
  const auto& s = *s_;
  std::optional<Failure> failure;
  s.check_partition(failure);
  agree_or_throw(s.comm, failure);

  // The union of the leaves is T* of the union of the owned points (check_tree on rank 0).
  const std::vector<Leaf<d>> leaves = gather_leaves(0);
  std::vector<Position<d>> owned;
  for (const Position<d>& q : s.tree->positions())
    if (s.role[s.root_of(q)] == 1) owned.push_back(q);
  const std::vector<Position<d>> points = gather_all(s.comm, owned);
  if (s.rank == 0) {
    const CheckReport<d> report = check_tree<d>(points, leaves);
    if (!report.ok()) s.fail(failure, "the gathered leaves are not T*: " + report.summary());
  }
  agree_or_throw(s.comm, failure);
}

template class MpiQuadtree<2>;
template class MpiQuadtree<3>;
template std::vector<Leaf<2>> gather_leaves<2>(MPI_Comm, std::span<const Leaf<2>>, int);
template std::vector<Leaf<3>> gather_leaves<3>(MPI_Comm, std::span<const Leaf<3>>, int);

}  // namespace dynmesh
