// Shared vocabulary of the radiosity library: colours, errors, progress reporting.
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "radiosity/export.hpp"

// glm::vec3 appears in the public API; a consumer whose GLM settings change its layout
// (GLM_FORCE_ALIGNED_GENTYPES and similar) would silently disagree with the binary.
static_assert(sizeof(glm::vec3) == 12, "radiosity requires glm::vec3 to be three packed floats");

namespace radiosity {
inline namespace v1 {

/// Marks "no element / vertex / polygon" wherever an index may be absent.
inline constexpr std::uint32_t kNone = 0xffffffffu;

/// Linear RGB triple. Radiosity, emission (W/m^2) and reflectance are always solved for
/// R, G and B together.
using Rgb = glm::vec3;

/// What went wrong, for programs that branch on it. The message says it for people.
enum class ErrorCode {
  invalid_argument,  ///< an option or a function argument is out of range
  invalid_scene,     ///< geometry or a material is unusable (NaN, zero area, reflectance >= 1, ...)
  file_not_found,    ///< a file that was named does not exist or cannot be opened
  parse_error,       ///< a file exists but its contents are broken
  io_error,          ///< writing a file failed
  memory_budget,     ///< the chosen method would need more memory than SolveOptions allows
  internal,          ///< a library bug or a failing dependency (Embree device creation, ...)
};

/// Every error the library reports on bad input. The message names the field, file, line or
/// polygon concerned. Thread safety: immutable after construction.
class RADIOSITY_API Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const noexcept { return code_; }

 private:
  ErrorCode code_;
};

class PatchHierarchy;  // mesh.hpp

/// Stage of a long computation that a progress report refers to.
enum class Phase {
  meshing,
  form_factors,
  solving,
  refining,
  rendering,
  lights,  ///< the first shot of the scene's lights (Light) onto the elements
};

/// Snapshot handed to a progress callback.
struct Progress {
  Phase phase = Phase::meshing;
  double fraction = 0.0;   ///< of the current phase, in [0, 1]; solvers estimate it from the residual
  int iteration = 0;       ///< sweeps (matrix methods) or shooting steps (progressive)
  double residual = 0.0;   ///< unshot / emitted power (see SolveOptions::tolerance)
  /// While solving: the current estimate, so an application can display it incrementally.
  /// `leaf_radiosity` has one value per leaf of `*hierarchy`, in hierarchy->leaves() order.
  /// Both pointers are valid only during the call; null in other phases.
  const PatchHierarchy* hierarchy = nullptr;
  const Rgb* leaf_radiosity = nullptr;
  /// Progressive refinement's ambient radiosity estimate (Cohen et al. 1988): add
  /// reflectance x ambient to a leaf's radiosity for display. Zero for the matrix methods.
  Rgb ambient{0.0f};
};

/// Called on the thread that started the computation, one call at a time, at phase
/// boundaries and at most about every 50 ms. Return false to cancel.
using ProgressFn = std::function<bool(const Progress&)>;

/// Version of the library binary, e.g. "0.1.0". Compare with RADIOSITY_VERSION_STRING from
/// <radiosity/version.hpp> to detect a header/binary mismatch.
RADIOSITY_API const char* version() noexcept;

}  // namespace v1
}  // namespace radiosity
