// What kind of build the tests run in.
#pragma once

namespace test {

/// True in the sanitizer build (RADIOSITY_SANITIZE). That build is for memory errors and
/// undefined behaviour, and runs everything three to five times slower; the heaviest physics
/// checks run their code paths there at a reduced size (each says what it leaves to the
/// Release build, which runs them in full), to keep the README's test command within CI's time.
inline constexpr bool kSanitizerBuild = RADIOSITY_TEST_SANITIZER_BUILD != 0;

}  // namespace test
