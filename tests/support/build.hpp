// What kind of build the tests run in, and the decorators that leave the heaviest physics
// checks to the Release build.
#pragma once

#include <doctest/doctest.h>

namespace test {

/// True in the sanitizer builds (RADIOSITY_SANITIZE, RADIOSITY_SANITIZE_THREAD). They are for
/// memory errors, undefined behaviour and data races, and run everything three to fifteen times
/// slower; some physics checks run their code paths there at a reduced size (each says what it
/// leaves to the Release build, which runs them in full), to keep the README's test command
/// within CI's time.
inline constexpr bool kSanitizerBuild = RADIOSITY_TEST_SANITIZER_BUILD != 0;
/// True in the ThreadSanitizer build only.
inline constexpr bool kThreadSanitizerBuild = RADIOSITY_TEST_THREAD_SANITIZER_BUILD != 0;

/// `TEST_CASE("..." * test::release_only)`: a physics check (many rays, a path-traced reference,
/// a converged solve at high reflectance) that only the Release build runs. Every code path it
/// takes is run in the sanitizer builds by lighter tests of its module; the sanitizers would
/// only repeat them with more samples, at ten times the cost. A skipped case is not listed, so
/// ctest does not register it in those builds.
inline const doctest::skip release_only{kSanitizerBuild};
/// `TEST_CASE("..." * test::not_under_thread_sanitizer)`: a check in a module the
/// ThreadSanitizer build covers whose parallel loops other tests there run too (serial meshing,
/// the estimators' closed-form accuracy); the Release and AddressSanitizer builds run it.
inline const doctest::skip not_under_thread_sanitizer{kThreadSanitizerBuild};

}  // namespace test
