// RADIOSITY_ASSERT: internal invariants (what the library's own code guarantees, never what a
// caller or a file can get wrong: those are Errors). On in Debug builds and in the sanitizer
// build (RADIOSITY_ENABLE_ASSERTS, set by RADIOSITY_SANITIZE), compiled out in Release; the
// condition must have no side effects.
#pragma once

#include <cstdio>
#include <cstdlib>

namespace radiosity::detail {

[[noreturn]] inline void assert_failed(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "radiosity: internal invariant failed: %s (%s:%d)\n", condition, file, line);
  std::abort();
}

}  // namespace radiosity::detail

#if defined(RADIOSITY_ENABLE_ASSERTS) || !defined(NDEBUG)
#define RADIOSITY_ASSERT(condition) \
  ((condition) ? static_cast<void>(0) : ::radiosity::detail::assert_failed(#condition, __FILE__, __LINE__))
#else
#define RADIOSITY_ASSERT(condition) static_cast<void>(0)
#endif
