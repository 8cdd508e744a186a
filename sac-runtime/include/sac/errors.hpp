// sac/errors.hpp — the exceptions the runtime throws.
//
// Purpose: every misuse of the runtime is reported with a clear exception rather than
// undefined behaviour.
//   UsageError     – the call is not allowed in the current state (reading a modifiable that
//                    was never written, propagate() from inside the computation, ...).
//   PoisonedError  – a body threw earlier; the engine refuses further work (destroying it is
//                    still safe and leak-free).
//   InvariantError – a check_invariants() found a broken invariant (a runtime bug or a
//                    documented misuse such as mutating a non-modifiable field).
// Invariants: none (value types). Complexity: n/a.
// Paper: docs/DESIGN.md, "The correctness contract".
#pragma once

#include <stdexcept>
#include <string>

namespace sac {

class UsageError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

class PoisonedError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class InvariantError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

}  // namespace sac
