// tetgen_peer.cpp — see tetgen_peer.hpp.
#include "tetgen_peer.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "bench_stats.hpp"
#include "dynmesh/tet_mesh.hpp"
#include "dynmesh/tet_mesh_check.hpp"

namespace bench {

namespace fs = std::filesystem;
using dynmesh::Point;

namespace {

/// Skips blank lines and '#' comments; false at the end of the file.
bool next_line(std::istream& in, std::istringstream& line) {
  std::string text;
  while (std::getline(in, text)) {
    const auto at = text.find_first_not_of(" \t\r");
    if (at == std::string::npos || text[at] == '#') continue;
    line.clear();
    line.str(text);
    return true;
  }
  return false;
}

/// The box's corners as nodes 1..8 (bit k of i − 1 set: the far side in coordinate k), then
/// the points; the six facets; no holes, no regions.
void write_poly(const fs::path& path, const dynmesh::Box<3>& box, std::span<const Point<3>> points) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + path.string());
  std::fprintf(f, "%zu 3 0 0\n", points.size() + 8);
  for (int i = 0; i < 8; ++i) {
    double c[3];
    for (int k = 0; k < 3; ++k) c[k] = box.origin[k] + ((i >> k) & 1 ? box.side : 0.0);
    std::fprintf(f, "%d %.17g %.17g %.17g\n", i + 1, c[0], c[1], c[2]);
  }
  for (std::size_t i = 0; i < points.size(); ++i)
    std::fprintf(f, "%zu %.17g %.17g %.17g\n", i + 9, points[i][0], points[i][1], points[i][2]);
  // Facets: x = lo, x = hi, y = lo, y = hi, z = lo, z = hi, each a cycle of its corners.
  static constexpr int kFacets[6][4] = {{1, 3, 7, 5}, {2, 4, 8, 6}, {1, 2, 6, 5},
                                        {3, 4, 8, 7}, {1, 2, 4, 3}, {5, 6, 8, 7}};
  std::fprintf(f, "6 0\n");
  for (const auto& q : kFacets) std::fprintf(f, "1\n4 %d %d %d %d\n", q[0], q[1], q[2], q[3]);
  std::fprintf(f, "0\n0\n");
  if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + path.string());
}

/// Reads `stem`.node and `stem`.ele into `r` (counts and dihedral angles).
void read_mesh(const fs::path& stem, TetgenResult& r) {
  std::ifstream node(stem.string() + ".node"), ele(stem.string() + ".ele");
  if (!node || !ele) throw std::runtime_error("no " + stem.string() + ".node/.ele");
  std::istringstream line;
  std::size_t count = 0, nodes_per_tet = 0;
  int dim = 0;
  if (!next_line(node, line) || !(line >> count >> dim) || dim != 3) throw std::runtime_error("bad .node header");
  std::vector<Point<3>> vertices(count);
  long first = 0;
  for (std::size_t i = 0; i < count; ++i) {
    long index = 0;
    if (!next_line(node, line) || !(line >> index >> vertices[i][0] >> vertices[i][1] >> vertices[i][2]))
      throw std::runtime_error("bad .node line");
    if (i == 0) first = index;  // TetGen numbers its output from the input's first index
    if (index - first != static_cast<long>(i)) throw std::runtime_error(".node out of order");
  }
  if (!next_line(ele, line) || !(line >> r.tetrahedra >> nodes_per_tet) || nodes_per_tet < 4)
    throw std::runtime_error("bad .ele header");
  r.vertices = count;
  r.min_dihedral = 180;
  r.max_dihedral = 0;
  for (std::size_t t = 0; t < r.tetrahedra; ++t) {
    long index = 0;
    std::array<long, 4> c{};
    if (!next_line(ele, line) || !(line >> index >> c[0] >> c[1] >> c[2] >> c[3]))
      throw std::runtime_error("bad .ele line");
    dynmesh::Tetrahedron tet{};
    for (int k = 0; k < 4; ++k) {
      const long v = c[k] - first;
      if (v < 0 || v >= static_cast<long>(count)) throw std::runtime_error(".ele names no vertex");
      tet.v[k] = vertices[static_cast<std::size_t>(v)];
    }
    // The angles do not depend on the orientation (TetGen's is the opposite of ours).
    for (double a : dynmesh::dihedral_angles_deg(tet)) {
      r.min_dihedral = std::min(r.min_dihedral, a);
      r.max_dihedral = std::max(r.max_dihedral, a);
    }
  }
}

/// The figure after "Total running seconds:" in TetGen's -V log, or a negative number.
double reported_seconds(const fs::path& log) {
  std::ifstream in(log);
  std::string text;
  constexpr std::string_view kKey = "Total running seconds:";
  while (std::getline(in, text))
    if (const auto at = text.find(kKey); at != std::string::npos) return std::atof(text.c_str() + at + kKey.size());
  return -1;
}

std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

std::string find_tetgen() {
  const char* path = std::getenv("PATH");
  std::string_view dirs = path ? path : "/usr/bin:/bin";
  while (!dirs.empty()) {
    const auto colon = dirs.find(':');
    const fs::path candidate = fs::path(std::string(dirs.substr(0, colon))) / "tetgen";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    dirs = colon == std::string_view::npos ? std::string_view{} : dirs.substr(colon + 1);
  }
  return {};
}

TetgenResult tetgen_quality_mesh(const std::string& tetgen, const dynmesh::Box<3>& box,
                                 std::span<const Point<3>> points) {
  TetgenResult r;
  std::string pattern = (fs::temp_directory_path() / "dynmesh_tetgen_XXXXXX").string();
  if (!::mkdtemp(pattern.data())) {
    r.note = "tetgen: no temporary directory";
    return r;
  }
  const fs::path dir = pattern;
  try {
    write_poly(dir / "box.poly", box, points);
    const std::string command =
        quoted(tetgen) + " -pqFV " + quoted((dir / "box.poly").string()) + " > " + quoted((dir / "log").string()) + " 2>&1";
    int status = 0;
    r.wall_seconds = seconds([&] { status = std::system(command.c_str()); });
    if (status != 0) throw std::runtime_error("exit status " + std::to_string(status) + " (log in " + dir.string() + ")");
    read_mesh(dir / "box.1", r);
    const double own = reported_seconds(dir / "log");
    r.own_time = own >= 0;
    r.seconds = r.own_time ? own : r.wall_seconds;
    r.ran = true;
  } catch (const std::exception& e) {
    r.note = std::string("tetgen: ") + e.what();
    return r;  // the directory stays for a look at the log
  }
  std::error_code ignored;
  fs::remove_all(dir, ignored);
  return r;
}

}  // namespace bench
