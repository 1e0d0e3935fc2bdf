// Private helpers shared by the reflection models in src/brdf: parameter checks and reflection
// directions; the constants and sampling warps come from src/core. Not installed.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/constants.hpp"
#include "core/sampling.hpp"
#include "radiosity/brdf.hpp"
#include "radiosity/common.hpp"

namespace radiosity {
namespace detail {
namespace brdf {

using detail::kInv2Pi;
using detail::kInvPi;
using detail::kOneMinusEpsilon;
using detail::kPi;

inline float clamp01(float u) { return std::min(std::max(u, 0.0f), kOneMinusEpsilon); }
inline glm::vec2 clamp01(const glm::vec2& u) { return {clamp01(u.x), clamp01(u.y)}; }

inline bool all_finite(const Rgb& c) { return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z); }
inline float mean(const Rgb& c) { return (c.x + c.y + c.z) / 3.0f; }

[[noreturn]] inline void throw_invalid(const std::string& where, const std::string& what) {
  throw Error(ErrorCode::invalid_argument, where + ": " + what);
}

/// Each channel finite and in [0, 1]; `name` is the parameter named in the error.
inline void check_unit_rgb(const char* where, const char* name, const Rgb& c) {
  if (!all_finite(c)) throw_invalid(where, std::string(name) + " is not finite");
  for (int k = 0; k < 3; ++k) {
    if (c[k] < 0.0f || c[k] > 1.0f) {
      throw_invalid(where, std::string(name) + " channel " + std::to_string(k) + " = " + std::to_string(c[k]) +
                               " is outside [0, 1]");
    }
  }
}

/// diffuse and specular each in [0, 1] and their sum <= 1 per channel (energy conservation).
inline void check_diffuse_specular(const char* where, const Rgb& diffuse, const Rgb& specular) {
  check_unit_rgb(where, "diffuse", diffuse);
  check_unit_rgb(where, "specular", specular);
  for (int k = 0; k < 3; ++k) {
    if (diffuse[k] + specular[k] > 1.0f) {
      throw_invalid(where, "diffuse + specular = " + std::to_string(diffuse[k] + specular[k]) + " in channel " +
                               std::to_string(k) + " exceeds 1 (not energy conserving)");
    }
  }
}

inline void check_positive(const char* where, const char* name, float v) {
  if (!std::isfinite(v)) throw_invalid(where, std::string(name) + " is not finite");
  if (!(v > 0.0f)) throw_invalid(where, std::string(name) + " = " + std::to_string(v) + " must be > 0");
}

inline void check_non_negative(const char* where, const char* name, float v) {
  if (!std::isfinite(v)) throw_invalid(where, std::string(name) + " is not finite");
  if (v < 0.0f) throw_invalid(where, std::string(name) + " = " + std::to_string(v) + " must be >= 0");
}

/// Mirror direction of w about the normal (0, 0, 1).
inline glm::vec3 reflect_z(const glm::vec3& w) { return {-w.x, -w.y, w.z}; }

/// Mirror direction of w about the unit vector h: 2 (w.h) h - w.
inline glm::vec3 reflect_about(const glm::vec3& w, const glm::vec3& h) { return 2.0f * glm::dot(w, h) * h - w; }

// The warps live in core/sampling.hpp, shared with the estimators and renderers.
using detail::concentric_disk;
using detail::cosine_hemisphere_pdf;
inline glm::vec3 sample_cosine_hemisphere(const glm::vec2& u) { return detail::cosine_hemisphere(u); }

/// The pdf of the models that sample cos/pi above the surface (Lambertian, measured): 0 for an
/// outgoing direction below it.
inline float cosine_lobe_pdf(const glm::vec3& wo, const glm::vec3& wi) {
  return wo.z > 0.0f ? cosine_hemisphere_pdf(wi) : 0.0f;
}

/// Their sample: a cosine-distributed direction above the surface, or nothing for wo below it
/// or for a point exactly on the disk rim (z = 0, a direction with no density).
inline std::optional<glm::vec3> sample_cosine_lobe(const glm::vec3& wo, const glm::vec2& u) {
  if (!(wo.z > 0.0f)) return std::nullopt;
  const glm::vec3 wi = sample_cosine_hemisphere(clamp01(u));
  if (!(wi.z > 0.0f)) return std::nullopt;
  return wi;
}

/// Remaps u (in [0, 1)) that fell below `p` (or above it) back onto [0, 1) so that one uniform
/// number both picks a lobe and drives that lobe's sampler.
inline float remap_below(float u, float p) { return clamp01(u / p); }
inline float remap_above(float u, float p) { return clamp01((u - p) / (1.0f - p)); }

}  // namespace brdf
}  // namespace detail
}  // namespace radiosity
