// sacapps/app.hpp — the uniform face of the classic self-adjusting apps.
//
// Purpose: the suite driver (bench/sac_suite) and the differential tests treat every app the
// same way: generate an input, run the conventional twin and the self-adjusting version,
// change the input element by element, propagate, verify. Each app also has its own typed
// API in its own header (sacapps/<app>.hpp); this interface is the adapter.
// Invariants: after run_self_adjusting() and after every propagate(), verify() is true.
// Complexity: see each app's header.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <sac/sac.hpp>

namespace sacapps {

class App {
 public:
  virtual ~App() = default;
  virtual std::string_view name() const = 0;

  /// Builds a fresh engine and the input of n elements from seed (not timed).
  virtual void generate(std::size_t n, std::uint64_t seed) = 0;
  /// A new App with a fresh engine whose input equals this one's current input (not run).
  virtual std::unique_ptr<App> clone_current() const = 0;

  /// The conventional (plain C++) computation on the current input; timed by the suite.
  virtual void run_conventional() = 0;
  /// Frees the conventional result kept by run_conventional() (untimed), so that the next
  /// run allocates from memory the allocator already holds, as a self-adjusting run starts
  /// on chunks a previous engine freed (sac/chunk_cache.hpp). Without it the first app of a
  /// process pays the kernel's first touch of fresh heap pages and the next ones do not.
  virtual void release_conventional() {}
  /// The self-adjusting computation from scratch (Engine::run); timed by the suite.
  virtual void run_self_adjusting() = 0;

  /// Number of input positions (elements of the generated input, present or not).
  virtual std::size_t positions() const = 0;
  virtual bool present(std::size_t i) const = 0;
  /// Mutator changes; the caller propagates. remove needs i present, reinsert i absent.
  virtual void remove(std::size_t i) = 0;
  virtual void reinsert(std::size_t i) = 0;
  /// Replaces element i (present) by a new element drawn from seed.
  virtual void modify(std::size_t i, std::uint64_t seed) = 0;

  /// True iff the self-adjusting output equals the conventional result on the current
  /// input (computed afresh, untimed).
  virtual bool verify() = 0;

  virtual sac::Engine& engine() = 0;
};

std::unique_ptr<App> make_map();
std::unique_ptr<App> make_filter();
std::unique_ptr<App> make_reverse();
std::unique_ptr<App> make_minimum();
std::unique_ptr<App> make_sum();
std::unique_ptr<App> make_exptrees();
std::unique_ptr<App> make_quicksort();
std::unique_ptr<App> make_mergesort();
std::unique_ptr<App> make_quickhull();
std::unique_ptr<App> make_diameter();

/// All app names, in the suite's order.
const std::vector<std::string>& app_names();
/// nullptr for an unknown name.
std::unique_ptr<App> make_app(std::string_view name);

}  // namespace sacapps
