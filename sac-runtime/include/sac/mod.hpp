// sac/mod.hpp — modifiables: the only memory whose changes propagate.
//
// Purpose: a Mod<T> is a versioned, multi-write cell. Each write inside the computation adds
// a version at the writer's timestamp; a read sees the latest version before its own time.
// The mutator gives a modifiable its base value with Engine::set() (a version that precedes
// all computation time), or a default with Engine::init_default() (T{}: while the
// modifiable has no version, the reads that see the default hang on the modifiable itself;
// it becomes a base version only when a version is written too). A Mod is 8 bytes and may
// live anywhere: in mutator-owned structures (inputs) or in objects allocated by the
// computation (Engine::alloc).
// Invariants: versions are kept newest first, strictly decreasing in time; a base version,
// if any, is last; the oldest version's link names the modifiable and says whether it has
// a default; a modifiable has default readers only while it has no version. Only the
// engine that wrote a Mod may touch it.
// Complexity: get() O(1); reads and writes at time t are O(number of versions after t).
// Paper: Acar, Ahmed, Blume, "Imperative self-adjusting computation" (POPL'08);
// docs/DESIGN.md, "Modifiables, reads and versions".
#pragma once

#include <cstdint>
#include <type_traits>

#include "sac/detail/trace_nodes.hpp"
#include "sac/errors.hpp"

namespace sac {

namespace detail {
class TraceChecker;  // src/engine_check.cpp: Engine::check_invariants()'s phases
}  // namespace detail

class ModBase {
 public:
  ModBase() = default;
  ModBase(const ModBase&) = delete;
  ModBase& operator=(const ModBase&) = delete;

  /// True once the mutator or the computation has written it, or it has a default.
  bool written() const { return head_ != 0; }

 protected:
  friend class Engine;
  friend class detail::TraceChecker;
  /// Marks head_ when init_default() gave m a default and no version exists yet; the rest
  /// of head_ is then the first of the reads that see the default (or null).
  static constexpr std::uintptr_t kDefaultOnly = detail::kDefaultOnlyMark;
  /// True when m has a default and no version (the default is a version's flag once one
  /// exists).
  bool default_only() const { return (head_ & kDefaultOnly) != 0; }
  /// The newest version, or null.
  detail::VersionBase* newest() const {
    return default_only() ? nullptr : reinterpret_cast<detail::VersionBase*>(head_);
  }
  /// The reads that see the default while m has no version, linked as a version's readers.
  detail::ReaderLink* default_readers() const {
    return default_only() ? reinterpret_cast<detail::ReaderLink*>(head_ & ~std::uintptr_t{7}) : nullptr;
  }
  void set_newest(detail::VersionBase* v) { head_ = reinterpret_cast<std::uintptr_t>(v); }
  // The newest version; or kDefaultOnly | the first default reader; or 0 (never written).
  std::uintptr_t head_ = 0;
};
static_assert(sizeof(ModBase) == sizeof(std::uintptr_t));

template <class T>
class Mod : public ModBase {
 public:
  using value_type = T;

  /// The newest value: the output after run()/propagate(). For the mutator only — inside
  /// the computation, read() it so the dependency is recorded.
  const T& get() const {
    if constexpr (std::is_default_constructible_v<T>) {
      static const T kDefault{};
      if (default_only()) return kDefault;
    }
    if (!head_) throw UsageError("sac::Mod::get: the modifiable was never written");
    return static_cast<const detail::Version<T>*>(newest())->value;
  }
};

}  // namespace sac
