// mpi_gen — inputs for the dynmesh-mpi tests (tests/mpi/mpi_test.sh):
//   mpi_gen DIST DIM N SEED SPREAD POINTS EDITS NEDITS
// writes N points of distribution DIST (distributions.hpp) to POINTS, one "x y [z]" line each
// (%.17g: exact), and NEDITS edits to EDITS: alternately the deletion of a present point and
// the insertion of a new one of the same distribution (another seed), so the spread and the
// shape stay those of DIST. Deterministic in its arguments.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "dynmesh/distributions.hpp"
#include "dynmesh/point.hpp"

namespace {

template <std::size_t d>
void line(std::FILE* f, const char* prefix, const dynmesh::Point<d>& p) {
  std::fputs(prefix, f);
  for (std::size_t a = 0; a < d; ++a) std::fprintf(f, a ? " %s" : "%s", dynmesh::format_exact(p[a]).c_str());
  std::fputc('\n', f);
}

template <std::size_t d>
int run(dynmesh::Distribution dist, std::size_t n, std::uint64_t seed, double spread, const char* points_path,
        const char* edits_path, std::size_t nedits) {
  const std::size_t extra = nedits / 2 + 1;
  // One draw of n + extra points: the first n are the input, the rest are inserted later,
  // so they come from the same construction (and, for shrinking, the same octaves).
  std::vector<dynmesh::Point<d>> all = dynmesh::generate<d>(dist, n + extra, seed, spread);
  std::FILE* f = std::fopen(points_path, "w");
  if (!f) return 1;
  for (std::size_t i = 0; i < n; ++i) line<d>(f, "", all[i]);
  std::fclose(f);
  f = std::fopen(edits_path, "w");
  if (!f) return 1;
  dynmesh::Rng rng(seed + 1);
  std::vector<dynmesh::Point<d>> present(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n));
  std::size_t next = n;
  for (std::size_t k = 0; k < nedits; ++k) {
    if (k % 2 == 0 && !present.empty()) {
      const std::size_t i = static_cast<std::size_t>(rng.below(present.size()));
      line<d>(f, "- ", present[i]);
      present[i] = present.back();
      present.pop_back();
    } else if (next < all.size()) {
      line<d>(f, "+ ", all[next]);
      present.push_back(all[next++]);
    }
  }
  std::fclose(f);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 9) {
    std::fprintf(stderr, "usage: mpi_gen DIST DIM N SEED SPREAD POINTS EDITS NEDITS\n");
    return 2;
  }
  const auto dist = dynmesh::parse_distribution(argv[1]);
  if (!dist) return 2;
  const int dim = std::atoi(argv[2]);
  const std::size_t n = std::strtoull(argv[3], nullptr, 10), nedits = std::strtoull(argv[8], nullptr, 10);
  const std::uint64_t seed = std::strtoull(argv[4], nullptr, 10);
  const double spread = std::strtod(argv[5], nullptr);
  return dim == 3 ? run<3>(*dist, n, seed, spread, argv[6], argv[7], nedits)
                  : run<2>(*dist, n, seed, spread, argv[6], argv[7], nedits);
}
