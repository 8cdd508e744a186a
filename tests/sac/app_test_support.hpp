// app_test_support.hpp — helpers shared by the differential tests of the classic apps.
#pragma once

#include "../sanitized.hpp"
#include <cstddef>
#include <random>

#include <gtest/gtest.h>

#include "sacapps/app.hpp"

namespace app_test {

/// Built with AddressSanitizer (CI runs it at -O0): tests scale their sizes down.
using test_support::kSanitized;
/// Built with SAC_DEBUG_CHECKS (every propagate() checks the whole trace): loops of many
/// updates on a large trace scale down further.
using test_support::kDebugChecks;

/// After a propagate: the output is right, the engine is sound, and the live trace equals a
/// from-scratch run's on the current input.
inline void expect_consistent(sacapps::App& app) {
  EXPECT_TRUE(app.verify());
  EXPECT_NO_THROW(app.engine().check_invariants());
  auto fresh = app.clone_current();
  fresh->run_self_adjusting();
  EXPECT_TRUE(fresh->verify());
  EXPECT_EQ(app.engine().live_events(), fresh->engine().live_events());
  EXPECT_EQ(app.engine().record_bytes(), fresh->engine().record_bytes());
}

/// A random position in the wanted state (present or absent), or positions() if none is.
inline std::size_t pick(const sacapps::App& app, bool want_present, std::mt19937_64& rng) {
  const std::size_t n = app.positions();
  if (n == 0) return 0;
  const std::size_t start = rng() % n;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = (start + k) % n;
    if (app.present(i) == want_present) return i;
  }
  return n;
}

}  // namespace app_test
