// dynmesh-mpi — `dynmesh quadtree` and `dynmesh mesh --postprocess quadtree` on MPI ranks
// (docs/FORMATS.md, docs/DISTRIBUTED.md):
//   mpirun -np P dynmesh-mpi quadtree POINTS [--dim 2|3] [--box o1 o2 [o3] L]
//                [--duplicates error|skip] [--edits FILE] [--batch K] --cells OUT [--stats]
//   mpirun -np P dynmesh-mpi mesh POINTS [--dim 2|3] [--box ...] [--postprocess quadtree]
//                [--min-angle DEG] [--duplicates error|skip] [--edits FILE] [--batch K]
//                -o OUTBASE [--feed F] [--vtk F] [--msh F] [--stats]
// Same inputs, box and edit semantics as the one-process commands, through the same readers
// and labels (initial_points.hpp, input_labels.hpp): rank 0 reads the files and hands the
// points and the edits to MpiQuadtree or MpiMesh, which route them to their ranks. Every
// output is written once, by rank 0, as the ranks' sorted parts arrive (no rank holds them
// all), and equals the one-process command's for every P: the leaves merged
// (detail/merge_on_root.hpp); the feed merged per propagation; the mesh's vertices numbered
// as they merge, each rank told its numbers (detail/number_on_root.hpp), then its simplices
// renumbered and merged; every file in the parts of mesh_text_parts.hpp. --stats prints, per
// rank, on stderr (gathered to rank 0, in rank order): points owned, ghost points, simplices
// owned (mesh), trace bytes, mean time per propagation, peak resident memory. DynHPU does not
// run on ranks: `mesh` refuses --postprocess hpu, the 2D default.
// Errors: one line `dynmesh-mpi: <message>` from rank 0 and exit status 1 on every rank (2 for
// a malformed command line); every failure is agreed by all ranks before the next
// collective, so none waits forever. Hidden test options: --partition-level L (l0; the mesh
// lowers it to T*'s coarsest leaf), --ghost-ring W (a narrower ring must break exactness),
// --rebalance F, --measure-writing (quadtree, with --stats: the writing's own peak memory, by
// restarting the process's peak counter when the writing begins; docs/DISTRIBUTED.md,
// "Writing the output").
// No memory guard: the memory is spread over the ranks, which one process cannot see.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <mpi.h>

#include "atomic_file.hpp"
#include "distinct_paths.hpp"
#include "dynmesh/detail/merge_on_root.hpp"
#include "dynmesh/detail/mesh_grid.hpp"
#include "dynmesh/detail/number_on_root.hpp"
#include "dynmesh/io.hpp"
#include "dynmesh/mesh_io.hpp"
#include "dynmesh/mesh_text_parts.hpp"
#include "dynmesh/mpi_mesh.hpp"
#include "dynmesh/mpi_quadtree.hpp"
#include "initial_points.hpp"
#include "input_labels.hpp"
#include "number_options.hpp"
#include "peak_memory.hpp"
#include "postprocess_option.hpp"
#include "verify.hpp"

namespace {

using namespace dynmesh;
using namespace dynmesh::tool;

struct Options {
  std::string points;
  int dim = 2;
  bool dim_given = false;
  std::vector<double> box;
  bool skip_duplicates = false;
  std::string edits;
  std::size_t batch = 0;
  std::string cells;
  bool stats = false;
  int partition_level = -1;
  int ghost_ring = -1;  // -1: the command's own (1 for the tree, kMeshGhostRing for the meshes)
  double rebalance = 1.5;
  bool measure_writing = false;
  // mesh
  std::string postprocess;
  double min_angle = 0;
  bool min_angle_given = false;
  std::string outbase;
  std::string feed;
  std::string vtk;
  std::string msh;
};

int rank_of(MPI_Comm comm) {
  int r = 0;
  MPI_Comm_rank(comm, &r);
  return r;
}

/// Rank 0's message (empty: none) to every rank; true when there is one.
bool shared_failure(MPI_Comm comm, std::string& message) {
  std::uint64_t n = message.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm);
  message.resize(n);
  MPI_Bcast(message.data(), static_cast<int>(n), MPI_CHAR, 0, comm);
  return n != 0;
}

void print_error(const std::string& message) {
  std::fflush(stdout);
  std::fprintf(stderr, "dynmesh-mpi: %s\n", one_line(message).c_str());
}

/// Per-rank --stats lines, printed by rank 0 in rank order: the tree's figures, taken before
/// the tree was freed, and the rank's peak resident memory over the run; with
/// --measure-writing also the peak over the writing of the output alone and the resident
/// memory when the writing began (writing_mib < 0: not measured).
/// `simplices` (the mesh: those the rank owns; negative: the tree, none) follows the ghosts.
void print_stats(MPI_Comm comm, const MpiRankStats& st, int partition_level, double peak_mib, double writing_mib,
                 double writing_from_mib, long long simplices = -1) {
  char line[512];
  char owned[64] = "";
  if (simplices >= 0) std::snprintf(owned, sizeof owned, ", %lld simplices owned", simplices);
  const double mean = st.propagations ? st.propagate_seconds / static_cast<double>(st.propagations) : 0.0;
  int n = std::snprintf(line, sizeof line,
                        "[dynmesh-mpi] rank %d: owned %zu points in %zu root cells, ghost %zu points%s, trace %zu bytes, "
                        "%zu propagations, mean %.6f s, %zu repartitions, peak_rss %.0f MiB",
                        rank_of(comm), st.owned_points, st.owned_roots, st.ghost_points, owned, st.trace_bytes,
                        st.propagations, mean, st.repartitions, peak_mib);
  if (writing_mib >= 0 && n > 0 && static_cast<std::size_t>(n) < sizeof line)
    std::snprintf(line + n, sizeof line - static_cast<std::size_t>(n), ", writing peak_rss %.0f MiB (from %.0f MiB)",
                  writing_mib, writing_from_mib);
  int nranks = 1;
  MPI_Comm_size(comm, &nranks);
  std::vector<char> all(static_cast<std::size_t>(nranks) * sizeof line);
  MPI_Gather(line, sizeof line, MPI_CHAR, all.data(), sizeof line, MPI_CHAR, 0, comm);
  if (rank_of(comm) != 0) return;
  std::fflush(stdout);
  std::fprintf(stderr, "[dynmesh-mpi] %d ranks, partition level %d\n", nranks, partition_level);
  for (int r = 0; r < nranks; ++r) std::fprintf(stderr, "%s\n", all.data() + static_cast<std::size_t>(r) * sizeof line);
}

/// What rank 0 read, and what every rank learns of it: the box and the number of edits.
template <std::size_t d>
struct Inputs {
  std::optional<InitialPoints<d>> initial;  // rank 0
  EditScript<d> script;                     // rank 0
  Box<d> box;
  std::uint64_t nedits = 0;
  /// The initial points on rank 0, none elsewhere (the structures route them).
  std::span<const Point<d>> points(bool root) const {
    return root ? std::span<const Point<d>>(initial->file.points) : std::span<const Point<d>>{};
  }
};

/// Rank 0 reads POINTS and the edit script; the box and the edit count go to every rank.
/// False (rank 0 has printed the error) when reading failed.
template <std::size_t d>
bool read_inputs(MPI_Comm comm, const Options& o, Columns columns, Inputs<d>& in) {
  const bool root = rank_of(comm) == 0;
  std::string message;
  if (root) {
    try {
      in.initial.emplace(read_initial_points<d>(o.points, o.box, o.skip_duplicates, columns));
      if (!o.edits.empty()) in.script = read_edits_file<d>(o.edits);
    } catch (const std::exception& e) {
      message = e.what();
    }
  }
  if (shared_failure(comm, message)) {
    if (root) print_error(message);
    return false;
  }
  if (root) in.box = in.initial->box;
  double words[d + 1];
  for (std::size_t a = 0; a < d; ++a) words[a] = in.box.origin[a];
  words[d] = in.box.side;
  MPI_Bcast(words, d + 1, MPI_DOUBLE, 0, comm);
  for (std::size_t a = 0; a < d; ++a) in.box.origin[a] = words[a];
  in.box.side = words[d];
  in.nedits = in.script.edits.size();
  MPI_Bcast(&in.nedits, 1, MPI_UINT64_T, 0, comm);
  return true;
}

/// Builds the structure with make(); an InputError (the same on every rank) is labelled by
/// rank 0 with the point file's lines. False when it failed.
template <std::size_t d, class Structure, class Make>
bool build_or_report(MPI_Comm comm, const Inputs<d>& in, int resolution_level, std::optional<Structure>& out,
                     Make&& make) {
  try {
    make(out);
    return true;
  } catch (const InputError& e) {
    if (rank_of(comm) != 0) return false;
    try {
      rethrow_construction_error<d>(e, *in.initial, resolution_level);
    } catch (const std::exception& labelled) {
      print_error(labelled.what());
    }
    return false;
  }
}

/// Applies the script in batches of --batch (1 without it) on every rank, calling after()
/// after each; false (rank 0 has printed it, named by its line) when an edit is refused.
template <std::size_t d, class Structure, class After>
bool apply_script(MPI_Comm comm, const Options& o, const Inputs<d>& in, Structure& structure, After&& after) {
  const bool root = rank_of(comm) == 0;
  const std::size_t step = o.batch == 0 ? 1 : o.batch;
  const std::span<const Edit<d>> all(in.script.edits);
  for (std::uint64_t i = 0; i < in.nedits; i += step) {
    const std::size_t k = static_cast<std::size_t>(std::min<std::uint64_t>(step, in.nedits - i));
    try {
      structure.apply(root ? all.subspan(static_cast<std::size_t>(i), k) : std::span<const Edit<d>>{});
    } catch (const InputError& err) {
      if (!root) return false;
      const std::size_t at = err.point_indices().empty() ? 0 : err.point_indices().back();
      print_error(edit_error<d>(in.script, static_cast<std::size_t>(i) + at, err).what());
      return false;
    }
    after();
  }
  return true;
}

template <std::size_t d>
int run(MPI_Comm comm, const Options& o, Columns columns) {
  const bool root = rank_of(comm) == 0;
  Inputs<d> in;
  if (!read_inputs<d>(comm, o, columns, in)) return 1;
  const std::optional<InitialPoints<d>>& initial = in.initial;
  const Box<d>& box = in.box;
  std::string message;

  MpiQuadtreeOptions options;
  options.partition_level = o.partition_level;
  options.ghost_ring = o.ghost_ring >= 0 ? o.ghost_ring : 1;
  options.rebalance_factor = o.rebalance;
  std::optional<MpiQuadtree<d>> tree;
  if (!build_or_report<d>(comm, in, kMaxLevel, tree,
                          [&](auto& t) { t.emplace(comm, box, in.points(root), options); }))
    return 1;
  if (!apply_script<d>(comm, o, in, *tree, [] {})) return 1;
  MpiRankStats rank_stats;
  int partition_level = 0;
  if (o.stats) rank_stats = tree->rank_stats(), partition_level = tree->partition_level();

  // Free the trees before the leaves meet on rank 0: the trace is most of the memory. Rank 0
  // then writes OUT as the ranks' sorted leaves arrive, a chunk at a time
  // (detail/merge_on_root.hpp), so that no rank ever holds every leaf.
  const std::vector<Leaf<d>> local = tree->local_leaves();
  tree.reset();
  // The writing's own peak (--measure-writing): the peak counter restarts from the resident
  // set left once the tree is gone, so an outside measure of the peak sees the writing only.
  const double tree_peak = o.stats && o.measure_writing ? peak_rss_mib() : -1;
  const bool writing_measured = o.stats && o.measure_writing && reset_peak_rss();
  const double writing_from = writing_measured ? rss_mib() : -1;
  AtomicOutputs out;
  AtomicOutputs::Stream* file = nullptr;
  if (root) {
    try {
      file = &out.open_stream(o.cells);
      file->append(format_cells_header<d>(box));
    } catch (const std::exception& e) {
      message = e.what();
      file = nullptr;  // the merge still runs, so that no rank waits forever
    }
  }
  std::string text;
  try {
    dynmesh::detail::merge_on_root<Leaf<d>>(
        comm, std::span<const Leaf<d>>(local), 0, [](const Leaf<d>& a, const Leaf<d>& b) { return a.cell < b.cell; },
        [&](std::span<const Leaf<d>> part) {
          if (!file) return;
          text.clear();
          append_cells_lines<d>(text, part);
          file->append(text);
        });
    if (file) {
      out.commit();
      if (o.skip_duplicates) std::printf("duplicates: skipped %zu later copies\n", initial->duplicates_skipped);
    }
  } catch (const std::exception& e) {
    if (root && message.empty()) message = e.what();
  }
  if (o.stats) {
    // Without the restart the counter has seen the whole run; with it, the run's peak is the
    // larger of the two phases'.
    const double writing_peak = writing_measured ? peak_rss_mib() : -1;
    const double run_peak = writing_measured ? std::max(tree_peak, writing_peak) : peak_rss_mib();
    print_stats(comm, rank_stats, partition_level, run_peak, writing_peak, writing_from);
  }
  if (shared_failure(comm, message)) return root ? (print_error(message), 1) : 1;
  return 0;
}

/// Rank 0's end of a merge: text appended to an output stream, or nothing once the stream
/// failed (the merges go on, so that no rank waits; the first error is kept for the
/// agreement at the end).
struct RootText {
  AtomicOutputs::Stream* file = nullptr;
  std::string* message = nullptr;
  std::string text;

  template <class Format>
  void put(Format&& format) {
    if (!file) return;
    text.clear();
    format(text);
    try {
      file->append(text);
    } catch (const std::exception& e) {
      if (message->empty()) *message = e.what();
      file = nullptr;
    }
  }
};

/// Runs a collective merge; what it throws (on rank 0: a part out of order) is kept in
/// `message` for the agreement at the end, and the run goes on, so that no rank waits.
template <class Merge>
void guarded(std::string& message, Merge&& run) {
  try {
    run();
  } catch (const std::exception& e) {
    if (message.empty()) message = e.what();
  }
}

/// Opens OUT on rank 0 for a streamed output; a failure is kept in `message`.
AtomicOutputs::Stream* open_on_root(bool root, AtomicOutputs& out, const std::string& path, std::string& message) {
  if (!root || path.empty()) return nullptr;
  try {
    return &out.open_stream(path);
  } catch (const std::exception& e) {
    if (message.empty()) message = e.what();
    return nullptr;
  }
}

/// `dynmesh-mpi mesh`: MpiMesh on the ranks; rank 0 writes the feed as each propagation's
/// owned changes merge (counts first, then the '-' lines, then the '+' lines, each group
/// sorted as the ranks' sorted parts merge), then .node and .ele by numbering the ranks'
/// vertices on rank 0 (detail/number_on_root.hpp: once to count them for the header, once
/// to write them and send each rank its numbers) and merging the renumbered simplices.
template <std::size_t d>
int run_mesh(MPI_Comm comm, const Options& o, Columns columns) {
  using Simplex = MeshSimplex<d>;
  const bool root = rank_of(comm) == 0;
  Inputs<d> in;
  if (!read_inputs<d>(comm, o, columns, in)) return 1;
  const std::optional<InitialPoints<d>>& initial = in.initial;
  const Box<d>& box = in.box;
  std::string message;

  MpiQuadtreeOptions options = mpi_mesh_defaults();
  options.partition_level = o.partition_level;
  if (o.ghost_ring >= 0) options.ghost_ring = o.ghost_ring;
  options.rebalance_factor = o.rebalance;
  std::optional<MpiMesh<d>> mesh;
  // The mesh resolves points only down to its level R (none below 2: the box is unusable).
  const int level = dynmesh::detail::BasicMeshGrid<d>::resolution_level(box);
  if (!build_or_report<d>(comm, in, level >= 2 ? level : -1, mesh,
                          [&](auto& m) { m.emplace(comm, box, in.points(root), options); }))
    return 1;

  // The feed streams to its file aside as the edits propagate.
  AtomicOutputs out;
  RootText feed{open_on_root(root, out, o.feed, message), &message, {}};
  feed.put([](std::string& t) { t += feed_header(); });
  const auto less = [](const Simplex& a, const Simplex& b) { return a < b; };
  std::size_t propagations = 0;
  auto write_update = [&] {
    ++propagations;
    if (o.feed.empty()) return;
    const OwnedChange<d>& change = mesh->local_change();
    std::uint64_t mine[2] = {change.removed.size(), change.added.size()}, sums[2] = {0, 0};
    MPI_Reduce(mine, sums, 2, MPI_UINT64_T, MPI_SUM, 0, comm);
    feed.put([&](std::string& t) { append_feed_head(t, propagations, sums[0], sums[1]); });
    for (const auto& [sign, part] : {std::pair{'-', &change.removed}, std::pair{'+', &change.added}})
      guarded(message, [&, sign = sign, part = part] {
        dynmesh::detail::merge_on_root<Simplex>(comm, std::span<const Simplex>(*part), 0, less,
                                                [&](std::span<const Simplex> run) {
                                                  feed.put([&](std::string& t) { append_feed_lines(t, sign, run); });
                                                });
      });
  };
  if (!apply_script<d>(comm, o, in, *mesh, write_update)) return 1;

  MpiRankStats rank_stats;
  int partition_level = 0;
  if (o.stats) rank_stats = mesh->rank_stats(), partition_level = mesh->partition_level();
  // The simplices this rank owns, in index form, then the mesh goes: the trace is most of
  // the memory.
  const CanonicalMesh<d> mine = mesh->owned_mesh();
  mesh.reset();
  const std::vector<Point<d>>& vertices = mine.vertices;
  const auto& owned_cells = [&]() -> const auto& {
    if constexpr (d == 2) return mine.triangles;
    else return mine.tetrahedra;
  }();
  const auto point_less = [](const Point<d>& a, const Point<d>& b) { return a < b; };
  std::uint64_t nvertices = 0;
  (void)dynmesh::detail::number_on_root<Point<d>>(comm, std::span<const Point<d>>(vertices), 0, point_less,
                                                  [](std::span<const Point<d>>) {}, nvertices);
  // Every file of the mesh in its five parts (mesh_text_parts.hpp), fed by the same merges.
  struct File {
    MeshFile kind;
    RootText text;
  };
  std::vector<File> files;
  files.push_back({MeshFile::Node, {open_on_root(root, out, o.outbase + ".node", message), &message, {}}});
  files.push_back({MeshFile::Ele, {open_on_root(root, out, o.outbase + ".ele", message), &message, {}}});
  if (!o.vtk.empty()) files.push_back({MeshFile::Vtk, {open_on_root(root, out, o.vtk, message), &message, {}}});
  if (!o.msh.empty()) files.push_back({MeshFile::Msh, {open_on_root(root, out, o.msh, message), &message, {}}});
  for (File& f : files) f.text.put([&](std::string& t) { append_vertices_head(t, f.kind, nvertices, d); });
  std::size_t written = 0;
  std::vector<std::uint64_t> numbers;
  guarded(message, [&] {
    numbers = dynmesh::detail::number_on_root<Point<d>>(
        comm, std::span<const Point<d>>(vertices), 0, point_less,
        [&](std::span<const Point<d>> run) {
          for (File& f : files)
            f.text.put([&](std::string& t) { append_vertex_lines(t, f.kind, written, run, box); });
          written += run.size();
        },
        nvertices);
  });

  // Global numbers follow the local ones' order (both are coordinate order), so the
  // renumbered tuples stay canonical and sorted.
  using Cell = std::array<std::uint64_t, d + 1>;
  std::vector<Cell> cells;
  cells.reserve(owned_cells.size());
  for (const auto& local : owned_cells) {
    Cell c{};
    for (std::size_t k = 0; k <= d; ++k) c[k] = numbers[local[k]];
    cells.push_back(c);
  }
  std::uint64_t ncells_mine = cells.size(), ncells = 0;
  MPI_Reduce(&ncells_mine, &ncells, 1, MPI_UINT64_T, MPI_SUM, 0, comm);
  for (File& f : files) f.text.put([&](std::string& t) { append_cells_head(t, f.kind, ncells, d + 1); });
  std::size_t written_cells = 0;
  guarded(message, [&] {
    dynmesh::detail::merge_on_root<Cell>(comm, std::span<const Cell>(cells), 0, std::less<Cell>{},
                                         [&](std::span<const Cell> run) {
                                           for (File& f : files)
                                             f.text.put([&](std::string& t) {
                                               append_cell_lines(t, f.kind, written_cells, run);
                                             });
                                           written_cells += run.size();
                                         });
  });
  for (File& f : files) f.text.put([&](std::string& t) { append_file_tail(t, f.kind, ncells, d + 1); });
  if (root && message.empty()) {
    try {
      out.commit();
      if (o.skip_duplicates) std::printf("duplicates: skipped %zu later copies\n", initial->duplicates_skipped);
    } catch (const std::exception& e) {
      message = e.what();
    }
  }
  if (o.stats) print_stats(comm, rank_stats, partition_level, peak_rss_mib(), -1, -1, static_cast<long long>(owned_cells.size()));
  if (shared_failure(comm, message)) return root ? (print_error(message), 1) : 1;
  return 0;
}

/// The options both subcommands take: the points, their dimension and box, duplicates, the
/// edit script and its batches. Returns --dim.
CLI::Option* add_inputs(CLI::App* c, Options& o) {
  c->add_option("POINTS", o.points, "point file: .node, the vertices of a .poly, or plain text; read by rank 0")->required();
  CLI::Option* dim = c->add_option("--dim", o.dim,
                                   "dimension (default: a .node header's, or the count of numbers on the first line "
                                   "of plain text; given, the first 2 or 3 numbers of each line are the coordinates)")
                         ->check(CLI::IsMember({2, 3}));
  c->add_option("--box", o.box, "domain box: origin and side length (default: derived from the initial points)")
      ->expected(3, 4)
      ->type_name("o1 o2 [o3] L");
  c->add_option_function<std::string>(
       "--duplicates", [&o](const std::string& v) { o.skip_duplicates = v == "skip"; },
       "error (the default) or skip: drop later copies of a point")
      ->check(CLI::IsMember({"error", "skip"}));
  c->add_option("--edits", o.edits, "edit script: '+ x y [z]' inserts, '- x y [z]' deletes");
  c->add_option("--batch", o.batch, "propagate K consecutive edits together on all ranks (default: each alone)")
      ->check(whole_number(1, std::numeric_limits<std::size_t>::max()));
  return dim;
}

/// Test and experiment knobs, not part of the contract: hidden from --help.
void add_knobs(CLI::App* c, Options& o) {
  c->add_option("--partition-level", o.partition_level)->check(CLI::Range(0, 10))->group("");
  c->add_option("--ghost-ring", o.ghost_ring)->check(CLI::Range(0, 3))->group("");
  c->add_option("--rebalance", o.rebalance)->check(CLI::Range(0.0, 1e9))->group("");
}

int parse_and_run(MPI_Comm comm, int argc, char** argv) {
  const bool root = rank_of(comm) == 0;
  CLI::App app{"dynmesh-mpi: the dynamic quadtree T* and its meshes on MPI ranks, equal to `dynmesh quadtree` and "
               "`dynmesh mesh --postprocess quadtree` (docs/FORMATS.md, docs/DISTRIBUTED.md)"};
  app.require_subcommand(1);
  Options o;
  CLI::App* q = app.add_subcommand("quadtree", "Build T* of a point file on the ranks, apply an edit script, write the leaves");
  CLI::Option* dim = add_inputs(q, o);
  q->add_option("--cells", o.cells, "output: the final leaves as .cells (written by rank 0)")->required();
  q->add_flag("--stats", o.stats, "per rank on stderr: points owned, ghost points, trace bytes, mean propagation time, peak "
              "resident memory");
  add_knobs(q, o);
  q->add_flag("--measure-writing", o.measure_writing)->group("");
  q->parse_complete_callback([&o] {
    const std::string clash = output_overwrites_input({{"POINTS", o.points}, {"--edits", o.edits}}, {{"--cells", o.cells}});
    if (!clash.empty()) throw CLI::ValidationError(clash);
  });

  CLI::App* m = app.add_subcommand(
      "mesh", "Mesh the box of a point file on the ranks (the quadtree mesh in 2D, the octree's tetrahedra in 3D), "
              "apply an edit script, write the final mesh");
  CLI::Option* mesh_dim = add_inputs(m, o);
  m->add_option("--postprocess", o.postprocess,
                "quadtree: the quadtree mesh (2D) or the octree's tetrahedral mesh (3D); hpu does not run on ranks yet");
  CLI::Option* min_angle = m->add_option("--min-angle", o.min_angle, "2D: at most the quadtree mesh's bound");
  m->add_option("-o", o.outbase, "output: OUTBASE.node and OUTBASE.ele (written by rank 0)")->required();
  m->add_option("--feed", o.feed, "output: the change feed of every propagation");
  m->add_option("--vtk", o.vtk, "also write the mesh as legacy VTK");
  m->add_option("--msh", o.msh, "also write the mesh as Gmsh 2.2 ASCII");
  m->add_flag("--stats", o.stats, "per rank on stderr: points owned, ghost points, simplices owned, trace bytes, mean "
              "propagation time, peak resident memory");
  add_knobs(m, o);
  m->parse_complete_callback([&o] {
    if (o.outbase.empty()) throw CLI::ValidationError("-o needs a non-empty OUTBASE");
    const std::string clash = output_overwrites_input(
        {{"POINTS", o.points}, {"--edits", o.edits}},
        {{"-o", o.outbase + ".node"}, {"-o", o.outbase + ".ele"}, {"--feed", o.feed}, {"--vtk", o.vtk},
         {"--msh", o.msh}});
    if (!clash.empty()) throw CLI::ValidationError(clash);
  });
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Every rank parses the same arguments and fails alike; rank 0 speaks.
    if (e.get_exit_code() == 0) {
      if (root) app.exit(e);
      return 0;
    }
    if (root) print_error(std::string(e.what()) + " (see dynmesh-mpi --help)");
    return 2;
  }
  const bool meshing = m->parsed();
  o.dim_given = (meshing ? mesh_dim : dim)->count() > 0;
  o.min_angle_given = min_angle->count() > 0;
  // As `dynmesh quadtree`: --dim, else a .node header's, else the count of numbers on the
  // first line of plain text (io.hpp point_file_shape). Rank 0 looks; its error is everyone's.
  int shape[2] = {o.dim, 0};  // the dimension, and 1 for Columns::Exactly
  std::string message;
  if (root) {
    try {
      const PointFileShape found = point_file_shape(o.points, o.dim_given ? o.dim : 0);
      shape[0] = found.dim;
      shape[1] = found.columns == Columns::Exactly ? 1 : 0;
    } catch (const std::exception& e) {
      message = e.what();
    }
  }
  if (shared_failure(comm, message)) return root ? (print_error(message), 1) : 1;
  MPI_Bcast(shape, 2, MPI_INT, 0, comm);
  const int d = shape[0];
  const Columns columns = shape[1] != 0 ? Columns::Exactly : Columns::AtLeast;
  if (meshing) {
    // As `dynmesh mesh`: the 2D mesh's own options are a malformed command line in 3D; in
    // 2D, --postprocess and --min-angle as it takes them. DynHPU does not run on ranks yet.
    std::string why;
    try {
      if (d == 3) {
        why = mesh_options_2d_only(o.postprocess, o.min_angle_given, false);
        if (why.empty() && !o.postprocess.empty() && o.postprocess != "quadtree")
          why = "unknown --postprocess '" + o.postprocess + "' (quadtree, the 3D default)";
      } else if (check_postprocess(o.postprocess, false, o.min_angle_given ? std::optional<double>(o.min_angle)
                                                                            : std::nullopt) == PostprocessChoice::Hpu) {
        why = "the hpu mesh (the 2D default) does not run on ranks yet: pass --postprocess quadtree";
      }
    } catch (const std::exception& e) {
      why = e.what();
    }
    if (!why.empty()) {
      if (root) print_error(why);
      return 2;
    }
  }
  try {
    if (meshing) return d == 3 ? run_mesh<3>(comm, o, columns) : run_mesh<2>(comm, o, columns);
    return d == 3 ? run<3>(comm, o, columns) : run<2>(comm, o, columns);
  } catch (const std::exception& e) {
    // Only agreed failures reach here (MpiQuadtree throws on every rank alike).
    if (root) print_error(e.what());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  const int status = parse_and_run(MPI_COMM_WORLD, argc, argv);
  MPI_Finalize();
  return status;
}
