// sacapps/heap_list.hpp — the conventional twins' list: a heap-allocated singly linked list.
//
// Purpose: the baseline the self-adjusting list apps (map, filter, reverse, minimum, sum) are
// measured against. As in CEAL's conventional versions, an algorithm walks a chain of
// individually allocated cells and allocates one cell per output element with the general
// heap; no modifiables, no trace.
// Invariants: a heap::List owns exactly the cells reachable from its head.
// Complexity: building, copying to a vector and destruction are O(length).
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace sacapps::heap {

template <class T>
struct Cell {
  T value;
  Cell* next;
};

/// Owner of a chain of heap::Cell<T>.
template <class T>
class List {
 public:
  List() = default;
  explicit List(const std::vector<T>& values) {
    Cell<T>** tail = &head_;
    for (const T& v : values) {
      *tail = new Cell<T>{v, nullptr};
      tail = &(*tail)->next;
    }
  }
  /// Takes ownership of the chain starting at head.
  static List adopt(Cell<T>* head) {
    List l;
    l.head_ = head;
    return l;
  }
  List(const List&) = delete;
  List& operator=(const List&) = delete;
  List(List&& o) noexcept : head_(std::exchange(o.head_, nullptr)) {}
  List& operator=(List&& o) noexcept {
    if (this != &o) {
      clear();
      head_ = std::exchange(o.head_, nullptr);
    }
    return *this;
  }
  ~List() { clear(); }

  const Cell<T>* head() const { return head_; }

  std::vector<T> to_vector() const {
    std::vector<T> out;
    for (const Cell<T>* c = head_; c; c = c->next) out.push_back(c->value);
    return out;
  }

  void clear() {
    while (head_) delete std::exchange(head_, head_->next);
  }

 private:
  Cell<T>* head_ = nullptr;
};

}  // namespace sacapps::heap
