// Numbers every module uses, in one place (issue: pi was spelled seven ways).
#pragma once

namespace radiosity::detail {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.318309886183790671538f;
inline constexpr float kInv2Pi = 0.159154943091895335769f;
/// Largest float below 1, so that u in [0, 1) stays there after clamping.
inline constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

}  // namespace radiosity::detail
