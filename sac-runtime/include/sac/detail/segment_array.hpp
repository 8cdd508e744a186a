// sac/detail/segment_array.hpp — append-only scratch array in huge-page segments.
//
// Purpose: a buffer filled once and read back once (the keyed allocations of a run(), indexed
// at its end) without a vector's doublings: its elements live in 2 MiB huge-page segments
// from the pool's process-wide chunk cache, so a warm run does not fault in fresh pages.
// Invariants: element i is at segments[i / kPerSegment][i % kPerSegment]; segments.size() ==
// ceil(size() / kPerSegment); clear() returns every segment. T is trivially copyable and
// destructible: the segments are raw memory and no destructor runs on their elements.
// Complexity: push_back O(1) (one chunk acquisition per kPerSegment elements), operator[]
// O(1), clear O(segments).
// Paper: docs/DESIGN.md, "Memoization and keyed allocation".
#pragma once

#include <cstddef>
#include <new>
#include <type_traits>
#include <vector>

#include "sac/detail/pool.hpp"

namespace sac::detail {

template <class T>
class SegmentArray {
 public:
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  static constexpr std::size_t kPerSegment = Pool::kHugeChunk / sizeof(T);

  SegmentArray() = default;
  SegmentArray(const SegmentArray&) = delete;
  SegmentArray& operator=(const SegmentArray&) = delete;
  ~SegmentArray() { clear(); }

  void push_back(const T& x) {
    const std::size_t i = size_ % kPerSegment;
    if (i == 0) segments_.push_back(static_cast<T*>(Pool::acquire_huge_chunk()));
    ::new (static_cast<void*>(segments_.back() + i)) T(x);
    ++size_;
  }
  const T& operator[](std::size_t i) const { return segments_[i / kPerSegment][i % kPerSegment]; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }

  /// Returns every segment to the chunk cache.
  void clear() noexcept {
    for (T* seg : segments_) Pool::release_huge_chunk(seg);
    segments_.clear();
    size_ = 0;
  }

  /// Bytes of the segment directory; the segments themselves are scratch, held only while
  /// the array is filled.
  std::size_t directory_bytes() const { return segments_.capacity() * sizeof(T*); }

 private:
  std::vector<T*> segments_;
  std::size_t size_ = 0;
};

}  // namespace sac::detail
