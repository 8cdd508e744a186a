// inline_vec.hpp (private) — a short vector of trivially copyable values that keeps its
// first N elements inline and moves to the heap only beyond them.
//
// Purpose: the self-adjusting star walk (sa_delaunay.hpp, read_star) carries the triangles
// seen so far in every read's closure, and each step copies its closure; with std::vector
// each copy was a heap allocation (about a fifth of an hpu update's time went to malloc and
// free). A vertex has six triangles on average, so the inline part almost always suffices;
// a high-degree vertex (a box corner early on, a point of a cocircular grid) spills.
// Invariants: size() ≤ N ⇔ the elements are inline (heap_ null); otherwise they are all in
// heap_, which holds cap_ ≥ size(). Equality compares the elements. Layout: 16 + 8·N bytes
// for pointers (two 32-bit counts, the inline part, the heap pointer).
// Complexity: push_back O(1) amortized; copy O(size) with no allocation while size ≤ N.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>

namespace dynmesh::detail {

template <class T, std::size_t N>
class InlineVec {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  InlineVec() = default;
  InlineVec(const InlineVec& o) : size_(o.size_), inline_(o.inline_) {
    if (o.size_ > N) {
      heap_ = new T[o.size_];
      cap_ = o.size_;
      std::copy(o.heap_, o.heap_ + o.size_, heap_);
    }
  }
  InlineVec(InlineVec&& o) noexcept : size_(o.size_), cap_(o.cap_), inline_(o.inline_), heap_(o.heap_) {
    o.size_ = 0;
    o.cap_ = 0;
    o.heap_ = nullptr;
  }
  InlineVec& operator=(InlineVec o) noexcept {
    std::swap(size_, o.size_);
    std::swap(cap_, o.cap_);
    std::swap(inline_, o.inline_);
    std::swap(heap_, o.heap_);
    return *this;
  }
  ~InlineVec() { delete[] heap_; }

  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  const T* data() const noexcept { return size_ <= N ? inline_.data() : heap_; }
  T* data() noexcept { return size_ <= N ? inline_.data() : heap_; }
  const T& operator[](std::size_t i) const noexcept { return data()[i]; }
  const T& back() const noexcept { return data()[size_ - 1]; }
  std::span<const T> span() const noexcept { return {data(), size_}; }

  void push_back(const T& x) {
    if (size_ < N) {
      inline_[size_++] = x;
      return;
    }
    if (size_ == N || size_ == cap_) {  // spill, or grow the heap part
      const std::uint32_t cap = size_ == N ? static_cast<std::uint32_t>(2 * N) : 2 * cap_;
      T* h = new T[cap];
      std::copy(data(), data() + size_, h);
      delete[] heap_;
      heap_ = h;
      cap_ = cap;
    }
    heap_[size_++] = x;
  }
  void pop_back() noexcept {
    if (--size_ == N) {  // back inline
      std::copy(heap_, heap_ + N, inline_.begin());
      delete[] heap_;
      heap_ = nullptr;
      cap_ = 0;
    }
  }

  friend bool operator==(const InlineVec& a, const InlineVec& b) noexcept {
    return a.size_ == b.size_ && std::equal(a.data(), a.data() + a.size_, b.data());
  }

 private:
  // 32-bit counts and a bare pointer (not a std::vector): the vector rides in every star
  // step's closure, so its own size is trace memory.
  std::uint32_t size_ = 0;
  std::uint32_t cap_ = 0;  // of heap_
  std::array<T, N> inline_{};
  T* heap_ = nullptr;      // all the elements while size_ > N
};

}  // namespace dynmesh::detail
