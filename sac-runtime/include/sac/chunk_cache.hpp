// sac/chunk_cache.hpp — where the memory of a destroyed Engine goes.
//
// Purpose: an Engine carves its trace from large chunks (sac/detail/pool.hpp). When it dies,
// its chunks of 2 MiB and more go to a process-wide cache, so that the next engine of a
// benchmark or of a test loop finds them already faulted in; the rest go back to the
// system. A user meshing once should get the memory back, so the cache is small by default:
// 64 MiB, or SAC_CHUNK_CACHE_MB (read once, at first use); a program that builds engines in
// a loop may opt in to more.
// Invariants: chunk_cache_bytes() ≤ chunk_cache_limit() at every return of these functions.
// Complexity: O(cached chunks) per call; thread-safe.
// Paper: docs/DESIGN.md, "The runtime".
#pragma once

#include <cstddef>

namespace sac {

/// The cache's default bound.
inline constexpr std::size_t kDefaultChunkCacheBytes = std::size_t{64} << 20;

/// Sets the bound; chunks held beyond it go back to the system at once.
void set_chunk_cache_limit(std::size_t bytes);
std::size_t chunk_cache_limit() noexcept;
/// Bytes of freed chunks held now.
std::size_t chunk_cache_bytes() noexcept;
/// Returns every cached chunk to the system (the bound stays).
void trim_chunk_cache() noexcept;

}  // namespace sac
