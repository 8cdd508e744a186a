// app_support.hpp (private to sac_apps) — what the App adapters of the classic apps share.
//
// Purpose: input generation from a seed, and ListApp, the mutator side of every list app
// (input list, modification history for clone_current(), the heap-allocated linked-list copy
// of the input that the conventional twins walk).
// Invariants (ListApp): the engine, the input list and the outputs live and die together
// (State); replaying initial_ and replaced_ reproduces the cells and ids of the input.
// Complexity: generate/clone O(n + number of modifications); remove/reinsert/modify as
// InputList.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include <sac/sac.hpp>

#include "sacapps/app.hpp"
#include "sacapps/heap_list.hpp"
#include "sacapps/list.hpp"

namespace sacapps::support {

/// The benchmark's element values: uniform in [0, 2^31), a function of (seed, k).
inline std::int64_t draw_value(std::uint64_t seed, std::uint64_t k) {
  return static_cast<std::int64_t>(sac::mix64(sac::hash_combine(seed, k)) >> 33);
}

/// The mutator side shared by the list apps; Out is the type of the output modifiable.
template <class Out>
class ListApp : public App {
 public:
  using Value = std::int64_t;

  void generate(std::size_t n, std::uint64_t seed) override {
    initial_.resize(n);
    for (std::size_t k = 0; k < n; ++k) initial_[k] = draw_value(seed, k);
    replaced_.clear();
    s_ = std::make_unique<State>(initial_);
    plain_dirty_ = true;
    stale_.clear();
  }

  std::unique_ptr<App> clone_current() const override {
    std::unique_ptr<ListApp> c = make_empty();
    c->initial_ = initial_;
    c->replaced_ = replaced_;
    c->s_ = std::make_unique<State>(initial_);
    // Replaying the replacements in order hands out the same fresh ids.
    for (const auto& [i, v] : replaced_) c->s_->input.replace(i, v);
    for (std::size_t i = positions(); i-- > 0;)  // back to front: O(1) each
      if (!present(i)) c->s_->input.remove(i);
    return c;
  }

  std::size_t positions() const override { return state().input.capacity(); }
  bool present(std::size_t i) const override { return state().input.present(i); }

  void remove(std::size_t i) override {
    state().input.remove(i);
    plain_dirty_ = true;
  }
  void reinsert(std::size_t i) override {
    state().input.reinsert(i);
    plain_dirty_ = true;
  }
  void modify(std::size_t i, std::uint64_t seed) override {
    const Value v = draw_value(seed, i);
    state().input.replace(i, v);
    replaced_.emplace_back(i, v);
    plain_dirty_ = true;
  }

  sac::Engine& engine() override { return state().rt; }

 protected:
  struct State {
    sac::Engine rt;
    InputList<Value> input;
    Out out;  // written by the computation
    explicit State(const std::vector<Value>& values) : input(rt, values) {}
  };

  /// A new, empty app of the same kind (for clone_current).
  virtual std::unique_ptr<ListApp> make_empty() const = 0;

  State& state() {
    if (!s_) throw std::logic_error("sacapps: generate() first");
    return *s_;
  }
  const State& state() const {
    if (!s_) throw std::logic_error("sacapps: generate() first");
    return *s_;
  }

  /// Runs the self-adjusting program from scratch: body(Engine&, State&).
  template <class F>
  void run_from_scratch(F body) {
    State& s = state();
    s.rt.run([&](sac::Engine& rt) { body(rt, s); });
  }

  /// The current input as a plain linked list (rebuilt after changes, outside timing when
  /// the caller follows the suite's protocol: generate, then run_conventional).
  const heap::Cell<Value>* plain_input() {
    if (plain_dirty_) {
      plain_ = heap::List<Value>(state().input.values());
      plain_dirty_ = false;
    }
    return plain_.head();
  }

  /// Keeps a conventional result; the previous one is freed later, outside the timed run.
  void keep_conventional(heap::List<Value> result) {
    stale_.push_back(std::move(conventional_));
    conventional_ = std::move(result);
  }
  void drop_stale() { stale_.clear(); }
  void release_conventional() override {
    stale_.clear();
    conventional_ = {};
  }

  std::unique_ptr<State> s_;

 private:
  std::vector<Value> initial_;
  std::vector<std::pair<std::size_t, Value>> replaced_;  // (position, value), in order
  heap::List<Value> plain_;
  bool plain_dirty_ = true;
  heap::List<Value> conventional_;
  std::vector<heap::List<Value>> stale_;
};

}  // namespace sacapps::support
