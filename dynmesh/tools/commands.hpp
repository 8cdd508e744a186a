// dynmesh/tools/commands.hpp — the subcommands of the `dynmesh` program (private to the tool).
//
// Purpose: one options struct and one entry point per subcommand; main.cpp parses the
// command line into these with CLI11 and calls the entry point. The contracts are
// docs/FORMATS.md's `dynmesh quadtree`, `dynmesh mesh` (2D and 3D) and `dynmesh stability`
// (on a distribution, or on a point file and an edit file); `demo` is the README's main job.
// Invariants: an entry point returns the exit status (0 success, 1 failure) or throws; every
// exception becomes one line `dynmesh: <message>` on stderr in main.cpp (exit status 1, or 2
// for a CommandLineError), so the commands never print errors themselves.
// Complexity: see each command's source file.
// Paper: Acar & Hudson, "Optimal-time dynamic mesh refinement" (the quadtree; the stability
// bound O(lg L/s) that `stability` measures).
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynmesh/svg.hpp"

namespace dynmesh::tool {

struct QuadtreeOptions {
  std::string points;       // POINTS: .node or plain text
  int dim = 2;              // --dim
  bool dim_given = false;   // --dim appeared (else a .node header decides)
  std::vector<double> box;  // --box o1 o2 [o3] L (empty: derive from the initial points)
  bool skip_duplicates = false;  // --duplicates skip (default error)
  std::string edits;        // --edits FILE
  std::size_t batch = 0;    // --batch K (0: one propagation per edit)
  std::string cells;        // --cells OUT
  bool check = false;       // --check
  std::string svg;          // --svg OUT.svg (2D)
  double svg_point_radius = 0;                // --svg-point-radius PX (0: from the point count)
  std::size_t svg_max_points = kSvgMaxPoints;  // --svg-max-points N
  bool force = false;       // --force: skip the memory guard (memory_guard.hpp)
};

// `dynmesh mesh` (2D and 3D); named apart from dynmesh::MeshOptions, the library's.
struct MeshCommandOptions {
  std::string points;            // POINTS: .node or plain text
  int dim = 2;                   // --dim
  bool dim_given = false;        // --dim appeared (else the file decides: io.hpp point_file_shape)
  std::vector<double> box;       // --box o1 o2 [o3] L (empty: derive from the initial points)
  bool skip_duplicates = false;  // --duplicates skip (default error)
  std::string postprocess;       // --postprocess hpu|quadtree (empty: the default, hpu in 2D, quadtree in 3D)
  double min_angle = 0;          // --min-angle DEG
  bool min_angle_given = false;  // --min-angle appeared
  std::string edits;             // --edits FILE
  std::size_t batch = 0;         // --batch K (0: one propagation per edit)
  std::string outbase;           // -o OUTBASE: OUTBASE.node and OUTBASE.ele
  std::string feed;              // --feed F
  std::string vtk;               // --vtk F
  std::string msh;               // --msh F
  std::string svg;               // --svg F
  double svg_point_radius = 0;   // --svg-point-radius PX (0: from the point count)
  std::size_t svg_max_points = kSvgMaxPoints;  // --svg-max-points N
  bool check = false;            // --check
  bool stats = false;            // --stats
  bool force = false;            // --force: skip the memory guard (memory_guard.hpp)
};

struct StabilityOptions {
  int dim = 2;
  bool dim_given = false;        // --dim appeared (with --points, else a .node header decides)
  std::string points;            // --points POINTS (instead of --dist): the user's points
  bool points_given = false;     // --points appeared
  std::string edits;             // --edits FILE (with --points): the edits measured, one row each
  std::vector<double> box;       // --box o1 o2 [o3] L (with --points; empty: derived)
  std::string postprocess;       // --postprocess none|quadtree|hpu (empty: none, the tree alone)
  double min_angle = 0;          // --min-angle DEG (checked on the final mesh)
  bool min_angle_given = false;  // --min-angle appeared
  std::string dist;
  std::size_t n = 0;
  double spread = 0x1p20;
  std::size_t updates = 1000;
  std::uint64_t seed = 1;
  std::string csv;
  std::string plot;  // --plot OUT.svg (empty: no plot)
  bool force = false;  // --force: skip the memory guard (memory_guard.hpp)
};

struct DemoOptions {
  std::size_t n = 20000;
  std::size_t updates = 2000;
  std::uint64_t seed = 1;
  std::string svg = "dynmesh-demo.svg";
};

/// A command line that is malformed for what the files turn out to hold (an option of the
/// 2D mesh given 3D points): main.cpp prints it as CLI11's errors, one line, exit status 2.
struct CommandLineError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

int run_quadtree(const QuadtreeOptions& options);
int run_mesh(const MeshCommandOptions& options);
int run_stability(const StabilityOptions& options);
int run_demo(const DemoOptions& options);

/// Plots a stability CSV (all its rows, earlier runs included) to `svg_path` with gnuplot.
void plot_stability_csv(const std::string& csv_path, const std::string& svg_path);

}  // namespace dynmesh::tool
