// Tests of sac/chunk_cache.hpp: a destroyed engine's chunks go to the cache only up to its
// bound, lowering the bound or trimming unmaps them, and with the bound at 0 the resident
// set shrinks by the trace when the engine dies.
#include <gtest/gtest.h>

#include <cstddef>
#include <algorithm>
#include <cstdio>
#include <memory>
#include <vector>

#include <unistd.h>

#include "sac/chunk_cache.hpp"
#include "sac/sac.hpp"

namespace {

/// Restores the process-wide bound when a test ends.
class ChunkCache : public ::testing::Test {
 protected:
  void SetUp() override { saved_ = sac::chunk_cache_limit(); }
  void TearDown() override { sac::set_chunk_cache_limit(saved_); }

 private:
  std::size_t saved_ = 0;
};

/// An engine holding a trace of n reads (tens of MiB: several huge chunks).
struct BigTrace {
  explicit BigTrace(std::size_t n) : mods(n), rt(std::make_unique<sac::Engine>()) {
    for (std::size_t i = 0; i < n; ++i) rt->set(mods[i], static_cast<int>(i));
    rt->run([this](sac::Engine& rt2) {
      for (auto& m : mods) rt2.read(m, [](int) {});
    });
  }
  std::vector<sac::Mod<int>> mods;  // declared first: outlives the engine's records
  std::unique_ptr<sac::Engine> rt;
};

constexpr std::size_t kReads = 400'000;

/// Resident bytes (Linux), or 0 when /proc is not there. statm counts pages of the kernel's
/// size (4 KiB on x86-64, 16 or 64 KiB on some arm64 kernels).
std::size_t resident_bytes() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  unsigned long size = 0, resident = 0;
  const int got = std::fscanf(f, "%lu %lu", &size, &resident);
  std::fclose(f);
  const long page = ::sysconf(_SC_PAGESIZE);
  return got == 2 && page > 0 ? resident * static_cast<std::size_t>(page) : 0;
}

TEST_F(ChunkCache, DefaultBoundIsSmall) {
  EXPECT_LE(sac::kDefaultChunkCacheBytes, std::size_t{64} << 20);
}

TEST_F(ChunkCache, HoldsFreedChunksUpToItsBound) {
  sac::set_chunk_cache_limit(std::size_t{1} << 30);
  sac::trim_chunk_cache();
  auto big = std::make_unique<BigTrace>(kReads);
  const std::size_t trace = big->rt->trace_bytes();
  ASSERT_GT(trace, std::size_t{8} << 20);
  big.reset();
  EXPECT_GT(sac::chunk_cache_bytes(), trace / 2);  // most of the trace sat in huge chunks
  EXPECT_LE(sac::chunk_cache_bytes(), sac::chunk_cache_limit());
  sac::set_chunk_cache_limit(std::size_t{4} << 20);  // lowering the bound unmaps the rest
  EXPECT_LE(sac::chunk_cache_bytes(), std::size_t{4} << 20);
  sac::trim_chunk_cache();
  EXPECT_EQ(sac::chunk_cache_bytes(), 0u);
  EXPECT_EQ(sac::chunk_cache_limit(), std::size_t{4} << 20);  // trimming keeps the bound
}

TEST_F(ChunkCache, ABoundOfZeroGivesTheMemoryBack) {
  sac::set_chunk_cache_limit(0);
  BigTrace big(kReads);
  const std::size_t trace = big.rt->trace_bytes();
  const std::size_t before = resident_bytes();
  big.rt.reset();  // the engine alone, so the mods' vector does not blur the figure
  const std::size_t after = resident_bytes();
  EXPECT_EQ(sac::chunk_cache_bytes(), 0u);
  if (before == 0)
    GTEST_SKIP() << "/proc/self/statm cannot be read (no or a restricted /proc): the resident-set drop "
                    "is not checked, only that the cache holds nothing";
  EXPECT_GT(before - std::min(before, after), trace / 2)
      << "resident " << before << " -> " << after << " bytes, trace " << trace;
}

}  // namespace
