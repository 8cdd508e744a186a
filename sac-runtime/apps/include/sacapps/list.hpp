// sacapps/list.hpp — modifiable lists, the input and output type of the classic apps.
//
// Purpose: a list is a Mod<Cell*> (null = empty); each cell holds an immutable value, a
// stable id and the modifiable tail. Inputs are owned by the mutator (InputList); outputs are
// allocated by the computation with keyed allocation. Ids, not addresses, feed every
// pseudo-random choice, so traces never depend on pointer values.
// Invariants (InputList): the linked cells are exactly the present ones, in index order.
// Complexity: remove/reinsert O(1 + distance to the nearest present predecessor).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <sac/sac.hpp>

namespace sacapps {

template <class T>
struct Cell {
  T value;
  std::uint64_t id;
  sac::Mod<Cell*> next;
  Cell(T v, std::uint64_t i) : value(v), id(i) {}
};

template <class T>
using List = sac::Mod<Cell<T>*>;

/// Reads the newest contents of a list (mutator side).
template <class T>
std::vector<T> to_vector(const List<T>& head) {
  std::vector<T> out;
  for (Cell<T>* c = head.get(); c; c = c->next.get()) out.push_back(c->value);
  return out;
}

/// A mutator-owned input list over values[0..n), with element-wise remove and reinsert.
template <class T>
class InputList {
 public:
  InputList(sac::Engine& rt, const std::vector<T>& values) : rt_(&rt) {
    cells_.reserve(values.size());
    for (std::size_t i = 0; i < values.size(); ++i)
      cells_.push_back(std::make_unique<Cell<T>>(values[i], i));
    present_.assign(values.size(), true);
    rt_->set(head_, cells_.empty() ? nullptr : cells_[0].get());
    for (std::size_t i = 0; i < cells_.size(); ++i)
      rt_->set(cells_[i]->next, i + 1 < cells_.size() ? cells_[i + 1].get() : nullptr);
  }

  List<T>& head() { return head_; }
  const List<T>& head() const { return head_; }
  std::size_t capacity() const { return cells_.size(); }
  bool present(std::size_t i) const { return present_[i]; }
  const T& value(std::size_t i) const { return cells_[i]->value; }

  /// Unlinks element i (must be present). A mutator change: call propagate() afterwards.
  void remove(std::size_t i) {
    Cell<T>* c = cells_.at(i).get();
    rt_->set(link_before(i), c->next.get());
    present_[i] = false;
  }

  /// Links element i (must be absent) back at its original position.
  void reinsert(std::size_t i) {
    Cell<T>* c = cells_.at(i).get();
    sac::Mod<Cell<T>*>& before = link_before(i);
    rt_->set(c->next, before.get());
    rt_->set(before, c);
    present_[i] = true;
  }

  /// Replaces the value of element i (present) by linking in a fresh cell with a fresh id.
  void replace(std::size_t i, T v) {
    Cell<T>* old = cells_.at(i).get();
    auto fresh = std::make_unique<Cell<T>>(v, next_id_++);
    rt_->set(fresh->next, old->next.get());
    rt_->set(link_before(i), fresh.get());
    retired_.push_back(std::move(cells_[i]));
    cells_[i] = std::move(fresh);
  }

  /// The current sequence of values.
  std::vector<T> values() const { return to_vector(head_); }

 private:
  sac::Mod<Cell<T>*>& link_before(std::size_t i) {
    for (std::size_t j = i; j-- > 0;)
      if (present_[j]) return cells_[j]->next;
    return head_;
  }

  sac::Engine* rt_;
  List<T> head_;
  std::vector<std::unique_ptr<Cell<T>>> cells_;
  std::vector<std::unique_ptr<Cell<T>>> retired_;  // still referenced by the old trace
  std::vector<bool> present_;
  std::uint64_t next_id_ = std::uint64_t{1} << 40;
};

}  // namespace sacapps
