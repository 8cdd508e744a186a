// dynmesh — the command-line tool of the dynmesh library (docs/FORMATS.md):
//   dynmesh quadtree POINTS [--dim 2|3] [--box o1 o2 [o3] L] [--duplicates error|skip]
//                   [--edits FILE] [--batch K] --cells OUT [--check] [--svg OUT.svg]
//                   [--svg-point-radius PX] [--svg-max-points N] [--force]
//   dynmesh mesh POINTS [--dim 2|3] [--box o1 o2 [o3] L] [--duplicates error|skip]
//                [--postprocess hpu|quadtree] [--min-angle DEG] [--edits FILE] [--batch K]
//                -o OUTBASE [--feed F] [--vtk F] [--msh F] [--svg F] [--svg-point-radius PX]
//                [--svg-max-points N] [--check] [--stats] [--force]
//                (3D: the octree's tetrahedral mesh; hpu, --min-angle and --svg are 2D only)
//   dynmesh stability --dim 2|3 --dist NAME --n N [--spread S] [--updates U] [--seed X]
//                     [--postprocess none|quadtree|hpu] [--min-angle DEG] --csv OUT.csv [--plot OUT.svg]
//                     [--force]
//   dynmesh stability --points POINTS --edits FILE [--dim 2|3] [--box o1 o2 [o3] L]
//                     [--postprocess none|quadtree|hpu] [--min-angle DEG] --csv OUT.csv [--plot OUT.svg]
//                     [--force]
//   dynmesh demo [--n N] [--updates U] [--seed X] [--svg OUT.svg]
//   dynmesh --version
// Exit status: 0 on success; 1 with exactly one line `dynmesh: <message>` on stderr on any
// error (a build refused by the memory guard included); 2 for a command line CLI11 rejects
// (also one line), a bad --postprocess or --min-angle, an option of the 2D mesh given 3D
// points (CommandLineError), or an output path naming an input file (distinct_paths.hpp). Messages have their control bytes escaped (one_line). Progress lines (progress.hpp) go to stderr too, only on runs longer than a
// second (DYNMESH_PROGRESS_DELAY_MS overrides the second, for tests).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <functional>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "distinct_paths.hpp"
#include "dynmesh/distributions.hpp"
#include "memory_guard.hpp"
#include "number_options.hpp"
#include "postprocess_option.hpp"
#include "verify.hpp"

namespace {

using namespace dynmesh::tool;

constexpr std::uint64_t kMaxCount = 1'000'000'000;  // points or updates: beyond memory anyway

constexpr const char* kPointsHelp =
    "point file: .node (Triangle/TetGen), the vertices of a .poly, or plain text (x y [z] per line; a first line "
    "without numbers is a header); - reads standard input";
constexpr const char* kDuplicatesHelp =
    "error (the default): a repeated point is an error; skip: drop later copies of a point and say how many";
// The dimension rule of docs/FORMATS.md, "Input points" (io.hpp point_file_shape).
constexpr const char* kDimHelp =
    "dimension of the points (default: a .node header's, or the count of numbers on the first line of plain "
    "text, 2 or 3, which every line must then hold; given, the first 2 or 3 numbers of each line are the "
    "coordinates and further columns are ignored)";
constexpr const char* kForceHelp = "build even when the estimated memory exceeds the memory available (see below)";
constexpr const char* kSvgRadiusHelp =
    "--svg dot radius in pixels of the 1000-pixel drawing (default: from the number of points, a tenth of "
    "their even spacing, from 1 px (quadtree) or 1.5 px (mesh) down to 0.25 px)";

/// A subcommand and what runs it once the command line is parsed.
struct Command {
  CLI::App* app;
  std::function<int()> run;
};

/// An output that names an input file (distinct_paths.hpp) is a malformed command line.
void require_distinct(const std::string& points, const std::string& edits,
                      const std::vector<NamedPath>& outputs) {
  const std::string clash = output_overwrites_input({{"POINTS", points}, {"--edits", edits}}, outputs);
  if (!clash.empty()) throw CLI::ValidationError(clash);
}

// ---- the help's memory notes --------------------------------------------------------------

/// The memory guard's rule under each command's synopsis, with the costs per point it uses.
std::string memory_note(const std::string& costs) {
  return "Memory: a build whose estimated peak exceeds the memory available (the least of MemAvailable and "
         "what ulimit -v and ulimit -d leave) stops at once with exit status 1; one that fits is held to that "
         "memory (its data size is capped) and, should it outgrow it, stops with status 1 before writing "
         "anything; --force builds anyway, without the cap. "
         "Estimated peak per point held: " +
         costs + ".";
}

/// One structure's cost per point, and what a check adds.
std::string cost_text(const char* structure, const MemoryCost& cost, const char* check) {
  return std::string(structure) + " about " + human_bytes(cost.bytes_per_point) + ", " +
         human_bytes(cost.check_bytes_per_point) + " more " + check;
}

/// The hpu meshes' costs rise with the angle bound (memory_guard.hpp: the costliest inputs,
/// points along curves, at 20.7 and 30 degrees).
std::string hpu_cost_text(const char* structure, const MemoryCost& low, const MemoryCost& high, const char* check) {
  std::string text(structure);
  text.append(" about ").append(human_bytes(low.bytes_per_point)).append(" at --min-angle 20.7 to ");
  text.append(human_bytes(high.bytes_per_point)).append(" at 30, ").append(human_bytes(low.check_bytes_per_point));
  text.append(" to ").append(human_bytes(high.check_bytes_per_point)).append(" more ").append(check);
  return text;
}

// ---- options shared by the subcommands ----------------------------------------------------
// Whole-number options: digits only, within range (number_options.hpp).

/// POINTS, --dim, --box and --duplicates, as quadtree and mesh read a point file; returns --dim.
CLI::Option* add_point_file_options(CLI::App* cmd, std::string& points, int& dim, std::vector<double>& box,
                                    bool& skip_duplicates) {
  cmd->add_option("POINTS", points, kPointsHelp)->required();
  CLI::Option* dim_option = cmd->add_option("--dim", dim, kDimHelp)->check(CLI::IsMember({2, 3}));
  cmd->add_option("--box", box, "domain box: origin and side length (default: derived from the initial points)")
      ->expected(3, 4)
      ->type_name("o1 o2 [o3] L");
  cmd->add_option_function<std::string>(
         "--duplicates", [&skip_duplicates](const std::string& v) { skip_duplicates = v == "skip"; }, kDuplicatesHelp)
      ->check(CLI::IsMember({"error", "skip"}));
  return dim_option;
}

/// --edits and --batch.
void add_edit_options(CLI::App* cmd, std::string& edits, std::size_t& batch) {
  cmd->add_option("--edits", edits, "edit script: '+ x y [z]' inserts, '- x y [z]' deletes, one per line");
  cmd->add_option("--batch", batch, "propagate K consecutive edits together (default: each edit alone)")
      ->check(whole_number(1, std::numeric_limits<std::size_t>::max()));
}

/// --svg-point-radius and --svg-max-points, which only mean something with `svg`.
void add_svg_density(CLI::App* cmd, CLI::Option* svg, double& radius, std::size_t& max_points) {
  const std::string max_points_help = "--svg draws no input points when there are more than N (default " +
                                      std::to_string(dynmesh::kSvgMaxPoints) + ")";
  // A radius in pixels: positive, and no larger than the drawing.
  cmd->add_option("--svg-point-radius", radius, kSvgRadiusHelp)->check(CLI::Range(0.01, 1000.0))->needs(svg)->type_name("PX");
  cmd->add_option("--svg-max-points", max_points, max_points_help)
      ->check(whole_number(0, std::numeric_limits<std::size_t>::max()))
      ->needs(svg)
      ->type_name("N");
}

/// --seed, any 64-bit value.
CLI::Option* add_seed_option(CLI::App* cmd, std::uint64_t& seed, const char* help) {
  return cmd->add_option("--seed", seed, help)
      ->capture_default_str()
      ->check(whole_number(0, std::numeric_limits<std::uint64_t>::max()));
}

// ---- the subcommands ----------------------------------------------------------------------

/// `dynmesh quadtree`.
Command add_quadtree_command(CLI::App& app, QuadtreeOptions& q) {
  CLI::App* cmd = app.add_subcommand(
      "quadtree", "Build the quadtree T* of a point file, apply an edit script dynamically, write the leaves");
  CLI::Option* dim_option = add_point_file_options(cmd, q.points, q.dim, q.box, q.skip_duplicates);
  add_edit_options(cmd, q.edits, q.batch);
  cmd->add_option("--cells", q.cells, "output: the final leaves as .cells")->required();
  cmd->add_flag("--check", q.check, "also rebuild from scratch on the final points and fail if the trees differ");
  CLI::Option* svg = cmd->add_option("--svg", q.svg, "also draw the final tree and points (2D only)");
  add_svg_density(cmd, svg, q.svg_point_radius, q.svg_max_points);
  cmd->add_flag("--force", q.force, kForceHelp);
  cmd->parse_complete_callback([&q] { require_distinct(q.points, q.edits, {{"--cells", q.cells}, {"--svg", q.svg}}); });
  cmd->footer(
      "\nSynopsis (docs/FORMATS.md):\n"
      "  dynmesh quadtree POINTS [--dim 2|3] [--box o1 o2 [o3] L] [--duplicates error|skip]\n"
      "                   [--edits FILE] [--batch K] --cells OUT [--check]\n"
      "                   [--svg OUT.svg [--svg-point-radius PX] [--svg-max-points N]] [--force]\n\n" +
      memory_note(cost_text("quadtree (2D)", kQuadtree2dCost, "with --check") + "; " +
                  cost_text("octree (3D)", kOctree3dCost, "with --check")));
  return {cmd, [&q, dim_option] {
            q.dim_given = dim_option->count() > 0;
            return run_quadtree(q);
          }};
}

/// `dynmesh mesh`.
Command add_mesh_command(CLI::App& app, MeshCommandOptions& me) {
  CLI::App* cmd = app.add_subcommand(
      "mesh", "Mesh the box of a point file (triangles in 2D, tetrahedra in 3D), apply an edit script dynamically, "
              "write the final mesh");
  CLI::Option* dim_option = add_point_file_options(cmd, me.points, me.dim, me.box, me.skip_duplicates);
  cmd->add_option("--postprocess", me.postprocess,
                  "2D: hpu (the default: the off-center Delaunay mesh; self-adjusting under --edits) or quadtree (the "
                  "self-adjusting quadtree mesh, angles >= 18.4); 3D: quadtree (the default and only one: the "
                  "octree's tetrahedral mesh)");
  CLI::Option* min_angle_option = cmd->add_option(
      "--min-angle", me.min_angle,
      "2D only: smallest angle in degrees: hpu 1 to 30 (default 20.7); quadtree 0 to 18.4 (its bound, always kept)");
  add_edit_options(cmd, me.edits, me.batch);
  cmd->add_option("-o", me.outbase, "output base: writes OUTBASE.node and OUTBASE.ele")
      ->required()
      ->type_name("OUTBASE");
  cmd->add_option("--feed", me.feed, "also write the change feed of every propagation");
  cmd->add_option("--vtk", me.vtk, "also write the mesh as legacy VTK");
  cmd->add_option("--msh", me.msh, "also write the mesh as Gmsh 2.2 ASCII");
  CLI::Option* svg = cmd->add_option("--svg", me.svg, "also draw the mesh and its input points (2D only)");
  add_svg_density(cmd, svg, me.svg_point_radius, me.svg_max_points);
  cmd->add_flag("--check", me.check, "also mesh the final points from scratch and fail unless the meshes agree");
  cmd->add_flag("--stats", me.stats, "print a quality report on stderr");
  cmd->add_flag("--force", me.force, kForceHelp);
  // A bad --postprocess or --min-angle is a malformed command line (exit 2), found before
  // anything is read; so are the options of the 2D mesh alone with --dim 3 (points that turn
  // out 3D without --dim: run_mesh, before reading them).
  cmd->parse_complete_callback([&me, min_angle_option, dim_option, svg] {
    if (dim_option->count() > 0 && me.dim == 3) {
      const std::string why = mesh_options_2d_only(me.postprocess, min_angle_option->count() > 0, svg->count() > 0);
      if (!why.empty()) throw CLI::ValidationError(why);
    }
    check_postprocess_option(me.postprocess, /*allow_none=*/false, min_angle_option, me.min_angle);
    require_distinct(me.points, me.edits,
                     {{"-o", me.outbase + ".node"}, {"-o", me.outbase + ".ele"}, {"--feed", me.feed},
                      {"--vtk", me.vtk}, {"--msh", me.msh}, {"--svg", me.svg}});
  });
  cmd->footer(
      "\nSynopsis (docs/FORMATS.md):\n"
      "  dynmesh mesh POINTS [--dim 2|3] [--box o1 o2 [o3] L] [--duplicates error|skip]\n"
      "               [--postprocess hpu|quadtree] [--min-angle DEG] [--edits FILE] [--batch K]\n"
      "               -o OUTBASE [--feed F] [--vtk F] [--msh F]\n"
      "               [--svg F [--svg-point-radius PX] [--svg-max-points N]] [--check] [--stats] [--force]\n"
      "  In 3D the mesh is the octree's tetrahedral mesh: --postprocess hpu, --min-angle and --svg are 2D only.\n\n" +
      memory_note(hpu_cost_text("hpu mesh with --edits (self-adjusting)", kHpuDynamicCostLow, kHpuDynamicCostHigh,
                                "with --check") + "; " +
                  hpu_cost_text("hpu mesh without --edits", kHpuMeshCostLow, kHpuMeshCostHigh, "with --check") + "; " +
                  cost_text("quadtree mesh", kQuadtreeMeshCost, "with --check") + "; " +
                  cost_text("octree mesh (3D)", kOctreeMeshCost, "with --check")));
  return {cmd, [&me, min_angle_option, dim_option] {
            me.min_angle_given = min_angle_option->count() > 0;
            me.dim_given = dim_option->count() > 0;
            return run_mesh(me);
          }};
}

/// `dynmesh stability`.
Command add_stability_command(CLI::App& app, StabilityOptions& s) {
  CLI::App* cmd = app.add_subcommand(
      "stability",
      "Measure the trace distance of single-point updates and append one CSV row per update: "
      "dist,dim,n,log2_spread,op,trace_distance,seconds. The updates alternate deletions and insertions of a "
      "distribution's points (--dist), or are the edits of a file applied to a point file (--points, --edits). "
      "log2_spread is log2(L/s) of the point set after that update, exact for every row (the closest-pair "
      "distance is maintained)");
  CLI::Option* dim_option =
      cmd->add_option("--dim", s.dim, std::string("dimension (with --dist: required); with --points: ") + kDimHelp)
          ->check(CLI::IsMember({2, 3}));
  std::string distribution_names;
  for (const dynmesh::Distribution dist : dynmesh::all_distributions())
    distribution_names += (distribution_names.empty() ? "" : ", ") + std::string(dynmesh::distribution_name(dist));
  CLI::Option* dist_option = cmd->add_option("--dist", s.dist, "distribution: " + distribution_names);
  CLI::Option* n_option = cmd->add_option("--n", s.n, "number of points the tree is built on (with --dist)")
                              ->check(whole_number(2, kMaxCount));
  CLI::Option* spread_option =
      cmd->add_option("--spread", s.spread, "target spread L/s of the 'shrinking' distribution")->capture_default_str();
  CLI::Option* updates_option = cmd->add_option("--updates", s.updates, "updates measured (with --dist)")
                                    ->capture_default_str()
                                    ->check(whole_number(0, kMaxCount));
  CLI::Option* seed_option = add_seed_option(cmd, s.seed, "random seed (with --dist)");
  CLI::Option* points_option = cmd->add_option(
      "--points", s.points,
      "instead of --dist: build on this point file (.node or plain text, as quadtree and mesh read it); the CSV's "
      "dist is its base name without the extension, n its number of points");
  CLI::Option* edits_option = cmd->add_option(
      "--edits", s.edits, "with --points: edit script ('+ x y [z]' inserts, '- x y [z]' deletes), one row per edit");
  CLI::Option* box_option =
      cmd->add_option("--box", s.box, "with --points: domain box, origin and side length (default: derived)")
          ->expected(3, 4)
          ->type_name("o1 o2 [o3] L");
  // Which of the two sources, and the options each takes: a wrong mix is a malformed command
  // line (exit 2), reported by CLI11 as "--X excludes --Y" or "--X requires --Y".
  dist_option->excludes(points_option)->needs(dim_option)->needs(n_option);
  points_option->needs(edits_option);
  edits_option->needs(points_option);
  box_option->needs(points_option);
  for (CLI::Option* option : {n_option, spread_option, updates_option, seed_option}) option->excludes(points_option);
  cmd->add_option("--postprocess", s.postprocess,
                  "none (the default: the quadtree alone), quadtree (the quadtree mesh too; in 3D the octree's "
                  "tetrahedral mesh) or hpu (2D: the off-center Delaunay mesh too); "
                  "with a mesh, trace_distance and seconds count the whole update, tree and mesh");
  CLI::Option* min_angle_option = cmd->add_option(
      "--min-angle", s.min_angle,
      "with a mesh: hpu's angle bound, 1 to 30 (default 20.7); quadtree: the smallest angle checked on the final "
      "mesh, 0 to 18.4");
  cmd->add_option("--csv", s.csv, "output CSV (appended to; header written when new or empty)")->required();
  cmd->add_option("--plot", s.plot, "also plot every row of the CSV with gnuplot (SVG)");
  cmd->add_flag("--force", s.force, kForceHelp);
  cmd->parse_complete_callback([dist_option, points_option, &s, min_angle_option] {
    if (dist_option->count() == 0 && points_option->count() == 0) throw CLI::RequiredError("--dist or --points");
    check_postprocess_option(s.postprocess, /*allow_none=*/true, min_angle_option, s.min_angle);
    require_distinct(s.points, s.edits, {{"--csv", s.csv}, {"--plot", s.plot}});
  });
  cmd->footer(
      "\nSynopsis (docs/FORMATS.md):\n"
      "  dynmesh stability --dim 2|3 --dist NAME --n N [--spread S] [--updates U] [--seed X]\n"
      "                    [--postprocess none|quadtree|hpu] [--min-angle DEG] --csv OUT.csv\n"
      "                    [--plot OUT.svg] [--force]\n"
      "  dynmesh stability --points POINTS --edits FILE [--dim 2|3] [--box o1 o2 [o3] L]\n"
      "                    [--postprocess none|quadtree|hpu] [--min-angle DEG] --csv OUT.csv\n"
      "                    [--plot OUT.svg] [--force]\n\n" +
      memory_note(cost_text("quadtree (2D)", kQuadtree2dCost, "for the final check") + "; " +
                  cost_text("octree (3D)", kOctree3dCost, "for the final check") + "; " +
                  cost_text("quadtree mesh", kQuadtreeMeshCost, "for the final check") + "; " +
                  cost_text("octree mesh (3D)", kOctreeMeshCost, "for the final check") + "; " +
                  hpu_cost_text("hpu mesh", kHpuDynamicCostLow, kHpuDynamicCostHigh, "for the final check") +
                  "; the structure holds at most N + U/2 points (--dist), or the points of POINTS and the '+' "
                  "lines of FILE (--points)"));
  return {cmd, [&s, min_angle_option, dim_option, points_option] {
            s.min_angle_given = min_angle_option->count() > 0;
            s.dim_given = dim_option->count() > 0;
            s.points_given = points_option->count() > 0;
            return run_stability(s);
          }};
}

/// `dynmesh demo`.
Command add_demo_command(CLI::App& app, DemoOptions& m) {
  CLI::App* cmd = app.add_subcommand(
      "demo", "Mesh an embedded clustered point set with DynHPU, time single-point updates, verify, draw the mesh");
  cmd->add_option("--n", m.n, "number of points")->capture_default_str()->check(whole_number(2, kMaxCount));
  cmd->add_option("--updates", m.updates, "updates (alternating deletions and insertions)")
      ->capture_default_str()
      ->check(whole_number(0, kMaxCount));
  add_seed_option(cmd, m.seed, "random seed of the point set and of the updates");
  cmd->add_option("--svg", m.svg, "picture of the final mesh (empty: none)")->capture_default_str();
  return {cmd, [&m] { return run_demo(m); }};
}

/// Runs the parsed subcommand; an error becomes one line on stderr and exit status 2 (a
/// malformed command line) or 1.
int run(const std::vector<Command>& commands) {
  try {
    for (const Command& command : commands)
      if (*command.app) return command.run();
  } catch (const CommandLineError& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "dynmesh: %s (see dynmesh --help)\n", one_line(e.what()).c_str());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fflush(stdout);
    std::fprintf(stderr, "dynmesh: %s\n", out_of_memory_message().c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "dynmesh: %s\n", one_line(e.what()).c_str());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynmesh: dynamic well-graded quadtrees and quality meshes of changing point sets "
               "(file formats and contracts: docs/FORMATS.md)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("dynmesh ") + DYNMESH_VERSION, "print the version and exit");

  QuadtreeOptions quadtree;
  MeshCommandOptions mesh;
  StabilityOptions stability;
  DemoOptions demo;
  const std::vector<Command> commands{add_quadtree_command(app, quadtree), add_mesh_command(app, mesh),
                                      add_stability_command(app, stability), add_demo_command(app, demo)};

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    std::fprintf(stderr, "dynmesh: %s (see dynmesh --help)\n", one_line(e.what()).c_str());
    return 2;
  }
  return run(commands);
}
