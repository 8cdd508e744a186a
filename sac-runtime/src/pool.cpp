// pool.cpp — the pool's chunk acquisition and release (the cold path).
//
// Purpose: get and give back the chunks sac/detail/pool.hpp carves blocks from, through the
// chunk cache (sac/chunk_cache.hpp).
// Invariants: those of sac/detail/pool.hpp; a chunk is either in use by one pool or cached.
// Complexity: O(1) per chunk, plus the system's mapping calls.
// Paper: docs/DESIGN.md, "The runtime".
#include "sac/detail/pool.hpp"

#include "sac/chunk_cache.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <vector>

namespace sac::detail {

namespace {

// Freed huge chunks are kept for later pools (as malloc keeps freed heap), up to a bound,
// so that engines created one after another do not pay the kernel's first-touch zeroing
// again (sac/chunk_cache.hpp).
class ChunkCache {
 public:
  static ChunkCache& instance() {
    static ChunkCache* c = new ChunkCache;  // never destroyed: pools may die during exit
    return *c;
  }
  void* take(std::size_t size) {
    std::lock_guard<std::mutex> lock(mu_);
    for (std::size_t i = 0; i < free_.size(); ++i)
      if (free_[i].size == size) {
        void* p = free_[i].base;
        free_[i] = free_.back();
        free_.pop_back();
        held_ -= size;
        return p;
      }
    return nullptr;
  }
  bool give(void* base, std::size_t size) {
    std::lock_guard<std::mutex> lock(mu_);
    if (held_ + size > limit_) return false;
    free_.push_back({base, size});
    held_ += size;
    return true;
  }
  /// Sets the bound and unmaps what lies beyond it, largest chunks first.
  void limit(std::size_t bytes) {
    std::lock_guard<std::mutex> lock(mu_);
    limit_ = bytes;
    std::sort(free_.begin(), free_.end(), [](const Entry& a, const Entry& b) { return a.size < b.size; });
    while (held_ > limit_) {
      ::munmap(free_.back().base, free_.back().size);
      held_ -= free_.back().size;
      free_.pop_back();
    }
  }
  std::size_t limit() {
    std::lock_guard<std::mutex> lock(mu_);
    return limit_;
  }
  std::size_t held() {
    std::lock_guard<std::mutex> lock(mu_);
    return held_;
  }
  void trim() noexcept {
    std::lock_guard<std::mutex> lock(mu_);
    for (const Entry& e : free_) ::munmap(e.base, e.size);
    free_.clear();
    held_ = 0;
  }

 private:
  ChunkCache() {
    std::size_t bytes = kDefaultChunkCacheBytes;
    if (const char* e = std::getenv("SAC_CHUNK_CACHE_MB")) bytes = std::strtoull(e, nullptr, 10) << 20;
    limit_ = bytes;
  }
  struct Entry {
    void* base;
    std::size_t size;
  };
  std::mutex mu_;
  std::vector<Entry> free_;
  std::size_t held_ = 0;
  std::size_t limit_ = 0;
};

// Records keep numbers in their links' top 16 bits (sac/detail/trace_nodes.hpp): every
// address they link must fit in 48 bits, as user space does on x86-64 and AArch64 Linux.
bool below_2_48(const void* p, std::size_t n) {
  return reinterpret_cast<std::uintptr_t>(p) + n <= (std::uintptr_t{1} << 48);
}

void* map_huge(std::size_t size) {
  // Over-map by one huge page and trim, so that the chunk is 2 MiB-aligned.
  const std::size_t align = Pool::kHugeChunk;
  void* raw = ::mmap(nullptr, size + align, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS,
                     -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const auto r = reinterpret_cast<std::uintptr_t>(raw);
  const std::uintptr_t a = (r + align - 1) & ~(align - 1);
  if (a > r) ::munmap(raw, a - r);
  if (const std::uintptr_t tail = r + size + align - (a + size)) ::munmap(reinterpret_cast<void*>(a + size), tail);
#ifdef MADV_HUGEPAGE
  ::madvise(reinterpret_cast<void*>(a), size, MADV_HUGEPAGE);  // advisory
#endif
  return reinterpret_cast<void*>(a);
}

}  // namespace

void Pool::new_chunk() {
  const std::size_t size = next_chunk_;
  void* c = nullptr;
  if (size >= kHugeChunk) {
    c = ChunkCache::instance().take(size);
    if (!c) c = map_huge(size);
  } else {
    c = std::malloc(size);
  }
  if (!c) throw std::bad_alloc();
  if (!below_2_48(c, size)) {
    if (size >= kHugeChunk) ::munmap(c, size);
    else std::free(c);
    throw std::bad_alloc();
  }
  chunks_.push_back(Chunk{c, size});
  reserved_ += size;
  cur_ = static_cast<char*>(c);
  end_ = cur_ + size;
  if (next_chunk_ < kMaxChunk) next_chunk_ *= 2;
}

void* Pool::allocate_large(std::size_t n) {
  void* p = ::operator new(n);
  if (!below_2_48(p, n)) {
    ::operator delete(p);
    throw std::bad_alloc();
  }
  return p;
}

void* Pool::acquire_huge_chunk() {
  if (void* c = ChunkCache::instance().take(kHugeChunk)) return c;
  return map_huge(kHugeChunk);
}

void Pool::release_huge_chunk(void* p) noexcept {
  if (!ChunkCache::instance().give(p, kHugeChunk)) ::munmap(p, kHugeChunk);
}

void Pool::release() noexcept {
  for (const Chunk& c : chunks_) {
    if (c.size >= kHugeChunk) {
      if (!ChunkCache::instance().give(c.base, c.size)) ::munmap(c.base, c.size);
    }
    else std::free(c.base);
  }
  chunks_.clear();
}

}  // namespace sac::detail

namespace sac {

void set_chunk_cache_limit(std::size_t bytes) { detail::ChunkCache::instance().limit(bytes); }
std::size_t chunk_cache_limit() noexcept { return detail::ChunkCache::instance().limit(); }
std::size_t chunk_cache_bytes() noexcept { return detail::ChunkCache::instance().held(); }
void trim_chunk_cache() noexcept { detail::ChunkCache::instance().trim(); }

}  // namespace sac
