// sorted_change.hpp (private) — applying a change feed (removed, added) to a sorted list of
// simplices: shared by the triangle and the tetrahedron meshes (mesh.cpp, tet_mesh.cpp).
// Complexity: O((r + a) log t + t) for t simplices, r removed and a added.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace dynmesh::detail {

/// Returns false (and leaves `tris` unspecified) when a removed simplex is absent or an added
/// one is already present or repeated. `tris` is sorted; the change's groups are sorted by
/// contract (sorted copies keep a careless caller correct).
template <class T, class Change>
bool apply_sorted_change(std::vector<T>& tris, const Change& change) {
  // Both groups are sorted by contract; sorted copies keep a careless caller correct.
  const bool sorted = std::is_sorted(change.removed.begin(), change.removed.end()) &&
                      std::is_sorted(change.added.begin(), change.added.end());
  if (!sorted) {
    Change copy = change;
    std::sort(copy.removed.begin(), copy.removed.end());
    std::sort(copy.added.begin(), copy.added.end());
    return apply_sorted_change(tris, copy);
  }

  // Removal first: every removed triangle must be present, each once. The positions found
  // increase with the (sorted) removed list, so each search starts past the previous one.
  std::vector<std::size_t> gone;
  gone.reserve(change.removed.size());
  auto from = tris.begin();
  for (const T& t : change.removed) {
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

}  // namespace dynmesh::detail
