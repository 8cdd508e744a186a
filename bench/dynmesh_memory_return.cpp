// dynmesh_memory_return — how much memory a destroyed engine gives back.
//
// Builds a 2D DynamicQuadtree of python_uniform(n, 1) in the unit box, destroys it, and
// prints the trace bytes, the resident set (/proc/self/statm) before, built and after, and
// what the chunk cache holds (sac/chunk_cache.hpp). --cache-mb sets the cache's bound
// (default: the library's, 64 MiB, or SAC_CHUNK_CACHE_MB). One tree per process, so the
// figures are not blurred by earlier engines.
#include <cstddef>
#include <cstdio>
#include <memory>

#include <CLI/CLI.hpp>
#include <sac/chunk_cache.hpp>

#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_quadtree.hpp"

namespace {

double rss_mib() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  unsigned long size = 0, resident = 0;
  if (std::fscanf(f, "%lu %lu", &size, &resident) != 2) resident = 0;
  std::fclose(f);
  return static_cast<double>(resident) * 4096.0 / 1048576.0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynmesh_memory_return: resident memory before and after destroying a quadtree"};
  std::size_t n = 100000;
  long cache_mb = -1;
  app.add_option("--n", n, "points (python_uniform(n, 1))");
  app.add_option("--cache-mb", cache_mb, "the chunk cache's bound in MiB (default: the library's)");
  CLI11_PARSE(app, argc, argv);
  if (cache_mb >= 0) sac::set_chunk_cache_limit(static_cast<std::size_t>(cache_mb) << 20);

  const auto pts = dynmesh::python_uniform(n, 1);
  const dynmesh::Box<2> box{{0, 0}, 1};
  const double before = rss_mib();
  auto tree = std::make_unique<dynmesh::DynamicQuadtree<2>>(box, pts);
  const double built = rss_mib();
  const double trace = static_cast<double>(tree->trace_bytes()) / 1048576.0;
  tree.reset();
  const double after = rss_mib();
  std::printf("n %zu  cache bound %zu MiB  trace %.0f MiB  RSS MiB: before %.0f, built %.0f, destroyed %.0f  cache holds %.0f MiB\n",
              n, sac::chunk_cache_limit() >> 20, trace, before, built, after,
              static_cast<double>(sac::chunk_cache_bytes()) / 1048576.0);
}
