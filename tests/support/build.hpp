// What kind of build the tests run in.
#pragma once

namespace test {

/// True in the sanitizer builds (RADIOSITY_SANITIZE, RADIOSITY_SANITIZE_THREAD). They are for
/// memory errors, undefined behaviour and data races, and run everything three to fifteen times
/// slower; the heaviest physics
/// checks run their code paths there at a reduced size (each says what it leaves to the
/// Release build, which runs them in full), to keep the README's test command within CI's time.
inline constexpr bool kSanitizerBuild = RADIOSITY_TEST_SANITIZER_BUILD != 0;

}  // namespace test
