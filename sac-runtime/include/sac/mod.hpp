// sac/mod.hpp — modifiables: the only memory whose changes propagate.
//
// Purpose: a Mod<T> is a versioned, multi-write cell. Each write inside the computation adds
// a version at the writer's timestamp; a read sees the latest version before its own time.
// The mutator gives a modifiable its base value with Engine::set() (a version that precedes
// all computation time). A Mod is 8 bytes and may live anywhere: in mutator-owned structures
// (inputs) or in objects allocated by the computation (Engine::alloc).
// Invariants: versions are kept newest first, strictly decreasing in time; a base version,
// if any, is last. Only the engine that wrote a Mod may touch it.
// Complexity: get() O(1); reads and writes at time t are O(number of versions after t).
// Follows Acar, Ahmed, Blume, "Imperative self-adjusting computation" (POPL'08).
#pragma once

#include "sac/detail/trace_nodes.hpp"
#include "sac/errors.hpp"

namespace sac {

class ModBase {
 public:
  ModBase() = default;
  ModBase(const ModBase&) = delete;
  ModBase& operator=(const ModBase&) = delete;

  /// True once the mutator or the computation has written it.
  bool written() const { return newest_ != nullptr; }

 protected:
  friend class Engine;
  detail::VersionBase* newest_ = nullptr;
};

template <class T>
class Mod : public ModBase {
 public:
  using value_type = T;

  /// The newest value: the output after run()/propagate(). For the mutator only — inside
  /// the computation, read() it so the dependency is recorded.
  const T& get() const {
    if (!newest_) throw UsageError("sac::Mod::get: the modifiable was never written");
    return static_cast<const detail::Version<T>*>(newest_)->value;
  }
};

}  // namespace sac
