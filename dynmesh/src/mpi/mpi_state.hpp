// mpi_state.hpp (private) — the partition, ghosts, routing, coarse top and repartition that
// MpiQuadtree and MpiMesh share: one rank's state, over the local structure it runs.
//
// Purpose: a rank runs an ordinary single-process structure (`Local`: DynamicQuadtree, or a
// dynamic mesh) on the points of its own root cells and of the ring of root cells around
// them; this state partitions the root cells, routes points and edits to the ranks holding
// them, agrees on errors, keeps the per-root-cell summaries and decides the coarse top.
// docs/DISTRIBUTED.md gives the argument ("Partition", "Coarse cells", "Updates").
// Invariants: MpiQuadtree::check_invariants and MpiMesh::check_invariants check them: the
// starts cover the root cells in order and are alike on every rank, as are the counts, the
// split bits and the coarse levels; the local structure holds exactly the points of the owned
// and ghost root cells.
// Complexity: see mpi_quadtree.hpp.
// Paper: Acar & Hudson, Section 2 (T*); p4est (Burstedde, Wilcox, Ghattas 2011).
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <mpi.h>

#include "dynmesh/box.hpp"
#include "dynmesh/cell.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/edit.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/mpi_quadtree.hpp"
#include "dynmesh/point.hpp"
#include "mpi/agreed_error.hpp"
#include "mpi/morton.hpp"

namespace dynmesh {
namespace detail {

/// The finest partition level considered (2^(d·l) root cells: 2^20 in 2D, 2^18 in 3D), and
/// the occupied root cells wanted per rank when l0 is chosen (docs/DISTRIBUTED.md).
template <std::size_t d>
inline constexpr int kMaxPartitionLevel = d == 2 ? 10 : 6;
inline constexpr std::uint64_t kRootsPerRank = 4096;

/// A point or an edit on its way to the ranks that hold its root cell.
template <std::size_t d>
struct Routed {
  std::uint64_t index;  // global index: the order of application
  std::uint64_t op;     // EditOp (0 for an initial point)
  Point<d> point;
};

/// Coarse cell summary bits.
inline constexpr std::uint8_t kSplit = 1;
inline constexpr int kClassShift = 1;  // bits 1-2: the point count clamped to 2

/// An error of this rank's DynamicQuadtree, its local indices (into `global`) replaced by
/// the global ones, in the text too ("edit 3: ...", "points 2 and 7 have ...").
inline Failure relabel(const InputError& e, const std::string& noun, const std::vector<std::uint64_t>& global) {
  Failure f;
  f.kind = e.kind();
  std::vector<std::size_t> idx;
  for (const std::size_t i : e.point_indices()) idx.push_back(i < global.size() ? global[i] : i);
  std::string text = e.text();
  const auto& local = e.point_indices();
  if (!local.empty()) {
    const std::string one = noun + " " + std::to_string(local.back()) + ": ";
    if (text.rfind(one, 0) == 0) {
      text = noun + " " + std::to_string(idx.back()) + ": " + text.substr(one.size());
    } else if (local.size() == 2 && text.rfind(noun + "s " + std::to_string(local[0]) + " and ", 0) == 0) {
      text = noun + "s " + std::to_string(idx[0]) + " and " + std::to_string(idx[1]) +
             " have the same located position";
    }
  }
  f.text = text;
  f.indices = idx;
  f.key = idx.empty() ? Failure::kNoKey : *std::max_element(idx.begin(), idx.end());
  return f;
}

/// MPI_Alltoallv of trivially copyable items, `out[r]` to rank r; returns what arrived, in
/// rank order.
template <class T>
std::vector<T> alltoall(MPI_Comm comm, const std::vector<std::vector<T>>& out) {
  const int nranks = static_cast<int>(out.size());
  std::vector<int> send_n(out.size()), recv_n(out.size()), send_at(out.size()), recv_at(out.size());
  for (int r = 0; r < nranks; ++r) send_n[r] = static_cast<int>(out[r].size() * sizeof(T));
  MPI_Alltoall(send_n.data(), 1, MPI_INT, recv_n.data(), 1, MPI_INT, comm);
  int s = 0, t = 0;
  for (int r = 0; r < nranks; ++r) {
    send_at[r] = s;
    recv_at[r] = t;
    s += send_n[r];
    t += recv_n[r];
  }
  std::vector<char> send(static_cast<std::size_t>(s));
  for (int r = 0; r < nranks; ++r)
    if (!out[r].empty()) std::memcpy(send.data() + send_at[r], out[r].data(), static_cast<std::size_t>(send_n[r]));
  std::vector<T> in(static_cast<std::size_t>(t) / sizeof(T));
  MPI_Alltoallv(send.data(), send_n.data(), send_at.data(), MPI_BYTE, in.data(), recv_n.data(), recv_at.data(),
                MPI_BYTE, comm);
  return in;
}

/// MPI_Allgatherv of trivially copyable items, in rank order.
template <class T>
std::vector<T> gather_all(MPI_Comm comm, const std::vector<T>& mine) {
  int nranks = 1;
  MPI_Comm_size(comm, &nranks);
  int n = static_cast<int>(mine.size() * sizeof(T));
  std::vector<int> counts(static_cast<std::size_t>(nranks)), at(static_cast<std::size_t>(nranks));
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  int total = 0;
  for (int r = 0; r < nranks; ++r) {
    at[r] = total;
    total += counts[r];
  }
  std::vector<T> all(static_cast<std::size_t>(total) / sizeof(T));
  MPI_Allgatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), at.data(), MPI_BYTE, comm);
  return all;
}

/// The located positions of `points`, or the first failure (NaN, outside the box) keyed by
/// its global index `offset + i`.
template <std::size_t d>
std::optional<Failure> locate_all(const Box<d>& box, std::span<const Point<d>> points, std::uint64_t offset,
                                  const std::string& noun, std::vector<Position<d>>& out) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    try {
      out.push_back(dynmesh::locate(box, points[i]));
    } catch (const InputError& e) {
      Failure f;
      f.kind = e.kind();
      f.key = offset + i;
      f.indices = {static_cast<std::size_t>(offset + i)};
      f.text = noun + " " + std::to_string(offset + i) + ": point " + to_string<d>(points[i]) +
               (e.kind() == InputError::Kind::NotFinite ? " has a NaN or infinite coordinate"
                                                         : " is outside the domain box");
      return f;
    }
  }
  return std::nullopt;
}

inline double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

inline std::uint64_t exclusive_offset(MPI_Comm comm, std::uint64_t mine, std::uint64_t& total) {
  std::uint64_t before = 0;
  MPI_Exscan(&mine, &before, 1, MPI_UINT64_T, MPI_SUM, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) before = 0;  // MPI_Exscan leaves rank 0's result undefined
  MPI_Allreduce(&mine, &total, 1, MPI_UINT64_T, MPI_SUM, comm);
  return before;
}

/// How MpiState builds its local structure: LocalTraits<Local>::build(box, points,
/// split_below) returns one on those points (specialized next to each user: DynamicQuadtree
/// here, the meshes in mpi_mesh.cpp). Local also provides apply, is_split (T*), points, size,
/// trace_bytes and check_invariants.
template <class Local>
struct LocalTraits;

template <std::size_t d>
struct LocalTraits<DynamicQuadtree<d>> {
  static DynamicQuadtree<d> build(const Box<d>& box, std::span<const Point<d>> points, int split_below) {
    return DynamicQuadtree<d>(box, points, DynamicQuadtreeOptions{split_below});
  }
};

template <std::size_t d, class Local>
struct MpiState {
  MPI_Comm comm = MPI_COMM_NULL;
  int rank = 0, nranks = 1;
  Box<d> box;
  MpiQuadtreeOptions options;
  int l0 = 0;
  std::uint64_t nroots = 1;
  std::size_t total = 0;                       // points of all ranks
  std::vector<std::uint64_t> starts;           // size P + 1
  std::vector<std::uint32_t> counts;           // per root cell (Morton order), all ranks alike
  std::vector<std::uint8_t> root_split;        // per root cell, all ranks alike
  std::vector<std::vector<std::uint8_t>> coarse;  // coarse[l][m], l < l0: kSplit | class
  std::vector<std::uint8_t> role;              // per root cell, this rank: 1 owned, 2 ghost
  std::optional<Local> tree;                   // owned and ghost points
  bool split_to_l0 = false;                    // the meshes' local trees split all above l0
  MpiRankStats stats;

  ~MpiState() {
    if (comm != MPI_COMM_NULL) MPI_Comm_free(&comm);
  }

  std::uint64_t root_of(const Position<d>& q) const { return morton(cell_of(q, l0)); }
  int owner(std::uint64_t m) const {
    return static_cast<int>(std::upper_bound(starts.begin(), starts.end(), m) - starts.begin()) - 1;
  }
  bool owns(std::uint64_t m) const { return m >= starts[rank] && m < starts[rank + 1]; }

  /// Calls f(m') for every root cell within `w` root cells of m (m included), in the box.
  template <class F>
  void for_each_in_ring(std::uint64_t m, int w, F&& f) const {
    const CellId<d> c = from_morton<d>(m, l0);
    const std::int64_t n = static_cast<std::int64_t>(cells_per_axis(l0));
    const std::int64_t side = 2 * w + 1;
    std::int64_t block = 1;
    for (std::size_t a = 0; a < d; ++a) block *= side;
    for (std::int64_t code = 0; code < block; ++code) {
      CellId<d> ring_cell;
      ring_cell.level = l0;
      bool inside = true;
      std::int64_t rest = code;
      for (std::size_t a = 0; a < d; ++a) {
        const std::int64_t i = static_cast<std::int64_t>(c.index[a]) + rest % side - w;
        rest /= side;
        inside = inside && i >= 0 && i < n;
        ring_cell.index[a] = static_cast<std::uint64_t>(i);
      }
      if (inside) f(morton(ring_cell));
    }
  }

  /// The ranks that hold root cell m: its owner and every rank holding it as a ghost, sorted,
  /// into `out` (reused by the caller: no allocation per edit once it has grown).
  void holders(std::uint64_t m, std::vector<int>& out) const {
    out.clear();
    for_each_in_ring(m, options.ghost_ring, [&](std::uint64_t near) { out.push_back(owner(near)); });
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  /// Contiguous Morton runs balanced by point count: rank r starts at the first root cell
  /// before which at least ⌈r·n/P⌉ points lie.
  void partition() {
    starts.assign(static_cast<std::size_t>(nranks) + 1, nroots);
    starts[0] = 0;
    std::uint64_t before = 0, m = 0;
    for (int r = 1; r < nranks; ++r) {
      const std::uint64_t want = (static_cast<std::uint64_t>(r) * total + nranks - 1) / nranks;
      while (m < nroots && before < want) before += counts[m++];
      starts[r] = m;
    }
    role.assign(nroots, 0);
    for (std::uint64_t own = starts[rank]; own < starts[rank + 1]; ++own) {
      role[own] = 1;
      for_each_in_ring(own, options.ghost_ring, [&](std::uint64_t near) {
        if (role[near] == 0) role[near] = 2;
      });
    }
    // A cell met before its own turn came was marked ghost: owned ones win.
    for (std::uint64_t own = starts[rank]; own < starts[rank + 1]; ++own) role[own] = 1;
  }

  /// Builds this rank's tree on the routed points; errors name global indices.
  void build_tree(std::vector<Routed<d>> pts) {
    std::sort(pts.begin(), pts.end(), [](const Routed<d>& a, const Routed<d>& b) { return a.index < b.index; });
    std::vector<Point<d>> local;
    std::vector<std::uint64_t> global;
    for (const Routed<d>& p : pts) {
      local.push_back(p.point);
      global.push_back(p.index);
    }
    std::optional<Failure> failure;
    tree.reset();
    try {
      tree.emplace(LocalTraits<Local>::build(box, std::span<const Point<d>>(local), split_to_l0 ? l0 : 0));
    } catch (const InputError& e) {
      failure = relabel(e, "point", global);
    }
    agree_or_throw(comm, failure);
  }

  /// This rank's split bits of its owned root cells, gathered so that every rank has all.
  void gather_root_split() {
    std::vector<std::uint8_t> mine;
    for (std::uint64_t m = starts[rank]; m < starts[rank + 1]; ++m)
      mine.push_back(tree->is_split(from_morton<d>(m, l0)) ? 1 : 0);
    root_split = gather_all(comm, mine);
  }

  /// The levels above l0, from the root cells' counts and split bits: a coarse cell is split
  /// when it is crowded or touches a split cell one level finer (its children included).
  void compute_coarse() {
    coarse.assign(static_cast<std::size_t>(l0), {});
    std::vector<std::uint8_t> finer(nroots);
    for (std::uint64_t m = 0; m < nroots; ++m)
      finer[m] = static_cast<std::uint8_t>((root_split[m] ? kSplit : 0) |
                                           (std::min<std::uint32_t>(counts[m], 2) << kClassShift));
    for (int l = l0 - 1; l >= 0; --l) {
      const std::uint64_t n = std::uint64_t{1} << (d * static_cast<std::size_t>(l));
      std::vector<std::uint8_t>& cur = coarse[static_cast<std::size_t>(l)];
      cur.assign(n, 0);
      for (std::uint64_t m = 0; m < n; ++m) {
        unsigned cls = 0;
        for (std::uint64_t w = 0; w < static_cast<std::uint64_t>(kChildren<d>); ++w)
          cls += finer[m * kChildren<d> + w] >> kClassShift;
        cur[m] = static_cast<std::uint8_t>(std::min(cls, 2u) << kClassShift);
      }
      for (std::uint64_t m = 0; m < n; ++m) {
        const unsigned cls = cur[m] >> kClassShift;
        bool crowded = cls >= 2;
        if (cls == 1)
          for_each_neighbour(from_morton<d>(m, l), [&](const CellId<d>& nb) {
            crowded = crowded || (cur[morton(nb)] >> kClassShift) != 0;
          });
        if (crowded) cur[m] |= kSplit;
      }
      for (std::uint64_t m = 0; m < finer.size(); ++m)
        if (finer[m] & kSplit)
          for_each_coarser_touching(from_morton<d>(m, l + 1),
                                    [&](const CellId<d>& u) { cur[morton(u)] |= kSplit; });
      finer = cur;
    }
  }

  /// Is root cell m a leaf of T*: unsplit, with a split parent (or the box itself)?
  bool root_is_leaf(std::uint64_t m) const {
    if (root_split[m]) return false;
    return l0 == 0 || (coarse[static_cast<std::size_t>(l0 - 1)][m >> d] & kSplit);
  }

  /// This rank's figures (MpiQuadtree::rank_stats, MpiMesh::rank_stats).
  MpiRankStats rank_stats() const {
    MpiRankStats st = stats;
    st.owned_points = owned_points();
    st.ghost_points = tree->size() - st.owned_points;
    st.owned_roots = starts[rank + 1] - starts[rank];
    st.trace_bytes = tree->trace_bytes();
    return st;
  }

  std::size_t owned_points() const {
    std::size_t k = 0;
    for (std::uint64_t m = starts[rank]; m < starts[rank + 1]; ++m) k += counts[m];
    return k;
  }

  /// The points of this rank's tree that lie in root cells it owns.
  std::vector<Routed<d>> owned_routed() const {
    std::vector<Routed<d>> out;
    for (const auto& [id, p] : tree->points()) {
      const std::uint64_t m = root_of(dynmesh::locate(box, p));
      if (role[m] == 1) out.push_back(Routed<d>{0, 0, p});
    }
    return out;
  }

  /// Moves whole root cells so that the runs are balanced again, and rebuilds the trees.
  /// T* is a function of the point set, so the counts, split bits and coarse levels stay.
  void repartition() {
    redistribute(owned_routed());
    ++stats.repartitions;
  }

  /// Applies the inverse of `batch` (edits this rank applied, in order) to the local
  /// structure: it is a function of the point set, so this restores it exactly.
  void put_back(const std::vector<Edit<d>>& batch) {
    std::vector<Edit<d>> undo(batch.rbegin(), batch.rend());
    for (Edit<d>& e : undo) e.op = e.op == EditOp::Insert ? EditOp::Delete : EditOp::Insert;
    tree->apply(undo);
  }

  /// The first failure found, as an invariant failure naming this rank.
  void fail(std::optional<Failure>& failure, const std::string& text) const {
    if (failure) return;
    failure = Failure{};
    failure->invariant = true;
    failure->key = 0;
    failure->text = "dynmesh: rank " + std::to_string(rank) + ": " + text;
  }

  /// Collective: the local structure's own checks, the partition, the points held against
  /// the counts, the owned split bits, and the shared tables alike on every rank. Records the
  /// first fault in `failure` (the caller agrees on it).
  void check_partition(std::optional<Failure>& failure) const {
    const MpiState& s = *this;
    auto fail = [&](const std::string& text) { s.fail(failure, text); };
    try {
      s.tree->check_invariants();
    } catch (const std::exception& e) {
      fail(e.what());
    }
    if (s.starts.size() != static_cast<std::size_t>(s.nranks) + 1 || s.starts.front() != 0 || s.starts.back() != s.nroots ||
        !std::is_sorted(s.starts.begin(), s.starts.end()))
      fail("the partition does not cover the root cells in order");
    // The tree holds exactly the points of the owned and ghost root cells, as many as counted.
    std::vector<std::uint32_t> mine(s.nroots, 0);
    for (const auto& entry : s.tree->points()) {
      const Position<d> q = dynmesh::locate(s.box, entry.second);
      const std::uint64_t m = s.root_of(q);
      if (s.role[m] == 0) fail("its tree holds a point of root cell " + std::to_string(m) + ", neither owned nor ghost");
      ++mine[m];
    }
    for (std::uint64_t m = 0; m < s.nroots; ++m) {
      if (s.role[m] != 0 && mine[m] != s.counts[m])
        fail("root cell " + std::to_string(m) + " holds " + std::to_string(mine[m]) + " points, counted " +
             std::to_string(s.counts[m]));
      if (s.role[m] == 1 && (s.tree->is_split(from_morton<d>(m, s.l0)) ? 1 : 0) != s.root_split[m])
        fail("the split bit of root cell " + std::to_string(m) + " is stale");
    }
    // The shared tables are alike on every rank (an FNV-1a digest compared by min and max).
    std::uint64_t h = 1469598103934665603ULL;
    auto mix = [&](const void* p, std::size_t n) {
      for (std::size_t i = 0; i < n; ++i) h = (h ^ static_cast<const unsigned char*>(p)[i]) * 1099511628211ULL;
    };
    mix(s.starts.data(), s.starts.size() * sizeof(std::uint64_t));
    mix(s.counts.data(), s.counts.size() * sizeof(std::uint32_t));
    mix(s.root_split.data(), s.root_split.size());
    for (const auto& level : s.coarse) mix(level.data(), level.size());
    std::uint64_t lo = 0, hi = 0;
    MPI_Allreduce(&h, &lo, 1, MPI_UINT64_T, MPI_MIN, s.comm);
    MPI_Allreduce(&h, &hi, 1, MPI_UINT64_T, MPI_MAX, s.comm);
    if (lo != hi) fail("the partition, counts or coarse levels differ between ranks");
  }

  /// Collective: the partition recomputed from the counts, `mine` (each rank's owned points)
  /// sent to their owners and ghost holders, and the local structures rebuilt.
  void redistribute(const std::vector<Routed<d>>& mine) {
    partition();
    std::vector<std::vector<Routed<d>>> out(static_cast<std::size_t>(nranks));
    std::vector<int> to;
    for (const Routed<d>& p : mine) {
      holders(root_of(dynmesh::locate(box, p.point)), to);
      for (const int r : to) out[static_cast<std::size_t>(r)].push_back(p);
    }
    std::vector<Routed<d>> in = detail::alltoall(comm, out);
    // Order by position: the structure does not depend on it, the ids do.
    std::sort(in.begin(), in.end(), [&](const Routed<d>& a, const Routed<d>& b) {
      return dynmesh::locate(box, a.point) < dynmesh::locate(box, b.point);
    });
    for (std::size_t i = 0; i < in.size(); ++i) in[i].index = i;
    build_tree(std::move(in));
  }

  /// Collective: builds the partition and this rank's structure on `points` (any part of the
  /// point set on each rank). MpiQuadtree's constructor; MpiMesh's first step.
  void construct(MPI_Comm parent, const Box<d>& the_box, std::span<const Point<d>> points,
                 const MpiQuadtreeOptions& the_options) {
    MpiState& s = *this;
    MPI_Comm_dup(parent, &s.comm);
    MPI_Comm_rank(s.comm, &s.rank);
    MPI_Comm_size(s.comm, &s.nranks);
    s.box = the_box;
    s.options = the_options;
    validate_box(box);  // the same box on every rank: the same verdict

    std::uint64_t all = 0;
    const std::uint64_t offset = exclusive_offset(s.comm, points.size(), all);
    std::vector<Position<d>> located;
    agree_or_throw(s.comm, locate_all<d>(box, points, offset, "point", located));
    s.total = all;

    // Counts at the finest partition level, summed over the ranks; coarser levels aggregate
    // Morton blocks.
    const int finest = kMaxPartitionLevel<d>;
    std::vector<std::uint32_t> fine(std::uint64_t{1} << (d * finest), 0), sum(fine.size());
    for (const Position<d>& q : located) ++fine[morton(cell_of(q, finest))];
    MPI_Allreduce(fine.data(), sum.data(), static_cast<int>(fine.size()), MPI_UINT32_T, MPI_SUM, s.comm);
    fine.clear();
    fine.shrink_to_fit();
    auto counts_at = [&](int level) {
      const std::size_t shift = d * static_cast<std::size_t>(finest - level);
      std::vector<std::uint32_t> c(std::uint64_t{1} << (d * level), 0);
      for (std::uint64_t m = 0; m < sum.size(); ++m) c[m >> shift] += sum[m];
      return c;
    };
    if (options.partition_level >= 0) {
      s.l0 = std::min(options.partition_level, finest);
    } else {
      // The coarsest level with enough occupied root cells for every rank (so that the ghost
      // ring is thin against the run it surrounds), or about 8 points per occupied cell on
      // small inputs, whichever comes first.
      const std::uint64_t want =
          std::min<std::uint64_t>(kRootsPerRank * static_cast<std::uint64_t>(s.nranks), std::max<std::uint64_t>(1, all / 8));
      s.l0 = finest;
      for (int l = 1; l < finest; ++l) {
        const auto c = counts_at(l);
        const auto occupied = static_cast<std::uint64_t>(std::count_if(c.begin(), c.end(), [](std::uint32_t k) { return k != 0; }));
        if (occupied >= want) {
          s.l0 = l;
          break;
        }
      }
    }
    s.counts = counts_at(s.l0);
    s.nroots = s.counts.size();
    sum.clear();
    sum.shrink_to_fit();
    s.partition();

    std::vector<std::vector<Routed<d>>> out(static_cast<std::size_t>(s.nranks));
    std::vector<int> to;
    for (std::size_t i = 0; i < located.size(); ++i) {
      s.holders(s.root_of(located[i]), to);
      for (const int r : to) out[static_cast<std::size_t>(r)].push_back(Routed<d>{offset + i, 0, points[i]});
    }
    located.clear();
    std::vector<Routed<d>> in = alltoall(s.comm, out);
    out.clear();
    s.build_tree(std::move(in));
    s.gather_root_split();
    s.compute_coarse();
  }

  /// Collective: the ranks' edits as one batch (rank order), applied by one propagation on
  /// every rank holding them, the summaries and the coarse top brought up to date. Returns
  /// the edits this rank applied, sorted by global index; a refused batch throws on every
  /// rank and changes nothing.
  std::vector<Routed<d>> apply_batch(std::span<const Edit<d>> edits) {
  MpiState& s = *this;
  std::uint64_t all = 0;
  const std::uint64_t offset = exclusive_offset(s.comm, edits.size(), all);
  if (all == 0) return {};
  std::vector<Point<d>> pts;
  for (const Edit<d>& e : edits) pts.push_back(e.point);
  std::vector<Position<d>> located;
  std::optional<Failure> failure = locate_all<d>(s.box, pts, offset, "edit", located);

  // Route the edits that located (those before a failure); the tree validates the rest.
  std::vector<std::vector<Routed<d>>> out(static_cast<std::size_t>(s.nranks));
  std::vector<int> to;
  for (std::size_t i = 0; i < located.size(); ++i) {
      s.holders(s.root_of(located[i]), to);
      for (const int r : to)
        out[static_cast<std::size_t>(r)].push_back(
            Routed<d>{offset + i, static_cast<std::uint64_t>(edits[i].op), edits[i].point});
    }
    std::vector<Routed<d>> in = alltoall(s.comm, out);
    std::sort(in.begin(), in.end(), [](const Routed<d>& a, const Routed<d>& b) { return a.index < b.index; });
    std::vector<Edit<d>> batch;
    std::vector<std::uint64_t> global;
    for (const Routed<d>& r : in) {
      batch.push_back(Edit<d>{static_cast<EditOp>(r.op), r.point});
      global.push_back(r.index);
    }

    bool applied = false;
    if (!batch.empty()) {
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = thread_cpu_seconds();
      try {
        s.tree->apply(batch);
        applied = true;
      } catch (const InputError& e) {
        Failure f = relabel(e, "edit", global);
        if (!failure || f.key < failure->key) failure = std::move(f);
      }
      if (applied) {
        s.stats.propagate_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        s.stats.propagate_cpu_seconds += thread_cpu_seconds() - c0;
        ++s.stats.propagations;
      }
    }
    if (const auto agreed = agree(s.comm, failure)) {
      // Put the point set back: the tree is a function of it, so this restores it exactly.
      if (applied) s.put_back(batch);
      agreed->raise();
    }

    // New counts of owned root cells, and split bits of the owned root cells near an edit.
    std::vector<std::uint64_t> touched;
    for (const Routed<d>& r : in) {
      const std::uint64_t m = s.root_of(dynmesh::locate(s.box, r.point));
      s.for_each_in_ring(m, 1, [&](std::uint64_t near) {
        if (s.owns(near)) touched.push_back(near);
      });
    }
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    std::vector<std::uint32_t> owned_count(touched.size(), 0);
    for (std::size_t i = 0; i < touched.size(); ++i) owned_count[i] = s.counts[touched[i]];
    for (const Routed<d>& r : in) {
      const std::uint64_t m = s.root_of(dynmesh::locate(s.box, r.point));
      if (!s.owns(m)) continue;
      const auto at = std::lower_bound(touched.begin(), touched.end(), m) - touched.begin();
      owned_count[static_cast<std::size_t>(at)] += static_cast<EditOp>(r.op) == EditOp::Insert ? 1u : std::uint32_t(-1);
    }
    struct Change {
      std::uint64_t root;
      std::uint32_t count;
      std::uint32_t split;
    };
    std::vector<Change> changed;
    for (std::size_t i = 0; i < touched.size(); ++i) {
      const std::uint64_t m = touched[i];
      const std::uint32_t split = s.tree->is_split(from_morton<d>(m, s.l0)) ? 1 : 0;
      if (owned_count[i] != s.counts[m] || split != s.root_split[m]) changed.push_back(Change{m, owned_count[i], split});
    }
    const std::vector<Change> everyone = gather_all(s.comm, changed);
    bool coarse_stale = false;
    for (const Change& c : everyone) {
      s.total += c.count;
      s.total -= s.counts[c.root];
      coarse_stale = coarse_stale || std::min<std::uint32_t>(c.count, 2) != std::min<std::uint32_t>(s.counts[c.root], 2) ||
                     c.split != s.root_split[c.root];
      s.counts[c.root] = c.count;
      s.root_split[c.root] = static_cast<std::uint8_t>(c.split);
    }
    if (coarse_stale) s.compute_coarse();
    return in;
  }

  void maybe_repartition() {
    if (options.rebalance_factor <= 0 || nranks == 1) return;
    std::uint64_t largest = 0;
    for (int r = 0; r < nranks; ++r) {
      std::uint64_t k = 0;
      for (std::uint64_t m = starts[r]; m < starts[r + 1]; ++m) k += counts[m];
      largest = std::max(largest, k);
    }
    const double mean = static_cast<double>(total) / nranks;
    if (static_cast<double>(largest) > options.rebalance_factor * mean && static_cast<double>(largest) >= mean + 64)
      repartition();
  }
};

}  // namespace detail

}  // namespace dynmesh
