// The text forms of a 3D mesh (see dynmesh/tet_mesh_io.hpp for the formats; the templates
// they share with 2D are in io/mesh_text.hpp).
#include "dynmesh/tet_mesh_io.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dynmesh/tet_mesh_check.hpp"
#include "geometry/tet_geometry.hpp"
#include "io/mesh_text.hpp"

namespace dynmesh {
namespace {

// Far above the dihedral angles' rounding error, far below any angle a histogram tells apart.
constexpr double kAngleAccuracyDeg = 1e-9;

}  // namespace

std::string format_node(const TetMesh& mesh, const Box<3>& box) { return detail::node_text<3>(mesh.vertices, box); }

std::string format_ele(const TetMesh& mesh) { return detail::ele_text<4>(mesh.tetrahedra); }

std::string format_vtk(const TetMesh& mesh) {
  return detail::vtk_text<3, 4>(mesh.vertices, mesh.tetrahedra, 10);  // VTK_TETRA
}

std::string format_msh(const TetMesh& mesh) {
  return detail::msh_text<3, 4>(mesh.vertices, mesh.tetrahedra, 4);  // 4-node tetrahedron
}

TetMesh read_tet_node_ele(const std::string& node_text, const std::string& ele_text) {
  TetMesh mesh;
  detail::read_node_ele_text<3, 4>(node_text, ele_text, {"tetrahedron", "tetrahedra"}, mesh.vertices,
                                   mesh.tetrahedra);
  return mesh;
}

TetMeshStats tet_mesh_stats(const TetMesh& mesh) {
  TetMeshStats stats;
  stats.vertices = mesh.num_vertices();
  stats.tetrahedra = mesh.num_tetrahedra();
  if (mesh.tetrahedra.empty()) return stats;
  constexpr double inf = std::numeric_limits<double>::infinity();
  stats.min_dihedral_deg = stats.shortest_edge = stats.smallest_volume = inf;
  stats.max_dihedral_deg = stats.longest_edge = stats.largest_volume = -inf;
  for (std::size_t t = 0; t < mesh.num_tetrahedra(); ++t) {
    const Tetrahedron tet = mesh.tetrahedron(t);
    // In the tetrahedron's frame scaled by a power of two (exact): the volume is infinite or
    // 0 only when it is beyond the doubles' range itself.
    const detail::TetEdges frame = detail::tet_edges(tet.v);
    const double six_volume = detail::det3(frame.edges[0], frame.edges[1], frame.edges[2]);
    const double volume = std::ldexp(six_volume / 6, 3 * frame.exponent);
    stats.smallest_volume = std::min(stats.smallest_volume, volume);
    stats.largest_volume = std::max(stats.largest_volume, volume);
    for (const auto& [i, j] : detail::kTetEdgePairs) {
      const Point<3>&p = tet.v[i], &q = tet.v[j];
      const double edge = std::hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]);  // no overflow or underflow
      stats.shortest_edge = std::min(stats.shortest_edge, edge);
      stats.longest_edge = std::max(stats.longest_edge, edge);
    }
    for (const double angle : dihedral_angles_deg(tet)) {
      stats.min_dihedral_deg = std::min(stats.min_dihedral_deg, angle);
      stats.max_dihedral_deg = std::max(stats.max_dihedral_deg, angle);
      ++stats.dihedral_histogram[detail::angle_bin(angle, kAngleAccuracyDeg)];
    }
    stats.max_radius_edge_ratio = std::max(stats.max_radius_edge_ratio, radius_edge_ratio(tet));
  }
  return stats;
}

std::string format_stats(const TetMeshStats& s, std::size_t num_inputs) {
  std::string out = "Mesh quality statistics:\n\n";
  out += "  Vertices: " + std::to_string(s.vertices) + "    Tetrahedra: " + std::to_string(s.tetrahedra) + '\n';
  out += "  Input points: " + std::to_string(num_inputs);
  if (num_inputs != 0)
    out += "    Tetrahedra per input point: " +
           format_brief(static_cast<double>(s.tetrahedra) / static_cast<double>(num_inputs));
  out += "\n\n";
  constexpr std::size_t kLabel = 19;  // "Smallest dihedral:" and a space
  detail::append_stats_row(out, "Smallest volume:", s.smallest_volume, "Largest volume:", s.largest_volume, kLabel);
  detail::append_stats_row(out, "Shortest edge:", s.shortest_edge, "Longest edge:", s.longest_edge, kLabel);
  detail::append_stats_row(out, "Smallest dihedral:", s.min_dihedral_deg, "Largest dihedral:", s.max_dihedral_deg,
                           kLabel);
  out += "  Largest radius-edge ratio: " + format_brief(s.max_radius_edge_ratio) + '\n';
  out += "\n  Dihedral angle histogram:\n";
  detail::append_angle_histogram(out, s.dihedral_histogram);
  return out;
}

std::string format_feed_update(std::size_t k, const TetMeshChange& change) {
  std::string out;
  append_feed_update(out, k, change);
  return out;
}

void append_feed_update(std::string& out, std::size_t k, const TetMeshChange& change) {
  detail::append_feed_update_text<Tetrahedron>(out, k, change.removed, change.added);
}

}  // namespace dynmesh
