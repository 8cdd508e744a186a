// mpi_mesh.cpp — MpiMesh: the tree meshes over MpiState, each rank meshing its own and its
// ghost root cells (dynmesh/mpi_mesh.hpp states the contract; docs/DISTRIBUTED.md, "The
// meshes on ranks", the argument).
#include "dynmesh/mpi_mesh.hpp"

#include <algorithm>
#include <optional>
#include <string>
#include <utility>

#include "dynmesh/errors.hpp"
#include "mpi/agreed_error.hpp"
#include "mpi/morton.hpp"
#include "mpi/mpi_state.hpp"

namespace dynmesh {
namespace detail {

template <>
struct LocalTraits<DynamicMesh> {
  static DynamicMesh build(const Box<2>& box, std::span<const Point<2>> points, int split_below) {
    MeshOptions options;
    options.postprocess = Postprocess::Quadtree;
    options.tree.split_below = split_below;
    return DynamicMesh(box, points, options);
  }
  static std::vector<Triangle> simplices(const DynamicMesh& mesh) { return mesh.triangles(); }
  static const MeshChange& change(const DynamicMesh& mesh) { return mesh.last_change(); }
};

template <>
struct LocalTraits<DynamicOctreeMesh> {
  static DynamicOctreeMesh build(const Box<3>& box, std::span<const Point<3>> points, int split_below) {
    return DynamicOctreeMesh(box, points, DynamicQuadtreeOptions{split_below});
  }
  static std::vector<Tetrahedron> simplices(const DynamicOctreeMesh& mesh) { return mesh.tetrahedra(); }
  static const TetMeshChange& change(const DynamicOctreeMesh& mesh) { return mesh.last_change(); }
};

template <std::size_t d>
using LocalMesh = std::conditional_t<d == 2, DynamicMesh, DynamicOctreeMesh>;

template <std::size_t d>
struct MpiMeshState : MpiState<d, LocalMesh<d>> {
  using Base = MpiState<d, LocalMesh<d>>;
  using Local = LocalMesh<d>;
  using Simplex = MeshSimplex<d>;
  using Base::box;
  using Base::coarse;
  using Base::counts;
  using Base::l0;
  using Base::nroots;
  using Base::role;
  using Base::tree;

  OwnedChange<d> change;

  /// Is every cell of T* coarser than l0 split (no leaf of T* above a root cell)?
  bool top_split() const {
    if (l0 == 0) return true;
    const auto& level = coarse[static_cast<std::size_t>(l0 - 1)];
    return std::all_of(level.begin(), level.end(), [](std::uint8_t v) { return (v & kSplit) != 0; });
  }

  /// The level of T*'s coarsest leaf, if it is coarser than l0 (else l0).
  int coarsest_leaf() const {
    for (int l = 0; l < l0; ++l) {
      const auto& level = coarse[static_cast<std::size_t>(l)];
      for (std::uint64_t m = 0; m < level.size(); ++m)
        if (!(level[m] & kSplit) && (l == 0 || (coarse[static_cast<std::size_t>(l - 1)][m >> d] & kSplit))) return l;
    }
    return l0;
  }

  /// Collective: the partition moved to the coarser `level` and the local meshes rebuilt on
  /// the points the ranks own. The summaries are recounted from those points, so they hold
  /// for them whatever the tables said before (apply() comes here with a batch put back).
  void rebuild_at(int level) {
    const std::vector<Routed<d>> mine = this->owned_routed();
    std::vector<std::uint32_t> here(std::uint64_t{1} << (d * static_cast<std::size_t>(level)), 0);
    for (const Routed<d>& p : mine) ++here[morton(cell_of(dynmesh::locate(box, p.point), level))];
    counts.assign(here.size(), 0);
    MPI_Allreduce(here.data(), counts.data(), static_cast<int>(here.size()), MPI_UINT32_T, MPI_SUM, this->comm);
    l0 = level;
    nroots = counts.size();
    this->total = 0;
    for (const std::uint32_t k : counts) this->total += k;
    this->redistribute(mine);
    this->gather_root_split();
    this->compute_coarse();
  }

  /// The root cell holding the centroid of the corners `at(0..d)` (canonical order), in
  /// doubles: the same on every rank, so every simplex has one owner.
  template <class Corner>
  std::uint64_t owner_root(Corner&& at) const {
    Point<d> c{};
    for (std::size_t a = 0; a < d; ++a) {
      double sum = 0;
      for (std::size_t k = 0; k <= d; ++k) sum += at(k)[a];
      c[a] = sum / static_cast<double>(d + 1);
    }
    return this->root_of(dynmesh::locate(box, c));
  }
  std::uint64_t owner_root(const Simplex& s) const {
    return owner_root([&s](std::size_t k) -> const Point<d>& { return s.v[k]; });
  }

  std::vector<Simplex> owned(const std::vector<Simplex>& all) const {
    std::vector<Simplex> out;
    for (const Simplex& s : all)
      if (role[owner_root(s)] == 1) out.push_back(s);
    return out;
  }

  void apply(std::span<const Edit<d>> edits) {
    std::vector<Routed<d>> in = this->apply_batch(edits);
    if (!top_split()) {
      // A leaf of T* is now coarser than l0: put the batch back, move l0 up to that leaf's
      // level, and apply it again on the new partition, so that its change is taken from
      // local meshes that are right for both point sets.
      const int level = coarsest_leaf();
      std::vector<Edit<d>> batch;
      for (const Routed<d>& r : in) batch.push_back(Edit<d>{static_cast<EditOp>(r.op), r.point});
      if (!batch.empty()) this->put_back(batch);
      rebuild_at(level);
      in = this->apply_batch(edits);
    }
    change = OwnedChange<d>{};
    if (!in.empty()) {
      const auto& local = LocalTraits<Local>::change(*tree);
      change.removed = owned(local.removed);
      change.added = owned(local.added);
    }
    this->maybe_repartition();
  }
};

}  // namespace detail

template <std::size_t d>
  requires SupportedDim<d>
MpiMesh<d>::MpiMesh(MPI_Comm comm, const Box<d>& box, std::span<const Point<d>> points,
                    const MpiQuadtreeOptions& options)
    : s_(std::make_unique<detail::MpiMeshState<d>>()) {
  MpiQuadtreeOptions chosen = options;
  if (chosen.partition_level < 0) {
    // The finest partition the meshes allow is T*'s coarsest leaf (capped at the finest level
    // counted): the finer the root cells, the thinner the ring of 3 around a rank's run. T*
    // alone finds it, at a fraction of a mesh's cost, and is freed before the meshes are built.
    MpiQuadtreeOptions probe;
    probe.partition_level = detail::kMaxPartitionLevel<d>;
    probe.rebalance_factor = 0;
    int coarsest = detail::kMaxPartitionLevel<d>;
    {
      const MpiQuadtree<d> tree(comm, box, points, probe);
      for (const Leaf<d>& leaf : tree.local_leaves()) coarsest = std::min(coarsest, leaf.cell.level);
    }
    int least = coarsest;
    MPI_Allreduce(&coarsest, &least, 1, MPI_INT, MPI_MIN, comm);
    chosen.partition_level = least;
  }
  s_->split_to_l0 = true;
  s_->construct(comm, box, points, chosen);
  if (!s_->top_split()) s_->rebuild_at(s_->coarsest_leaf());
}

template <std::size_t d>
  requires SupportedDim<d>
MpiMesh<d>::~MpiMesh() = default;
template <std::size_t d>
  requires SupportedDim<d>
MpiMesh<d>::MpiMesh(MpiMesh&&) noexcept = default;
template <std::size_t d>
  requires SupportedDim<d>
MpiMesh<d>& MpiMesh<d>::operator=(MpiMesh&&) noexcept = default;

template <std::size_t d>
  requires SupportedDim<d>
void MpiMesh<d>::apply(std::span<const Edit<d>> edits) {
  s_->apply(edits);
}

template <std::size_t d>
  requires SupportedDim<d>
const Box<d>& MpiMesh<d>::box() const noexcept { return s_->box; }

template <std::size_t d>
  requires SupportedDim<d>
int MpiMesh<d>::partition_level() const noexcept { return s_->l0; }

template <std::size_t d>
  requires SupportedDim<d>
std::size_t MpiMesh<d>::size() const noexcept { return s_->total; }

template <std::size_t d>
  requires SupportedDim<d>
std::vector<typename MpiMesh<d>::Simplex> MpiMesh<d>::local_simplices() const {
  return s_->owned(detail::LocalTraits<detail::LocalMesh<d>>::simplices(*s_->tree));
}

template <std::size_t d>
  requires SupportedDim<d>
CanonicalMesh<d> MpiMesh<d>::owned_mesh() const {
  const auto& s = *s_;
  const CanonicalMesh<d> all = s.tree->mesh();
  const auto& cells = [&]() -> const auto& {
    if constexpr (d == 2) return all.triangles;
    else return all.tetrahedra;
  }();
  CanonicalMesh<d> out;
  auto& kept = [&]() -> auto& {
    if constexpr (d == 2) return out.triangles;
    else return out.tetrahedra;
  }();
  constexpr std::uint32_t kUnused = ~std::uint32_t{0};
  std::vector<std::uint32_t> renumber(all.vertices.size(), kUnused);
  for (const auto& c : cells) {
    const std::uint64_t m = s.owner_root([&](std::size_t k) -> const Point<d>& { return all.vertices[c[k]]; });
    if (s.role[m] != 1) continue;
    kept.push_back(c);
    for (const std::uint32_t v : c) renumber[v] = 0;
  }
  // The kept vertices in their order: a monotone renumbering keeps every tuple canonical and
  // the tuples sorted.
  for (std::size_t v = 0; v < all.vertices.size(); ++v)
    if (renumber[v] != kUnused) {
      renumber[v] = static_cast<std::uint32_t>(out.vertices.size());
      out.vertices.push_back(all.vertices[v]);
    }
  for (auto& c : kept)
    for (std::uint32_t& v : c) v = renumber[v];
  return out;
}

template <std::size_t d>
  requires SupportedDim<d>
const OwnedChange<d>& MpiMesh<d>::local_change() const noexcept { return s_->change; }

template <std::size_t d>
  requires SupportedDim<d>
MpiRankStats MpiMesh<d>::rank_stats() const {
  return s_->rank_stats();
}

template <std::size_t d>
  requires SupportedDim<d>
void MpiMesh<d>::check_invariants() const {
  using namespace detail;
  const auto& s = *s_;
  std::optional<Failure> failure;
  s.check_partition(failure);
  if (!s.top_split()) s.fail(failure, "a leaf of T* is coarser than the partition level " + std::to_string(s.l0));
  agree_or_throw(s.comm, failure);

  // The union of the owned simplices is the one-process mesh of the union of the points.
  const std::vector<Simplex> mine = local_simplices();
  std::vector<Point<d>> owned_points;
  for (const auto& entry : s.tree->points())
    if (s.role[s.root_of(dynmesh::locate(s.box, entry.second))] == 1) owned_points.push_back(entry.second);
  std::vector<Simplex> all = gather_all(s.comm, mine);
  const std::vector<Point<d>> points = gather_all(s.comm, owned_points);
  if (s.rank == 0) {
    std::sort(all.begin(), all.end());
    const auto one = LocalTraits<LocalMesh<d>>::build(s.box, points, 0);
    if (LocalTraits<LocalMesh<d>>::simplices(one) != all)
      s.fail(failure, "the ranks' simplices are not the one-process mesh of their points");
  }
  agree_or_throw(s.comm, failure);
}

template class MpiMesh<2>;
template class MpiMesh<3>;

}  // namespace dynmesh
