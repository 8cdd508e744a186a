// The canonical mesh and the change feed's application (see dynmesh/mesh.hpp).
#include "dynmesh/mesh.hpp"

#include <algorithm>
#include <cstddef>

namespace dynmesh {
namespace {

bool xy_equal(const Point<2>& a, const Point<2>& b) noexcept { return !xy_less(a, b) && !xy_less(b, a); }

// The index of p in the sorted, distinct `vertices` (p is known to be there).
std::uint32_t index_of(const std::vector<Point<2>>& vertices, const Point<2>& p) noexcept {
  const auto it = std::lower_bound(vertices.begin(), vertices.end(), p, xy_less);
  return static_cast<std::uint32_t>(it - vertices.begin());
}

// Rotates a counter-clockwise index triple to start at its smallest index: a rotation keeps
// the orientation, a reflection would not.
std::array<std::uint32_t, 3> rotate_to_smallest(std::uint32_t a, std::uint32_t b, std::uint32_t c) noexcept {
  if (b < a && b <= c) return {b, c, a};
  if (c < a && c < b) return {c, a, b};
  return {a, b, c};
}

}  // namespace

Mesh make_mesh(std::span<const Triangle> triangles) {
  Mesh mesh;
  mesh.vertices.reserve(triangles.size() * 3);
  for (const Triangle& t : triangles) mesh.vertices.insert(mesh.vertices.end(), t.v.begin(), t.v.end());
  std::sort(mesh.vertices.begin(), mesh.vertices.end(), xy_less);
  mesh.vertices.erase(std::unique(mesh.vertices.begin(), mesh.vertices.end(), xy_equal), mesh.vertices.end());
  mesh.vertices.shrink_to_fit();

  mesh.triangles.reserve(triangles.size());
  for (const Triangle& t : triangles)
    mesh.triangles.push_back(rotate_to_smallest(index_of(mesh.vertices, t.v[0]), index_of(mesh.vertices, t.v[1]),
                                                index_of(mesh.vertices, t.v[2])));
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
