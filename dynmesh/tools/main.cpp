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

/// An output that names an input file (distinct_paths.hpp) is a malformed command line.
void require_distinct(const std::string& points, const std::string& edits,
                      const std::vector<dynmesh::tool::NamedPath>& outputs) {
  const std::string clash =
      dynmesh::tool::output_overwrites_input({{"POINTS", points}, {"--edits", edits}}, outputs);
  if (!clash.empty()) throw CLI::ValidationError(clash);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace dynmesh::tool;
  CLI::App app{"dynmesh: dynamic well-graded quadtrees and quality meshes of changing point sets "
               "(file formats and contracts: docs/FORMATS.md)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("dynmesh ") + DYNMESH_VERSION, "print the version and exit");

  // Whole-number options: digits only, within range (number_options.hpp).
  const CLI::Validator at_least_one = whole_number(1, std::numeric_limits<std::size_t>::max());
  const CLI::Validator any_seed = whole_number(0, std::numeric_limits<std::uint64_t>::max());
  constexpr std::uint64_t kMaxCount = 1'000'000'000;  // points or updates: beyond memory anyway
  const char* const duplicates_help =
      "error (the default): a repeated point is an error; skip: drop later copies of a point and say how many";
  // The dimension rule of docs/FORMATS.md, "Input points" (io.hpp point_file_shape).
  const char* const dim_help =
      "dimension of the points (default: a .node header's, or the count of numbers on the first line of plain "
      "text, 2 or 3, which every line must then hold; given, the first 2 or 3 numbers of each line are the "
      "coordinates and further columns are ignored)";
  const char* const force_help = "build even when the estimated memory exceeds the memory available (see below)";
  const std::string svg_max_help = "--svg draws no input points when there are more than N (default " +
                                   std::to_string(dynmesh::kSvgMaxPoints) + ")";
  const char* const svg_radius_help =
      "--svg dot radius in pixels of the 1000-pixel drawing (default: from the number of points, a tenth of "
      "their even spacing, from 1 px (quadtree) or 1.5 px (mesh) down to 0.25 px)";
  // The memory guard's rule under each command's synopsis, with the costs per point it uses.
  auto memory_note = [](const std::string& costs) {
    return "Memory: a build whose estimated peak exceeds the memory available (the least of MemAvailable and "
           "what ulimit -v and ulimit -d leave) stops at once with exit status 1; one that fits is held to that "
           "memory (its data size is capped) and, should it outgrow it, stops with status 1 before writing "
           "anything; --force builds anyway, without the cap. "
           "Estimated peak per point held: " +
           costs + ".";
  };
  auto cost_text = [](const char* structure, const MemoryCost& cost, const char* check) {
    return std::string(structure) + " about " + human_bytes(cost.bytes_per_point) + ", " +
           human_bytes(cost.check_bytes_per_point) + " more " + check;
  };
  // The hpu meshes' costs rise with the angle bound (memory_guard.hpp: the costliest inputs,
  // points along curves, at 20.7 and 30 degrees).
  auto hpu_cost_text = [](const char* structure, const MemoryCost& low, const MemoryCost& high, const char* check) {
    std::string text(structure);
    text.append(" about ").append(human_bytes(low.bytes_per_point)).append(" at --min-angle 20.7 to ");
    text.append(human_bytes(high.bytes_per_point)).append(" at 30, ").append(human_bytes(low.check_bytes_per_point));
    text.append(" to ").append(human_bytes(high.check_bytes_per_point)).append(" more ").append(check);
    return text;
  };
  // A radius in pixels: positive, and no larger than the drawing.
  const CLI::Validator radius_px = CLI::Range(0.01, 1000.0);
  const CLI::Validator any_count = whole_number(0, std::numeric_limits<std::size_t>::max());
  // --svg-point-radius and --svg-max-points, which only mean something with `svg`.
  auto add_svg_density = [&](CLI::App* cmd, CLI::Option* svg, double& radius, std::size_t& max_points) {
    cmd->add_option("--svg-point-radius", radius, svg_radius_help)->check(radius_px)->needs(svg)->type_name("PX");
    cmd->add_option("--svg-max-points", max_points, svg_max_help)->check(any_count)->needs(svg)->type_name("N");
  };

  QuadtreeOptions q;
  CLI::App* quadtree = app.add_subcommand(
      "quadtree", "Build the quadtree T* of a point file, apply an edit script dynamically, write the leaves");
  quadtree->add_option("POINTS", q.points, "point file: .node (Triangle/TetGen), the vertices of a .poly, or plain text (x y [z] per "
                        "line; a first line without numbers is a header); - reads standard input")
      ->required();
  CLI::Option* dim_opt =
      quadtree->add_option("--dim", q.dim, dim_help)
          ->check(CLI::IsMember({2, 3}));
  quadtree->add_option("--box", q.box, "domain box: origin and side length (default: derived from the initial points)")
      ->expected(3, 4)
      ->type_name("o1 o2 [o3] L");
  quadtree
      ->add_option_function<std::string>(
          "--duplicates", [&q](const std::string& v) { q.skip_duplicates = v == "skip"; }, duplicates_help)
      ->check(CLI::IsMember({"error", "skip"}));
  quadtree->add_option("--edits", q.edits, "edit script: '+ x y [z]' inserts, '- x y [z]' deletes, one per line");
  quadtree->add_option("--batch", q.batch, "propagate K consecutive edits together (default: each edit alone)")
      ->check(at_least_one);
  quadtree->add_option("--cells", q.cells, "output: the final leaves as .cells")->required();
  quadtree->add_flag("--check", q.check, "also rebuild from scratch on the final points and fail if the trees differ");
  CLI::Option* quadtree_svg = quadtree->add_option("--svg", q.svg, "also draw the final tree and points (2D only)");
  add_svg_density(quadtree, quadtree_svg, q.svg_point_radius, q.svg_max_points);
  quadtree->add_flag("--force", q.force, force_help);
  quadtree->parse_complete_callback([&q] { require_distinct(q.points, q.edits, {{"--cells", q.cells}, {"--svg", q.svg}}); });
  quadtree->footer(
      "\nSynopsis (docs/FORMATS.md):\n"
      "  dynmesh quadtree POINTS [--dim 2|3] [--box o1 o2 [o3] L] [--duplicates error|skip]\n"
      "                   [--edits FILE] [--batch K] --cells OUT [--check]\n"
      "                   [--svg OUT.svg [--svg-point-radius PX] [--svg-max-points N]] [--force]\n\n" +
      memory_note(cost_text("quadtree (2D)", kQuadtree2dCost, "with --check") + "; " +
                  cost_text("octree (3D)", kOctree3dCost, "with --check")));

  MeshCommandOptions me;
  CLI::App* mesh = app.add_subcommand(
      "mesh", "Mesh the box of a point file (triangles in 2D, tetrahedra in 3D), apply an edit script dynamically, "
              "write the final mesh");
  mesh->add_option("POINTS", me.points, "point file: .node (Triangle/TetGen), the vertices of a .poly, or plain text (x y [z] per "
                    "line; a first line without numbers is a header); - reads standard input")->required();
  CLI::Option* mesh_dim_opt =
      mesh->add_option("--dim", me.dim, dim_help)
          ->check(CLI::IsMember({2, 3}));
  mesh->add_option("--box", me.box, "domain box: origin and side length (default: derived from the initial points)")
      ->expected(3, 4)
      ->type_name("o1 o2 [o3] L");
  mesh->add_option_function<std::string>(
          "--duplicates", [&me](const std::string& v) { me.skip_duplicates = v == "skip"; }, duplicates_help)
      ->check(CLI::IsMember({"error", "skip"}));
  mesh->add_option("--postprocess", me.postprocess,
                   "2D: hpu (the default: the off-center Delaunay mesh; self-adjusting under --edits) or quadtree (the "
                   "self-adjusting quadtree mesh, angles >= 18.4); 3D: quadtree (the default and only one: the "
                   "octree's tetrahedral mesh)");
  CLI::Option* min_angle_opt = mesh->add_option(
      "--min-angle", me.min_angle,
      "2D only: smallest angle in degrees: hpu 1 to 30 (default 20.7); quadtree 0 to 18.4 (its bound, always kept)");
  CLI::Option* mesh_svg = nullptr;  // set below; read when parsing completes
  // A bad --postprocess or --min-angle is a malformed command line (exit 2), found before
  // anything is read; so are the options of the 2D mesh alone with --dim 3 (points that turn
  // out 3D without --dim: run_mesh, before reading them).
  mesh->parse_complete_callback([&me, min_angle_opt, mesh_dim_opt, &mesh_svg] {
    if (mesh_dim_opt->count() > 0 && me.dim == 3) {
      const std::string why =
          mesh_options_2d_only(me.postprocess, min_angle_opt->count() > 0, mesh_svg && mesh_svg->count() > 0);
      if (!why.empty()) throw CLI::ValidationError(why);
    }
    check_postprocess_option(me.postprocess, /*allow_none=*/false, min_angle_opt, me.min_angle);
    require_distinct(me.points, me.edits,
                     {{"-o", me.outbase + ".node"}, {"-o", me.outbase + ".ele"}, {"--feed", me.feed},
                      {"--vtk", me.vtk}, {"--msh", me.msh}, {"--svg", me.svg}});
  });
  mesh->add_option("--edits", me.edits, "edit script: '+ x y [z]' inserts, '- x y [z]' deletes, one per line");
  mesh->add_option("--batch", me.batch, "propagate K consecutive edits together (default: each edit alone)")
      ->check(at_least_one);
  mesh->add_option("-o", me.outbase, "output base: writes OUTBASE.node and OUTBASE.ele")
      ->required()
      ->type_name("OUTBASE");
  mesh->add_option("--feed", me.feed, "also write the change feed of every propagation");
  mesh->add_option("--vtk", me.vtk, "also write the mesh as legacy VTK");
  mesh->add_option("--msh", me.msh, "also write the mesh as Gmsh 2.2 ASCII");
  mesh_svg = mesh->add_option("--svg", me.svg, "also draw the mesh and its input points (2D only)");
  add_svg_density(mesh, mesh_svg, me.svg_point_radius, me.svg_max_points);
  mesh->add_flag("--check", me.check, "also mesh the final points from scratch and fail unless the meshes agree");
  mesh->add_flag("--stats", me.stats, "print a quality report on stderr");
  mesh->add_flag("--force", me.force, force_help);
  mesh->footer(
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

  StabilityOptions s;
  CLI::App* stability = app.add_subcommand(
      "stability",
      "Measure the trace distance of single-point updates and append one CSV row per update: "
      "dist,dim,n,log2_spread,op,trace_distance,seconds. The updates alternate deletions and insertions of a "
      "distribution's points (--dist), or are the edits of a file applied to a point file (--points, --edits). "
      "log2_spread is log2(L/s) of the point set after that update, exact for every row (the closest-pair "
      "distance is maintained)");
  CLI::Option* stability_dim_opt =
      stability->add_option("--dim", s.dim, std::string("dimension (with --dist: required); with --points: ") + dim_help)
          ->check(CLI::IsMember({2, 3}));
  std::string distribution_names;
  for (const dynmesh::Distribution dist : dynmesh::all_distributions())
    distribution_names += (distribution_names.empty() ? "" : ", ") + std::string(dynmesh::distribution_name(dist));
  CLI::Option* dist_opt = stability->add_option("--dist", s.dist, "distribution: " + distribution_names);
  CLI::Option* n_opt = stability->add_option("--n", s.n, "number of points the tree is built on (with --dist)")
                           ->check(whole_number(2, kMaxCount));
  CLI::Option* spread_opt =
      stability->add_option("--spread", s.spread, "target spread L/s of the 'shrinking' distribution")
          ->capture_default_str();
  CLI::Option* updates_opt = stability->add_option("--updates", s.updates, "updates measured (with --dist)")
                                 ->capture_default_str()
                                 ->check(whole_number(0, kMaxCount));
  CLI::Option* seed_opt =
      stability->add_option("--seed", s.seed, "random seed (with --dist)")->capture_default_str()->check(any_seed);
  CLI::Option* points_opt = stability->add_option(
      "--points", s.points,
      "instead of --dist: build on this point file (.node or plain text, as quadtree and mesh read it); the CSV's "
      "dist is its base name without the extension, n its number of points");
  CLI::Option* stability_edits_opt = stability->add_option(
      "--edits", s.edits, "with --points: edit script ('+ x y [z]' inserts, '- x y [z]' deletes), one row per edit");
  CLI::Option* stability_box_opt =
      stability->add_option("--box", s.box, "with --points: domain box, origin and side length (default: derived)")
          ->expected(3, 4)
          ->type_name("o1 o2 [o3] L");
  // Which of the two sources, and the options each takes: a wrong mix is a malformed command
  // line (exit 2), reported by CLI11 as "--X excludes --Y" or "--X requires --Y".
  dist_opt->excludes(points_opt)->needs(stability_dim_opt)->needs(n_opt);
  points_opt->needs(stability_edits_opt);
  stability_edits_opt->needs(points_opt);
  stability_box_opt->needs(points_opt);
  for (CLI::Option* opt : {n_opt, spread_opt, updates_opt, seed_opt}) opt->excludes(points_opt);
  CLI::Option* stability_angle_opt = nullptr;  // set below; read when parsing completes
  stability->parse_complete_callback([dist_opt, points_opt, &s, &stability_angle_opt] {
    if (dist_opt->count() == 0 && points_opt->count() == 0) throw CLI::RequiredError("--dist or --points");
    check_postprocess_option(s.postprocess, /*allow_none=*/true, stability_angle_opt, s.min_angle);
    require_distinct(s.points, s.edits, {{"--csv", s.csv}, {"--plot", s.plot}});
  });
  stability->add_option("--postprocess", s.postprocess,
                        "none (the default: the quadtree alone), quadtree (the quadtree mesh too; in 3D the octree's "
                        "tetrahedral mesh) or hpu (2D: the off-center Delaunay mesh too); "
                        "with a mesh, trace_distance and seconds count the whole update, tree and mesh");
  stability_angle_opt = stability->add_option(
      "--min-angle", s.min_angle, "with a mesh: hpu's angle bound, 1 to 30 (default 20.7); quadtree: the smallest angle checked on the final mesh, 0 to 18.4");
  stability->add_option("--csv", s.csv, "output CSV (appended to; header written when new or empty)")->required();
  stability->add_option("--plot", s.plot, "also plot every row of the CSV with gnuplot (SVG)");
  stability->add_flag("--force", s.force, force_help);
  stability->footer(
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

  DemoOptions m;
  CLI::App* demo = app.add_subcommand(
      "demo", "Mesh an embedded clustered point set with DynHPU, time single-point updates, verify, draw the mesh");
  demo->add_option("--n", m.n, "number of points")->capture_default_str()->check(whole_number(2, kMaxCount));
  demo->add_option("--updates", m.updates, "updates (alternating deletions and insertions)")
      ->capture_default_str()
      ->check(whole_number(0, kMaxCount));
  demo->add_option("--seed", m.seed, "random seed of the point set and of the updates")
      ->capture_default_str()
      ->check(any_seed);
  demo->add_option("--svg", m.svg, "picture of the final mesh (empty: none)")->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    std::fprintf(stderr, "dynmesh: %s (see dynmesh --help)\n", one_line(e.what()).c_str());
    return 2;
  }

  try {
    if (*quadtree) {
      q.dim_given = dim_opt->count() > 0;
      return run_quadtree(q);
    }
    if (*mesh) {
      me.min_angle_given = min_angle_opt->count() > 0;
      me.dim_given = mesh_dim_opt->count() > 0;
      return run_mesh(me);
    }
    if (*stability) {
      s.min_angle_given = stability_angle_opt->count() > 0;
      s.dim_given = stability_dim_opt->count() > 0;
      s.points_given = points_opt->count() > 0;
      return run_stability(s);
    }
    if (*demo) return run_demo(m);
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
