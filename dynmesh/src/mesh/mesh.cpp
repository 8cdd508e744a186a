// The canonical mesh and the change feed's application (see dynmesh/mesh.hpp).
#include "dynmesh/mesh.hpp"

#include <algorithm>
#include <cstddef>

namespace dynmesh {
namespace {

// Rotates a counter-clockwise index triple to start at its smallest index: a rotation keeps
// the orientation, a reflection would not.
std::array<std::uint32_t, 3> rotate_to_smallest(std::uint32_t a, std::uint32_t b, std::uint32_t c) noexcept {
  if (b < a && b <= c) return {b, c, a};
  if (c < a && c < b) return {c, a, b};
  return {a, b, c};
}

}  // namespace

Mesh make_mesh(std::span<const Triangle> triangles) {
  // Every corner with its slot (3·triangle + corner), sorted by (x, y): one pass then both
  // numbers the distinct points and tells each slot its vertex, with no searching.
  struct Corner {
    Point<2> p;
    std::size_t slot;
  };
  std::vector<Corner> corners;
  corners.reserve(3 * triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) corners.push_back({triangles[t].v[k], 3 * t + k});
  std::sort(corners.begin(), corners.end(), [](const Corner& l, const Corner& r) { return xy_less(l.p, r.p); });

  Mesh mesh;
  std::vector<std::uint32_t> vertex_of(corners.size());
  for (std::size_t i = 0; i < corners.size(); ++i) {
    if (i == 0 || xy_less(corners[i - 1].p, corners[i].p)) mesh.vertices.push_back(corners[i].p);
    vertex_of[corners[i].slot] = static_cast<std::uint32_t>(mesh.vertices.size() - 1);
  }
  corners = {};

  mesh.triangles.reserve(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    mesh.triangles.push_back(rotate_to_smallest(vertex_of[3 * t], vertex_of[3 * t + 1], vertex_of[3 * t + 2]));
  std::sort(mesh.triangles.begin(), mesh.triangles.end());
  return mesh;
}

std::vector<Triangle> triangles_of(const Mesh& mesh) {
  std::vector<Triangle> out;
  out.reserve(mesh.num_triangles());
  // Index order is (x, y) order, so a canonical index triple gives a canonical Triangle and
  // the sorted triples give sorted Triangles.
  for (std::size_t i = 0; i < mesh.num_triangles(); ++i) out.push_back(mesh.triangle(i));
  return out;
}

bool apply_change(std::vector<Triangle>& tris, const MeshChange& change) {
  // Both groups are sorted by contract; sorted copies keep a careless caller correct.
  const bool sorted = std::is_sorted(change.removed.begin(), change.removed.end()) &&
                      std::is_sorted(change.added.begin(), change.added.end());
  if (!sorted) {
    MeshChange copy = change;
    std::sort(copy.removed.begin(), copy.removed.end());
    std::sort(copy.added.begin(), copy.added.end());
    return apply_change(tris, copy);
  }

  // Removal first: every removed triangle must be present, each once. The positions found
  // increase with the (sorted) removed list, so each search starts past the previous one.
  std::vector<std::size_t> gone;
  gone.reserve(change.removed.size());
  auto from = tris.begin();
  for (const Triangle& t : change.removed) {
    const auto it = std::lower_bound(from, tris.end(), t);
    if (it == tris.end() || *it != t) return false;
    gone.push_back(static_cast<std::size_t>(it - tris.begin()));
    from = it + 1;
  }
  // Compact from the first removed position on: the untouched prefix is not moved.
  if (!gone.empty()) {
    std::size_t write = gone.front(), next_gone = 0;
    for (std::size_t read = gone.front(); read < tris.size(); ++read) {
      if (next_gone < gone.size() && gone[next_gone] == read) {
        ++next_gone;
        continue;
      }
      tris[write++] = tris[read];
    }
    tris.resize(write);
  }

  // Addition: no added triangle may be present after the removal, nor repeated.
  for (std::size_t i = 0; i < change.added.size(); ++i) {
    if (i > 0 && change.added[i] == change.added[i - 1]) return false;
    if (std::binary_search(tris.begin(), tris.end(), change.added[i])) return false;
  }
  // Merge from the back so that only the suffix after the first insertion point moves.
  const std::size_t old_size = tris.size();
  tris.resize(old_size + change.added.size());
  std::size_t read = old_size, add = change.added.size(), write = tris.size();
  while (add > 0) {
    if (read > 0 && change.added[add - 1] < tris[read - 1])
      tris[--write] = tris[--read];
    else
      tris[--write] = change.added[--add];
  }
  return true;
}

}  // namespace dynmesh
