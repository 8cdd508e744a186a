// sac/detail/stamp_queue.hpp — the change-propagation priority queue.
//
// Purpose: affected reads wait here until change propagation re-executes them in time order.
// A binary min-heap of T* ordered by the OrderList position of Traits::stamp(t); each element
// stores its heap index (Traits::pos(t), Traits::set_pos(t, i)) so that undone reads leave the queue in O(log n).
// An element may carry an Aux value while queued (the engine: the modifiable the read reads,
// which the read record itself does not keep); Aux = std::nullptr_t costs nothing.
// Relabelling the order list never changes relative order, so the heap stays valid.
//
// Invariants (check_invariants()): heap order under OrderList::less; Traits::pos(heap_[i]) == i
// for every i; elements not in the queue have pos == kNotQueued.
// Complexity: push, pop, remove O(log n) comparisons; top O(1).
// Paper: the priority-queue propagation of Acar, "Self-Adjusting Computation" (thesis, 2005),
// ch. 6; docs/DESIGN.md, "Change propagation".
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sac/detail/order_list.hpp"
#include "sac/errors.hpp"

namespace sac::detail {

inline constexpr std::uint32_t kNotQueued = 0xffffffffu;

template <class T, class Traits, class Aux = std::nullptr_t>
class StampQueue {
 public:
  explicit StampQueue(const OrderList& order) : order_(&order) {}

  bool empty() const { return heap_.empty(); }
  std::size_t size() const { return heap_.size(); }
  T* top() const { return heap_.front().t; }
  bool contains(const T* t) const { return Traits::pos(t) != kNotQueued; }

  void push(T* t, Aux aux = Aux{}) {
    Traits::set_pos(t, static_cast<std::uint32_t>(heap_.size()));
    heap_.push_back(Entry{t, aux});
    sift_up(heap_.size() - 1);
  }

  /// Removes and returns the earliest element; its Aux goes to *aux when given.
  T* pop(Aux* aux = nullptr) {
    const Entry e = heap_.front();
    remove_at(0);
    if (aux) *aux = e.aux;
    return e.t;
  }

  void remove(T* t) { remove_at(Traits::pos(t)); }
  /// The Aux of t, which is queued.
  Aux& aux(const T* t) { return heap_[Traits::pos(t)].aux; }

  std::size_t memory_bytes() const { return heap_.capacity() * sizeof(Entry); }

  void check_invariants() const {
    for (std::size_t i = 0; i < heap_.size(); ++i) {
      if (Traits::pos(heap_[i].t) != i)
        throw InvariantError("StampQueue: stored index mismatch at " + std::to_string(i));
      if (!Traits::stamp(heap_[i].t)->linked())
        throw InvariantError("StampQueue: element with an unlinked stamp");
      if (i > 0 && before(heap_[i].t, heap_[(i - 1) / 2].t))
        throw InvariantError("StampQueue: heap order broken at " + std::to_string(i));
    }
  }

 private:
  struct Entry {
    T* t;
    [[no_unique_address]] Aux aux;
  };

  bool before(const T* a, const T* b) const { return order_->less(Traits::stamp(a), Traits::stamp(b)); }

  void remove_at(std::size_t i) {
    const Entry gone = heap_[i];
    const Entry last = heap_.back();
    heap_.pop_back();
    Traits::set_pos(gone.t, kNotQueued);
    if (gone.t == last.t) return;
    heap_[i] = last;
    Traits::set_pos(last.t, static_cast<std::uint32_t>(i));
    if (i > 0 && before(last.t, heap_[(i - 1) / 2].t)) sift_up(i);
    else sift_down(i);
  }

  void sift_up(std::size_t i) {
    const Entry e = heap_[i];
    while (i > 0) {
      std::size_t p = (i - 1) / 2;
      if (!before(e.t, heap_[p].t)) break;
      heap_[i] = heap_[p];
      Traits::set_pos(heap_[i].t, static_cast<std::uint32_t>(i));
      i = p;
    }
    heap_[i] = e;
    Traits::set_pos(e.t, static_cast<std::uint32_t>(i));
  }

  void sift_down(std::size_t i) {
    const Entry e = heap_[i];
    const std::size_t n = heap_.size();
    for (;;) {
      std::size_t c = 2 * i + 1;
      if (c >= n) break;
      if (c + 1 < n && before(heap_[c + 1].t, heap_[c].t)) ++c;
      if (!before(heap_[c].t, e.t)) break;
      heap_[i] = heap_[c];
      Traits::set_pos(heap_[i].t, static_cast<std::uint32_t>(i));
      i = c;
    }
    heap_[i] = e;
    Traits::set_pos(e.t, static_cast<std::uint32_t>(i));
  }

  const OrderList* order_;
  std::vector<Entry> heap_;
};

}  // namespace sac::detail
