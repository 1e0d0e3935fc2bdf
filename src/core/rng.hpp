// Counter-based random streams: every (seed, key...) gets its own independent stream, so results
// do not depend on which thread computes what or in which order.
#pragma once

#include <cstdint>

#include <glm/vec2.hpp>

namespace radiosity::detail {

/// SplitMix64 finaliser: a bijective 64-bit mixer.
inline std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// PCG32 (O'Neill 2014), seeded from a hash of the seed and up to two keys.
class Rng {
 public:
  explicit Rng(std::uint64_t seed, std::uint64_t key_a = 0, std::uint64_t key_b = 0) {
    std::uint64_t s = mix64(seed ^ mix64(key_a ^ mix64(key_b + 0x632be59bd9b4e019ull)));
    state_ = 0;
    inc_ = (mix64(s + 1) << 1u) | 1u;
    next();
    state_ += s;
    next();
  }

  std::uint32_t next() {
    std::uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  /// Uniform in [0, 1).
  float uniform() { return static_cast<float>(next() >> 8) * 0x1p-24f; }
  /// Uniform integer in [0, n), n >= 1: the high half of next() x n (Lemire, "Fast random integer
  /// generation in an interval", ACM TOMACS 2019, without the rejection step): a multiply where
  /// next() % n divides, with a bias below n / 2^32, far under any estimator's noise.
  std::uint32_t below(std::uint32_t n) {
    return static_cast<std::uint32_t>((static_cast<std::uint64_t>(next()) * n) >> 32);
  }
  glm::vec2 uniform2() {
    float a = uniform();
    return {a, uniform()};
  }

 private:
  std::uint64_t state_ = 0;
  std::uint64_t inc_ = 1;
};

}  // namespace radiosity::detail
