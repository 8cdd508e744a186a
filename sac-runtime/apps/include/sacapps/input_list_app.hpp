// sacapps/input_list_app.hpp — the App adapter shared by the apps whose input is one InputList.
//
// Purpose: quicksort, mergesort, quickhull and diameter differ only in what they compute;
// owning the engine and the input, the element-wise changes and clone_current() are the same
// for all of them and live here. A subclass supplies the element generator (draw) and the
// three computations (run_conventional, run_self_adjusting, verify).
// Invariants: the engine is replaced together with the input and the outputs (whose
// modifiables hold its versions) and is destroyed after them; the modification log replays,
// in order, every replace() done since generate(), so a clone's cells carry the same ids as
// this app's (InputList hands out replacement ids from a counter) and id-driven coin flips
// agree between a live run and a from-scratch run.
// Complexity: generate O(n); remove/reinsert as InputList; clone_current
// O(n + modifications).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <sac/sac.hpp>

#include "sacapps/app.hpp"
#include "sacapps/list.hpp"

namespace sacapps {

/// (value, id) of a list, in list order: what the apps compare, ids included.
template <class T>
struct Tagged {
  T value;
  std::uint64_t id;
  friend bool operator==(const Tagged&, const Tagged&) = default;
};

/// Reads the newest contents of a list with the ids (mutator side).
template <class T>
std::vector<Tagged<T>> to_tagged(const List<T>& head) {
  std::vector<Tagged<T>> out;
  for (const Cell<T>* c = head.get(); c; c = c->next.get()) out.push_back({c->value, c->id});
  return out;
}

template <class T>
class InputListApp : public App {
 public:
  void generate(std::size_t n, std::uint64_t seed) override {
    std::vector<T> values;
    values.reserve(n);
    for (std::size_t i = 0; i < n; ++i) values.push_back(draw(sac::hash_combine(seed, i)));
    set_input(std::move(values));
  }

  /// Builds a fresh engine over exactly these values (ids 0..n-1); the tests use it for
  /// hand-made inputs (all equal, collinear, ...).
  void set_input(std::vector<T> values) {
    values_ = std::move(values);
    log_.clear();
    reset_input();
  }

  std::size_t positions() const override { return input().capacity(); }
  bool present(std::size_t i) const override { return input().present(i); }
  void remove(std::size_t i) override {
    require_present(i, true, "remove");
    input_->remove(i);
    input_changed();
  }
  void reinsert(std::size_t i) override {
    require_present(i, false, "reinsert");
    input_->reinsert(i);
    input_changed();
  }
  void modify(std::size_t i, std::uint64_t seed) override {
    require_present(i, true, "modify");
    const T v = draw(seed);
    input_->replace(i, v);
    log_.emplace_back(i, v);
    input_changed();
  }

  sac::Engine& engine() override {
    if (!rt_) throw std::logic_error(std::string(name()) + ": generate() first");
    return *rt_;
  }

  /// The current input sequence with ids (mutator side).
  std::vector<Tagged<T>> current_input() const { return to_tagged(input().head()); }

 protected:
  InputListApp() = default;

  /// A new element drawn from seed (a pure function of seed).
  virtual T draw(std::uint64_t seed) const = 0;
  /// Called after every element change (e.g. to drop a cached conventional input).
  virtual void input_changed() {}
  /// Called when the engine is replaced: outputs written by the old engine must go with it.
  virtual void reset_outputs() = 0;

  /// Makes this app's input a copy of o's current input: same values, ids and presence.
  void copy_input_from(const InputListApp& o) {
    values_ = o.values_;
    log_ = o.log_;
    reset_input();
    for (const auto& [i, v] : log_) input_->replace(i, v);
    for (std::size_t i = values_.size(); i-- > 0;)  // back to front: O(1) each
      if (!o.input_->present(i)) input_->remove(i);
    input_changed();
  }

  /// Run guard: run_self_adjusting() is once per generate()/clone.
  void begin_run() {
    if (ran_) throw std::logic_error(std::string(name()) + ": already run on this input");
    ran_ = true;
  }
  bool ran() const { return ran_; }

  std::unique_ptr<sac::Engine> rt_;  // first: destroyed last
  std::unique_ptr<InputList<T>> input_;

 private:
  void reset_input() {
    reset_outputs();
    input_.reset();
    rt_ = std::make_unique<sac::Engine>();
    input_ = std::make_unique<InputList<T>>(*rt_, values_);
    ran_ = false;
    input_changed();
  }
  const InputList<T>& input() const {
    if (!input_) throw std::logic_error(std::string(name()) + ": generate() first");
    return *input_;
  }
  void require_present(std::size_t i, bool want, const char* what) const {
    if (i >= input().capacity() || input_->present(i) != want)
      throw std::invalid_argument(std::string(name()) + "::" + what + ": bad position");
  }

  std::vector<T> values_;                          // the generated input, by position
  std::vector<std::pair<std::size_t, T>> log_;    // every replace(), in order
  bool ran_ = false;
};

}  // namespace sacapps
