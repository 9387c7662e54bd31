// Whether this test binary is instrumented by AddressSanitizer, for the
// random sweeps that ask fewer cases of each kind there.
//
// The sanitizer build looks for memory errors and undefined behaviour: each
// kind of case must still run, but the statistics of thousands of random
// cases belong to the release build's long sweeps. Instrumented code (and
// the exact oracles' allocations) run 5 to 25 times slower.
#pragma once

#include <algorithm>

namespace proxima::test {

// gcc defines __SANITIZE_ADDRESS__; clang
// answers __has_feature(address_sanitizer) instead.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kUnderSanitizers = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kUnderSanitizers = true;
#else
inline constexpr bool kUnderSanitizers = false;
#endif
#else
inline constexpr bool kUnderSanitizers = false;
#endif

// n cases in release, n / divisor (at least one) under the sanitizers.
constexpr int sanitized_count(int n, int divisor) {
  return kUnderSanitizers ? std::max(1, n / divisor) : n;
}

}  // namespace proxima::test
