// sac/detail/pool.hpp — size-class pool allocator for trace nodes, closures and versions.
//
// Purpose: the hot paths (reads, writes, allocations) must not call the general-purpose heap
// once per event. Blocks are carved from chunks that grow geometrically from 64 KiB to
// 32 MiB; chunks of 2 MiB and more are mapped 2 MiB-aligned and advised as transparent huge
// pages (first touch of a large trace then faults once per huge page, not per small one),
// one free list per 8-byte size class.
// Invariants: live_bytes() == sum of sizes of blocks handed out and not yet returned;
//             a block is returned with the same size it was requested with.
// Complexity: allocate/deallocate O(1); chunks are released only when the pool dies.
// Blocks larger than kMaxSmall bytes go to ::operator new. Every block lies below 2^48
// (records keep numbers in their links' top 16 bits): memory above it is refused with
// std::bad_alloc.
// Paper: docs/DESIGN.md, "The runtime".
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <vector>

namespace sac::detail {

class Pool {
 public:
  static constexpr std::size_t kGrain = 8;
  static constexpr std::size_t kMaxSmall = 512;
  static constexpr std::size_t kFirstChunk = 64 * 1024;
  static constexpr std::size_t kHugeChunk = 2 * 1024 * 1024;
  static constexpr std::size_t kMaxChunk = 32 * 1024 * 1024;

  Pool() = default;
  Pool(const Pool&) = delete;
  Pool& operator=(const Pool&) = delete;
  ~Pool() { release(); }

  void* allocate(std::size_t n) {
    n = round(n);
    void* p;
    if (n > kMaxSmall) {
      p = allocate_large(n);
    } else if (Free*& head = free_[n / kGrain]) {
      p = head;
      head = head->next;
    } else {
      p = carve(n);
    }
    live_bytes_ += n;  // after: a block that could not be had is not counted
    return p;
  }

  void deallocate(void* p, std::size_t n) noexcept {
    n = round(n);
    live_bytes_ -= n;
    if (n > kMaxSmall) {
      ::operator delete(p);
      return;
    }
    Free* b = static_cast<Free*>(p);
    b->next = free_[n / kGrain];
    free_[n / kGrain] = b;
  }

  /// A 2 MiB-aligned huge-page chunk of kHugeChunk bytes for scratch buffers, from the
  /// process-wide cache of freed chunks when one is there (then already faulted in).
  static void* acquire_huge_chunk();
  static void release_huge_chunk(void* p) noexcept;

  std::size_t live_bytes() const { return live_bytes_; }
  std::size_t reserved_bytes() const { return reserved_; }

 private:
  struct Free {
    Free* next;
  };
  static constexpr std::size_t round(std::size_t n) {
    return n < kGrain ? kGrain : (n + kGrain - 1) & ~(kGrain - 1);
  }
  void* carve(std::size_t n) {
    if (static_cast<std::size_t>(end_ - cur_) < n) new_chunk();  // the old tail is abandoned
    void* p = cur_;
    cur_ += n;
    return p;
  }
  void new_chunk();           // pool.cpp
  void* allocate_large(std::size_t n);  // pool.cpp
  void release() noexcept;    // pool.cpp

  Free* free_[kMaxSmall / kGrain + 1] = {};
  struct Chunk {
    void* base;
    std::size_t size;
  };
  std::vector<Chunk> chunks_;
  std::size_t next_chunk_ = kFirstChunk;
  std::size_t reserved_ = 0;
  char* cur_ = nullptr;
  char* end_ = nullptr;
  std::size_t live_bytes_ = 0;
};

}  // namespace sac::detail
