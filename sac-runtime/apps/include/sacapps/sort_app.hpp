// sacapps/sort_app.hpp — what the two sorting apps (quicksort, mergesort) share.
//
// Purpose: the order both sorts produce, the linked lists of their conventional twins, and
// SortApp, the App adapter: input = a list of int64 drawn uniformly from [0, range), output =
// the list sorted by (value, id). Each sort supplies its self-adjusting program and its twin.
// Invariants: sorts_before is a strict total order (ids are distinct), so the sorted list is
// unique: the self-adjusting output and the twin's are equal value for value and id for id,
// whatever the algorithm and however many values are equal.
// Complexity: see quicksort.hpp and mergesort.hpp; the adapter adds O(n) per verify().
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include <sac/sac.hpp>

#include "sacapps/input_list_app.hpp"
#include "sacapps/list.hpp"

namespace sacapps {

/// The sort order: by value, ties by id. For any cells with `value` and `id` (both twins).
template <class A, class B>
bool sorts_before(const A& a, const B& b) {
  return a.value < b.value || (!(b.value < a.value) && a.id < b.id);
}

/// A cell of the conventional twins' lists (cf. Cell<T>, without the modifiable).
template <class T>
struct SortCell {
  T value;
  std::uint64_t id;
  const SortCell* next;
};

/// Bump allocation of SortCells in chunks, all freed with the arena: the conventional twins
/// allocate their output cells as they go, like their self-adjusting versions (and CEAL's
/// conventional versions) do.
template <class T>
class SortArena {
 public:
  SortCell<T>* make(const T& value, std::uint64_t id, const SortCell<T>* next = nullptr) {
    if (used_ == kChunk) {
      chunks_.push_back(std::make_unique<SortCell<T>[]>(kChunk));
      used_ = 0;
    }
    SortCell<T>* c = &chunks_.back()[used_++];
    *c = SortCell<T>{value, id, next};
    return c;
  }

 private:
  static constexpr std::size_t kChunk = 4096;
  std::vector<std::unique_ptr<SortCell<T>[]>> chunks_;
  std::size_t used_ = kChunk;
};

/// The App adapter of a sort of int64 lists.
class SortApp : public InputListApp<std::int64_t> {
 public:
  using Value = std::int64_t;
  static constexpr Value kFullRange = Value{1} << 62;

  /// The sorted output (after run_self_adjusting()).
  const List<Value>& output() const { return *out_; }

  void run_conventional() override {
    SortArena<Value> arena;
    result_ = sort_conventional(plain_input(), arena);
    result_arena_ = std::move(arena);  // frees the previous result's cells (O(n / 4096))
  }

  void run_self_adjusting() override {
    begin_run();
    out_ = std::make_unique<List<Value>>();
    rt_->run([this](sac::Engine& rt) { sort_self_adjusting(rt, input_->head(), out_.get()); });
  }

  bool verify() override {
    if (!ran()) return false;
    run_conventional();
    const SortCell<Value>* c = result_;
    for (const Cell<Value>* o = out_->get(); o; o = o->next.get(), c = c->next)
      if (!c || o->value != c->value || o->id != c->id) return false;
    return c == nullptr;
  }

 protected:
  explicit SortApp(Value range) : range_(range) {}

  /// The self-adjusting sort: writes to *dst the list in sorted by sorts_before.
  virtual void sort_self_adjusting(sac::Engine& rt, const List<Value>& in, List<Value>* dst) = 0;
  /// The conventional twin.
  virtual const SortCell<Value>* sort_conventional(const SortCell<Value>* in,
                                                   SortArena<Value>& arena) = 0;

  Value draw(std::uint64_t seed) const override {
    std::uint64_t state = seed;
    const std::uint64_t r = sac::splitmix64(state);  // the first output of splitmix64(seed)
    return static_cast<Value>(r % static_cast<std::uint64_t>(range_));
  }
  void reset_outputs() override { out_.reset(); }

  Value range_;

 private:
  void input_changed() override { plain_valid_ = false; }

  /// The current input as a plain list, rebuilt after changes (outside the timed run when
  /// the caller follows the suite's protocol: change, verify, then time).
  const SortCell<Value>* plain_input() {
    if (!plain_valid_) {
      plain_arena_ = SortArena<Value>{};
      plain_ = nullptr;
      const SortCell<Value>** tail = &plain_;
      for (const Cell<Value>* c = input_->head().get(); c; c = c->next.get()) {
        SortCell<Value>* o = plain_arena_.make(c->value, c->id);
        *tail = o;
        tail = &o->next;
      }
      plain_valid_ = true;
    }
    return plain_;
  }

  std::unique_ptr<List<Value>> out_;
  SortArena<Value> plain_arena_;
  const SortCell<Value>* plain_ = nullptr;
  bool plain_valid_ = false;
  SortArena<Value> result_arena_;
  const SortCell<Value>* result_ = nullptr;
};

}  // namespace sacapps
