// sac/read_slots.hpp — the modifiables of a multi-read, as its own closure sees them.
//
// Purpose: a body of Engine::read_many may take, after its values, a ReadSlots<T>: slot i's
// modifiable, read from the multi-read's record rather than copied into the closure. A
// closure that must know which modifiable each value came from (to name a cell, say) keeps
// this 8-byte view instead of k pointers of its own; the view stays valid for as long as
// the read lives, so a nested read_many can look through it at an outer read's modifiables.
// Invariants: operator[](i) is the modifiable slot i reads now; follow() (Engine::read_many)
// moves a slot to another modifiable, and the view shows the new one from then on. Only
// i < k, the number of the read's modifiables, is valid.
// Complexity: O(1) a slot.
// Paper: docs/DESIGN.md, "Modifiables, reads and versions".
#pragma once

#include <cstddef>

#include "sac/detail/trace_nodes.hpp"
#include "sac/mod.hpp"

namespace sac {

template <class T>
class ReadSlots {
 public:
  ReadSlots() = default;
  explicit ReadSlots(const detail::ReadSlot* slots) noexcept : s_(slots) {}
  const Mod<T>& operator[](std::size_t i) const noexcept { return *static_cast<const Mod<T>*>(s_[i].mod); }
  explicit operator bool() const noexcept { return s_ != nullptr; }

 private:
  const detail::ReadSlot* s_ = nullptr;
};

}  // namespace sac
