// Pool chunk acquisition and release (the cold path).
#include "sac/detail/pool.hpp"

#include "sac/chunk_cache.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <system_error>
#include <thread>
#include <utility>
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

/// Gives a chunk no longer wanted to the cache, or back to the system beyond its bound.
void give_or_unmap(void* base, std::size_t size) noexcept {
  if (!ChunkCache::instance().give(base, size)) ::munmap(base, size);
}

// The next huge chunk, faulted in ahead on a worker thread (sac/chunk_cache.hpp says why).
// One chunk at a time: a pool that takes a chunk asks for the next one, and the worker maps
// it and writes a byte of every page, so the kernel's zeroing of those pages runs beside
// the computation instead of inside its first writes. A pool that asks before the chunk is
// ready maps its own, as without the worker, and the ready one serves the next ask of its
// size. Only the thread that made it uses the worker: in a forked child (no worker thread)
// every call does nothing.
class Prefaulter {
 public:
  static Prefaulter& instance() {
    static Prefaulter* p = new Prefaulter;  // never destroyed, as the cache
    return *p;
  }

  /// The ready chunk if it has `size` bytes (else it goes to the cache), or null.
  void* take(std::size_t size) {
    if (!mine()) return nullptr;
    void* stale = nullptr;
    std::size_t stale_size = 0;
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (!ready_) return nullptr;
      if (ready_size_ == size) {
        ++served_;
        return std::exchange(ready_, nullptr);
      }
      stale = std::exchange(ready_, nullptr), stale_size = ready_size_;
    }
    give_or_unmap(stale, stale_size);
    return nullptr;
  }

  /// Asks for a chunk of `size` bytes, unless one is asked for, being made or ready.
  void request(std::size_t size) {
    if (!enabled_.load(std::memory_order_relaxed) || !mine()) return;
    std::lock_guard<std::mutex> lock(mu_);
    if (want_ || busy_ || ready_) return;
    if (!started_) {
      try {
        std::thread([this] { run(); }).detach();
      } catch (const std::system_error&) {
        return;  // no thread: chunks are faulted in by their first writes, as before
      }
      started_ = true;
    }
    want_ = size;
    wake_.notify_one();
  }

  /// Cancels what is asked for or being made, and gives the ready chunk to the cache (or
  /// back to the system): a dead engine's memory goes where the cache's bound says.
  void drop() noexcept {
    if (!mine()) return;
    void* stale = nullptr;
    std::size_t stale_size = 0;
    {
      std::unique_lock<std::mutex> lock(mu_);
      want_ = 0;
      gen_.fetch_add(1, std::memory_order_relaxed);
      idle_.wait(lock, [&] { return !busy_; });
      stale = std::exchange(ready_, nullptr), stale_size = ready_size_;
    }
    if (stale) give_or_unmap(stale, stale_size);
  }

  void set_enabled(bool on) noexcept {
    enabled_.store(on, std::memory_order_relaxed);
    if (!on) drop();
  }
  bool enabled() const noexcept { return enabled_.load(std::memory_order_relaxed); }
  std::size_t ready_bytes() {
    if (!mine()) return 0;
    std::lock_guard<std::mutex> lock(mu_);
    return ready_ ? ready_size_ : 0;
  }
  std::size_t served() {
    std::lock_guard<std::mutex> lock(mu_);
    return served_;
  }
  void wait_idle() {
    if (!mine()) return;
    std::unique_lock<std::mutex> lock(mu_);
    idle_.wait(lock, [&] { return !busy_ && !want_; });
  }

 private:
  Prefaulter() : pid_(::getpid()) {
    const char* e = std::getenv("SAC_PREFAULT");
    enabled_.store(!(e && std::strcmp(e, "0") == 0), std::memory_order_relaxed);
  }
  bool mine() const noexcept { return ::getpid() == pid_; }

  void run() {
    for (;;) {
      std::unique_lock<std::mutex> lock(mu_);
      wake_.wait(lock, [&] { return want_ != 0; });
      const std::size_t size = std::exchange(want_, 0);
      const std::uint64_t gen = gen_.load(std::memory_order_relaxed);
      busy_ = true;
      lock.unlock();
      void* c = nullptr;
      try {
        c = map_huge(size);
      } catch (const std::bad_alloc&) {
      }
      bool whole = c != nullptr;
      for (std::size_t off = 0; c && off < size; off += kPage) {
        if (gen_.load(std::memory_order_relaxed) != gen) {  // dropped: stop at once
          whole = false;
          break;
        }
        static_cast<volatile char*>(c)[off] = 0;
      }
      lock.lock();
      if (whole && gen == gen_.load(std::memory_order_relaxed)) {
        ready_ = c, ready_size_ = size;
        c = nullptr;
      }
      lock.unlock();
      if (c) ::munmap(c, size);
      lock.lock();
      busy_ = false;
      lock.unlock();
      idle_.notify_all();
    }
  }

  static constexpr std::size_t kPage = 4096;
  const pid_t pid_;
  std::atomic<bool> enabled_{true};
  std::atomic<std::uint64_t> gen_{0};
  std::mutex mu_;
  std::condition_variable wake_, idle_;
  std::size_t want_ = 0;  // asked for, not yet begun
  bool busy_ = false;     // the worker is making one
  bool started_ = false;
  void* ready_ = nullptr;
  std::size_t ready_size_ = 0;
  std::size_t served_ = 0;
};

}  // namespace

void Pool::new_chunk() {
  const std::size_t size = next_chunk_;
  void* c = nullptr;
  if (size >= kHugeChunk) {
    c = Prefaulter::instance().take(size);
    if (!c) c = ChunkCache::instance().take(size);
    if (!c) c = map_huge(size);
  } else {
    c = std::malloc(size);
  }
  if (!c) throw std::bad_alloc();
  chunks_.push_back(Chunk{c, size});
  reserved_ += size;
  cur_ = static_cast<char*>(c);
  end_ = cur_ + size;
  if (next_chunk_ < kMaxChunk) next_chunk_ *= 2;
  // Only chunks of the largest size are asked for: they hold all of a large trace but its
  // first 32 MiB, and with one size only, a chunk held ahead always fits the next ask.
  if (next_chunk_ == kMaxChunk) Prefaulter::instance().request(next_chunk_);
}

void* Pool::acquire_huge_chunk() {
  if (void* c = ChunkCache::instance().take(kHugeChunk)) return c;
  return map_huge(kHugeChunk);
}

void Pool::release_huge_chunk(void* p) noexcept {
  if (!ChunkCache::instance().give(p, kHugeChunk)) ::munmap(p, kHugeChunk);
}

void Pool::release() noexcept {
  if (next_chunk_ == kMaxChunk) Prefaulter::instance().drop();
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
void trim_chunk_cache() noexcept {
  detail::Prefaulter::instance().drop();
  detail::ChunkCache::instance().trim();
}
void set_chunk_prefault(bool on) noexcept { detail::Prefaulter::instance().set_enabled(on); }
bool chunk_prefault() noexcept { return detail::Prefaulter::instance().enabled(); }
std::size_t chunk_prefault_bytes() noexcept { return detail::Prefaulter::instance().ready_bytes(); }
std::size_t chunk_prefaults_served() noexcept { return detail::Prefaulter::instance().served(); }
void wait_chunk_prefault() noexcept { detail::Prefaulter::instance().wait_idle(); }

}  // namespace sac
