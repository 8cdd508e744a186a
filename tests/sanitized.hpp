// tests/sanitized.hpp — whether the test binary is built with AddressSanitizer, and whether
// the libraries run their checkers after every update (SAC_DEBUG_CHECKS).
//
// Purpose: suites scale their sizes down under ASan (CI runs it at -O0), so the sanitizer
// pass stays within CI's time budget while still exercising every path; loops of many
// updates on a large trace scale down further under SAC_DEBUG_CHECKS, whose checks are
// O(trace) per update.
// Invariants: kSanitized and kDebugChecks are compile-time constants; tests/CMakeLists.txt
// defines SAC_DEBUG_CHECKS for the test binaries exactly when it builds the libraries so.
// Complexity: none. Paper: none.
#pragma once

namespace test_support {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
#else
inline constexpr bool kSanitized = false;
#endif

#ifdef SAC_DEBUG_CHECKS
inline constexpr bool kDebugChecks = true;
#else
inline constexpr bool kDebugChecks = false;
#endif

}  // namespace test_support
