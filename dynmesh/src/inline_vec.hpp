// inline_vec.hpp (private) — a short vector of trivially copyable values that keeps its
// first N elements inline and moves to the heap only beyond them.
//
// Purpose: the self-adjusting star walk (sa_delaunay.hpp, read_star) carries the triangles
// seen so far in every read's closure, and each step copies its closure; with std::vector
// each copy was a heap allocation (about a fifth of an hpu update's time went to malloc and
// free). A vertex has six triangles on average, so the inline part almost always suffices;
// a high-degree vertex (a box corner early on, a point of a cocircular grid) spills.
// Invariants: size() ≤ N ⇔ the elements are inline (heap_ empty); otherwise they are all in
// heap_. Equality compares the elements.
// Complexity: push_back O(1) amortized; copy O(size) with no allocation while size ≤ N.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <span>
#include <type_traits>
#include <vector>

namespace dynmesh::detail {

template <class T, std::size_t N>
class InlineVec {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  const T* data() const noexcept { return size_ <= N ? inline_.data() : heap_.data(); }
  T* data() noexcept { return size_ <= N ? inline_.data() : heap_.data(); }
  const T& operator[](std::size_t i) const noexcept { return data()[i]; }
  const T& back() const noexcept { return data()[size_ - 1]; }
  std::span<const T> span() const noexcept { return {data(), size_}; }

  void push_back(const T& x) {
    if (size_ < N) {
      inline_[size_++] = x;
      return;
    }
    if (size_ == N) heap_.assign(inline_.begin(), inline_.end());
    heap_.push_back(x);
    ++size_;
  }
  void pop_back() noexcept {
    if (size_ > N) heap_.pop_back();
    if (--size_ == N) {
      std::copy(heap_.begin(), heap_.end(), inline_.begin());
      heap_.clear();
    }
  }

  friend bool operator==(const InlineVec& a, const InlineVec& b) noexcept {
    return a.size_ == b.size_ && std::equal(a.data(), a.data() + a.size_, b.data());
  }

 private:
  std::size_t size_ = 0;
  std::array<T, N> inline_{};
  std::vector<T> heap_;
};

}  // namespace dynmesh::detail
