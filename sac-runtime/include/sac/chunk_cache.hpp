// sac/chunk_cache.hpp — where the memory of a destroyed Engine goes.
//
// Purpose: an Engine carves its trace from large chunks (sac/detail/pool.hpp). When it dies,
// its chunks of 2 MiB and more go to a process-wide cache, so that the next engine of a
// benchmark or of a test loop finds them already faulted in; the rest go back to the
// system. A user meshing once should get the memory back, so the cache is small by default:
// 64 MiB, or SAC_CHUNK_CACHE_MB (read once, at first use); a program that builds engines in
// a loop may opt in to more.
//
// Prefaulting: the kernel zeroes a page at its first write, and on a virtual machine that
// first touch is slow (about 2.4 ms per MiB here, a sixth of a large from-scratch run). So
// while an engine fills one huge chunk, a worker thread (one per process, started at the
// first ask) maps the next and writes a byte of every page, and the engine finds it ready.
// At most one chunk (32 MiB) is held ahead; a dying engine cancels it and gives it to the
// cache. It is on by default; SAC_PREFAULT=0 (read once) or set_chunk_prefault(false) turns
// it off. It changes no result, only where the zeroing runs.
// Invariants: chunk_cache_bytes() ≤ chunk_cache_limit() at every return of these functions;
// chunk_prefault_bytes() ≤ 32 MiB.
// Complexity: O(cached chunks) per call; thread-safe.
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
/// Returns every cached chunk to the system (the bound stays), the prefaulted one included.
void trim_chunk_cache() noexcept;

/// Turns prefaulting on or off (off also gives back the chunk held ahead).
void set_chunk_prefault(bool on) noexcept;
bool chunk_prefault() noexcept;
/// Bytes of the chunk faulted in ahead and not yet taken (0 or one chunk).
std::size_t chunk_prefault_bytes() noexcept;
/// How many chunks engines took from the worker so far.
std::size_t chunk_prefaults_served() noexcept;
/// Waits until the worker has finished what it was asked for (for tests and benchmarks).
void wait_chunk_prefault() noexcept;

}  // namespace sac
