// sac/detail/stamp_queue.hpp — the change-propagation priority queue.
//
// Purpose: affected reads wait here until change propagation re-executes them in time order.
// A binary min-heap of T* ordered by the OrderList position of Traits::stamp(t); each element
// stores its heap index (Traits::pos(t)) so that undone reads leave the queue in O(log n).
// Relabelling the order list never changes relative order, so the heap stays valid.
//
// Invariants (check_invariants()): heap order under OrderList::less; Traits::pos(heap_[i]) == i
// for every i; elements not in the queue have pos == kNotQueued.
// Complexity: push, pop, remove O(log n) comparisons; top O(1).
// Follows the priority-queue propagation of Acar, "Self-Adjusting Computation" (2005), ch. 6.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sac/detail/order_list.hpp"
#include "sac/errors.hpp"

namespace sac {

inline constexpr std::uint32_t kNotQueued = 0xffffffffu;

template <class T, class Traits>
class StampQueue {
 public:
  explicit StampQueue(const OrderList& order) : order_(&order) {}

  bool empty() const { return heap_.empty(); }
  std::size_t size() const { return heap_.size(); }
  T* top() const { return heap_.front(); }
  bool contains(const T* t) const { return Traits::pos(t) != kNotQueued; }

  void push(T* t) {
    Traits::pos(t) = static_cast<std::uint32_t>(heap_.size());
    heap_.push_back(t);
    sift_up(heap_.size() - 1);
  }

  T* pop() {
    T* t = heap_.front();
    remove_at(0);
    return t;
  }

  void remove(T* t) { remove_at(Traits::pos(t)); }

  std::size_t memory_bytes() const { return heap_.capacity() * sizeof(T*); }

  void check_invariants() const {
    for (std::size_t i = 0; i < heap_.size(); ++i) {
      if (Traits::pos(heap_[i]) != i)
        throw InvariantError("StampQueue: stored index mismatch at " + std::to_string(i));
      if (!Traits::stamp(heap_[i])->linked())
        throw InvariantError("StampQueue: element with an unlinked stamp");
      if (i > 0 && before(heap_[i], heap_[(i - 1) / 2]))
        throw InvariantError("StampQueue: heap order broken at " + std::to_string(i));
    }
  }

 private:
  bool before(const T* a, const T* b) const { return order_->less(Traits::stamp(a), Traits::stamp(b)); }

  void remove_at(std::size_t i) {
    T* gone = heap_[i];
    T* last = heap_.back();
    heap_.pop_back();
    Traits::pos(gone) = kNotQueued;
    if (gone == last) return;
    heap_[i] = last;
    Traits::pos(last) = static_cast<std::uint32_t>(i);
    if (i > 0 && before(last, heap_[(i - 1) / 2])) sift_up(i);
    else sift_down(i);
  }

  void sift_up(std::size_t i) {
    T* t = heap_[i];
    while (i > 0) {
      std::size_t p = (i - 1) / 2;
      if (!before(t, heap_[p])) break;
      heap_[i] = heap_[p];
      Traits::pos(heap_[i]) = static_cast<std::uint32_t>(i);
      i = p;
    }
    heap_[i] = t;
    Traits::pos(t) = static_cast<std::uint32_t>(i);
  }

  void sift_down(std::size_t i) {
    T* t = heap_[i];
    const std::size_t n = heap_.size();
    for (;;) {
      std::size_t c = 2 * i + 1;
      if (c >= n) break;
      if (c + 1 < n && before(heap_[c + 1], heap_[c])) ++c;
      if (!before(heap_[c], t)) break;
      heap_[i] = heap_[c];
      Traits::pos(heap_[i]) = static_cast<std::uint32_t>(i);
      i = c;
    }
    heap_[i] = t;
    Traits::pos(t) = static_cast<std::uint32_t>(i);
  }

  const OrderList* order_;
  std::vector<T*> heap_;
};

}  // namespace sac
