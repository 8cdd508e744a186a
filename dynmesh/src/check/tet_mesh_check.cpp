// The checker of the 3D mesh contract (see dynmesh/tet_mesh_check.hpp for what it checks).
#include "dynmesh/tet_mesh_check.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <compare>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "check/check_support.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/predicates.hpp"
#include "geometry/tet_geometry.hpp"

namespace dynmesh {

std::string_view defect_name(TetMeshDefect defect) noexcept {
  switch (defect) {
    case TetMeshDefect::Canonical:
      return "canonical";
    case TetMeshDefect::BadIndex:
      return "bad-index";
    case TetMeshDefect::Orientation:
      return "orientation";
    case TetMeshDefect::OutsideBox:
      return "outside-box";
    case TetMeshDefect::IsolatedVertex:
      return "isolated-vertex";
    case TetMeshDefect::MissingCorner:
      return "missing-corner";
    case TetMeshDefect::FaceTwice:
      return "face-twice";
    case TetMeshDefect::OpenFace:
      return "open-face";
    case TetMeshDefect::Volume:
      return "volume";
    case TetMeshDefect::MissingInput:
      return "missing-input";
    case TetMeshDefect::SmallDihedral:
      return "small-dihedral";
    case TetMeshDefect::LargeDihedral:
      return "large-dihedral";
  }
  return "unknown";
}

bool TetMeshReport::ok() const noexcept {
  for (std::size_t c : counts)
    if (c != 0) return false;
  return true;
}

std::string TetMeshReport::summary() const {
  if (ok())
    return "tetrahedral mesh ok: dihedral angles in [" + format_exact(min_dihedral_deg) + ", " +
           format_exact(max_dihedral_deg) + "] degrees";
  return detail::invalid_summary<TetMeshDefect>("tetrahedral mesh", *this);
}

std::array<double, 6> dihedral_angles_deg(const Tetrahedron& tet) noexcept {
  // The corners off each edge of detail::kTetEdgePairs, in the same order.
  constexpr std::array<std::array<std::size_t, 2>, 6> kOff{{{2, 3}, {1, 3}, {1, 2}, {0, 3}, {0, 2}, {0, 1}}};
  const detail::TetEdges frame = detail::tet_edges(tet.v);
  std::array<double, 6> angles{};
  for (std::size_t k = 0; k < 6; ++k) {
    const std::size_t from = detail::kTetEdgePairs[k][0];
    const detail::Vec3& e = frame.edges[k];
    const detail::Vec3 u = frame.from_to(from, kOff[k][0]), w = frame.from_to(from, kOff[k][1]);
    // The normals e × u and e × w are u and w with their components along e removed, turned
    // by the same quarter turn about e and scaled by |e|: their angle is the dihedral angle,
    // and their cross product is det(e, u, w)·e.
    const double sine = std::abs(detail::det3(e, u, w)) * std::sqrt(detail::dot(e, e));
    const double cosine = detail::dot(detail::cross(e, u), detail::cross(e, w));
    angles[k] = std::atan2(sine, cosine) * (180.0 / std::numbers::pi);
  }
  return angles;
}

double radius_edge_ratio(const Tetrahedron& tet) noexcept {
  const detail::TetEdges frame = detail::tet_edges(tet.v);
  const detail::Vec3 &u = frame.edges[0], &v = frame.edges[1], &w = frame.edges[2];
  const double det = detail::det3(u, v, w);
  if (det == 0) return std::numeric_limits<double>::infinity();
  // The circumcentre relative to v0: (|u|² v × w + |v|² w × u + |w|² u × v) / (2 det).
  const detail::Vec3 vw = detail::cross(v, w), wu = detail::cross(w, u), uv = detail::cross(u, v);
  const double uu = detail::dot(u, u), vv = detail::dot(v, v), ww = detail::dot(w, w);
  detail::Vec3 centre{};
  for (std::size_t a = 0; a < 3; ++a) centre[a] = (uu * vw[a] + vv * wu[a] + ww * uv[a]) / (2 * det);
  double shortest = std::numeric_limits<double>::infinity();
  for (const detail::Vec3& e : frame.edges) shortest = std::min(shortest, detail::dot(e, e));
  return std::sqrt(detail::dot(centre, centre)) / std::sqrt(shortest);
}

namespace {

using Index = std::uint32_t;
using Tet = std::array<Index, 4>;
using Domain = detail::ClosedBox<3>;
using Recorder = detail::DefectRecorder<TetMeshReport, TetMeshDefect>;

std::string describe_tetrahedron(const TetMesh& mesh, std::size_t t) {
  const Tet& tet = mesh.tetrahedra[t];
  std::string s = "tetrahedron " + std::to_string(t) + " [" + std::to_string(tet[0]) + " " + std::to_string(tet[1]) +
                  " " + std::to_string(tet[2]) + " " + std::to_string(tet[3]) + "]";
  for (Index i : tet)
    if (i < mesh.num_vertices()) {
      s += ' ';  // appended apart: " " + string trips GCC 12's -Wrestrict false positive (bug 105651)
      s += to_string(mesh.vertices[i]);
    }
  return s;
}

std::string describe_vertex(const TetMesh& mesh, Index i) {
  return "vertex " + std::to_string(i) + " " + to_string(mesh.vertices[i]);
}

// ---- the oriented faces ---------------------------------------------------------------------
//
// The faces of a positively oriented a, b, c, d, each ordered so that the remaining corner
// lies on its positive side (orient3d(face, corner) > 0): the normal points inside, and the
// tetrahedron across a shared face sees it in the opposite orientation.
constexpr std::array<std::array<std::size_t, 3>, 4> kFaces{{{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}}};

// A face as its sorted vertex triple and its orientation: rotated to start at its smallest
// vertex, it is (low, x, y); `flipped` says x > y. A matched interior face has one of each.
struct Face {
  std::array<Index, 3> vertices;  // sorted
  bool flipped;
  Index tet;

  friend auto operator<=>(const Face&, const Face&) = default;
  bool same_triangle(const Face& other) const noexcept { return vertices == other.vertices; }
};

Face oriented_face(Index a, Index b, Index c, Index tet) noexcept {
  // Rotate (an even permutation, the orientation stays) so that the smallest comes first.
  if (b < a && b < c) return oriented_face(b, c, a, tet);
  if (c < a && c < b) return oriented_face(c, a, b, tet);
  return Face{{a, std::min(b, c), std::max(b, c)}, b > c, tet};
}

std::string describe_face(const TetMesh& mesh, const Face& f) {
  const auto& [a, low, high] = f.vertices;
  const Index b = f.flipped ? high : low, c = f.flipped ? low : high;  // back to its orientation
  return "face [" + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "] " +
         to_string(mesh.vertices[a]) + " " + to_string(mesh.vertices[b]) + " " + to_string(mesh.vertices[c]);
}

}  // namespace

TetMeshReport check_tet_mesh(const TetMesh& mesh, const Box<3>& box, std::span<const Point<3>> inputs,
                             const TetMeshCheckOptions& options) {
  TetMeshReport report;
  Recorder record(report, options.max_problems);
  const Domain domain(box);
  const std::size_t nv = mesh.num_vertices(), nt = mesh.num_tetrahedra();
  const auto& vs = mesh.vertices;

  // Canonical vertex order. Lookups below need a sorted list; a broken mesh gets a copy.
  const bool vertices_sorted = detail::check_vertex_order<TetMeshDefect>(vs, &xyz_less, "(x, y, z)", record);
  const detail::PointLookup<3, decltype(&xyz_less)> lookup(vs, vertices_sorted, &xyz_less);
  detail::check_box<TetMeshDefect>(vs, domain, lookup, record,
                                   [&](std::size_t i) { return describe_vertex(mesh, static_cast<Index>(i)); });

  // Per tetrahedron: indices, canonical rotation and order, orientation, volume, dihedral
  // angles. Volumes are in units of 2^(3k) with 2^k <= L < 2^(k+1) (exact scaling), so that
  // neither the box's nor a tetrahedron's overflows or underflows in a box of extreme size.
  const int side_exponent = std::isfinite(box.side) && box.side > 0 ? std::ilogb(box.side) : 0;
  auto scaled = [&](double length) { return std::ldexp(length, -side_exponent); };
  std::vector<char> well_formed(nt, 0), used(nv, 0);
  detail::CompensatedSum volume;  // six times the volume
  double min_angle = std::numeric_limits<double>::infinity(), max_angle = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    const Tet& tet = mesh.tetrahedra[t];
    if (t > 0 && tet < mesh.tetrahedra[t - 1])
      record.add(TetMeshDefect::Canonical, [&] { return describe_tetrahedron(mesh, t) + " is out of order"; });
    const bool in_range = std::all_of(tet.begin(), tet.end(), [&](Index i) { return i < nv; });
    const bool distinct = tet[0] != tet[1] && tet[0] != tet[2] && tet[0] != tet[3] && tet[1] != tet[2] &&
                          tet[1] != tet[3] && tet[2] != tet[3];
    if (!in_range || !distinct) {
      record.add(TetMeshDefect::BadIndex,
                 [&] { return describe_tetrahedron(mesh, t) + " names a missing vertex or one twice"; });
      continue;
    }
    well_formed[t] = 1;
    for (Index i : tet) used[i] = 1;
    if (detail::canonical_rotation(tet, std::less<>{}) != tet)
      record.add(TetMeshDefect::Canonical,
                 [&] { return describe_tetrahedron(mesh, t) + " is not in the canonical rotation"; });
    const Tetrahedron corners = mesh.tetrahedron(t);
    const auto& [a, b, c, d] = corners.v;
    const int sign = orient3d(a, b, c, d);
    if (sign <= 0)
      record.add(TetMeshDefect::Orientation, [&] {
        return describe_tetrahedron(mesh, t) +
               (sign < 0 ? " is negatively oriented" : " is degenerate (coplanar corners)");
      });
    detail::Vec3 edge[3];
    for (std::size_t k = 0; k < 3; ++k)
      for (std::size_t axis = 0; axis < 3; ++axis) edge[k][axis] = scaled(corners.v[k + 1][axis] - a[axis]);
    volume.add(detail::det3(edge[0], edge[1], edge[2]));

    const std::array<double, 6> angles = dihedral_angles_deg(corners);
    const double lo = *std::min_element(angles.begin(), angles.end());
    const double hi = *std::max_element(angles.begin(), angles.end());
    min_angle = std::min(min_angle, lo);
    max_angle = std::max(max_angle, hi);
    if (lo < options.min_dihedral_deg)
      record.add(TetMeshDefect::SmallDihedral, [&] {
        return describe_tetrahedron(mesh, t) + " has a dihedral angle of " + format_exact(lo) + " degrees, below " +
               format_exact(options.min_dihedral_deg);
      });
    if (hi > options.max_dihedral_deg)
      record.add(TetMeshDefect::LargeDihedral, [&] {
        return describe_tetrahedron(mesh, t) + " has a dihedral angle of " + format_exact(hi) + " degrees, above " +
               format_exact(options.max_dihedral_deg);
      });
  }
  if (std::isfinite(min_angle)) {
    report.min_dihedral_deg = min_angle;
    report.max_dihedral_deg = max_angle;
  }

  const double box_volume = scaled(domain.hi[0] - domain.lo[0]) * scaled(domain.hi[1] - domain.lo[1]) *
                            scaled(domain.hi[2] - domain.lo[2]);
  const double mesh_volume = volume.value() / 6;
  if (!(std::abs(mesh_volume - box_volume) <= 1e-9 * box_volume))
    record.add(TetMeshDefect::Volume, [&] {
      const std::string unit = side_exponent == 0 ? "" : " (in units of 2^" + std::to_string(3 * side_exponent) + ")";
      return "the tetrahedra's volume " + format_exact(mesh_volume) + " differs from the box's " +
             format_exact(box_volume) + unit;
    });

  for (Index i = 0; i < nv; ++i)
    if (!used[i])
      record.add(TetMeshDefect::IsolatedVertex,
                 [&] { return describe_vertex(mesh, i) + " belongs to no tetrahedron"; });

  // Faces: sorted by vertex triple, then orientation, then tetrahedron, so that each triangle
  // is one run holding its uses in either orientation.
  std::vector<Face> faces;
  faces.reserve(4 * nt);
  for (std::size_t t = 0; t < nt; ++t) {
    if (!well_formed[t]) continue;
    const Tet& tet = mesh.tetrahedra[t];
    for (const auto& [i, j, k] : kFaces) faces.push_back(oriented_face(tet[i], tet[j], tet[k], static_cast<Index>(t)));
  }
  std::sort(faces.begin(), faces.end());
  for (std::size_t begin = 0, end = 0; begin < faces.size(); begin = end) {
    end = begin + 1;
    while (end < faces.size() && faces[end].same_triangle(faces[begin])) ++end;
    std::size_t uses[2] = {0, 0};
    for (std::size_t f = begin; f < end; ++f) {
      const Face& face = faces[f];
      if (uses[face.flipped]++ != 0)
        record.add(TetMeshDefect::FaceTwice, [&] {
          return describe_face(mesh, face) + " is used by tetrahedra " + std::to_string(faces[f - 1].tet) + " and " +
                 std::to_string(face.tet);
        });
    }
    if (uses[0] != 0 && uses[1] != 0) continue;
    const Face& lone = faces[begin];
    const auto& [a, b, c] = lone.vertices;
    if (!domain.on_one_side(std::array{vs[a], vs[b], vs[c]}))
      record.add(TetMeshDefect::OpenFace, [&] {
        return describe_face(mesh, lone) + " of tetrahedron " + std::to_string(lone.tet) +
               " has no neighbour and is not on the box boundary";
      });
  }

  detail::check_inputs<TetMeshDefect>(inputs, lookup, record);
  return report;
}

void require_valid_tet_mesh(const TetMesh& mesh, const Box<3>& box, std::span<const Point<3>> inputs,
                            const TetMeshCheckOptions& options) {
  const TetMeshReport report = check_tet_mesh(mesh, box, inputs, options);
  if (!report.ok()) throw InvariantError(report.summary());
}

}  // namespace dynmesh
