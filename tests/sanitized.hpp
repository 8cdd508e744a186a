// tests/sanitized.hpp — whether the test binary is built with AddressSanitizer.
//
// Purpose: suites scale their sizes down under ASan (CI runs it at -O0), so the sanitizer
// pass stays within CI's time budget while still exercising every path.
// Invariants: kSanitized is a compile-time constant.
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

}  // namespace test_support
