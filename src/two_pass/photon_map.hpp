// The caustic photon map of the two-pass renderer: photons shot from the emitters through
// specular surfaces (L S+ D paths), stored where they first land on a diffuse surface, and a
// k-nearest-neighbour density estimate of the irradiance they carry. Private to the library.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "radiosity/common.hpp"
#include "radiosity/two_pass.hpp"
#include "two_pass/specular_scene.hpp"

namespace radiosity::detail {

/// A photon at rest on a diffuse surface.
struct Photon {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};  ///< of the surface it landed on (front side)
  Rgb power{0.0f};         ///< W per channel
  PolygonId polygon = 0;
  std::uint16_t specular_bounces = 0;  ///< specular events between the emitter and here, >= 1
};

/// What shooting produced.
struct PhotonShoot {
  std::vector<Photon> photons;  ///< in a deterministic order
  std::size_t emitted = 0;
  Rgb emitted_power{0.0f};  ///< W per channel, the scene's total
};

/// Shoots `options.photons` photons (none if the scene has no emitter or no specular surface)
/// and keeps those that reach a front-facing surface with a diffuse part after at least one
/// specular event: every such landing is stored, and the photon goes on along the surface's
/// specular part (Russian roulette by the event's weight) until `options.max_bounces` specular
/// events. Landings that the extended pass 1 already carries are not stored: those reached
/// only through mirror reflections (at most `pass1_depth`, SolveReport::specular_depth) and
/// window passages (form_factors/pass1_material.hpp), and with `pass1_glass`
/// (SolveReport::emitted_through_glass) glass passages and reflections too; with pass1_depth 0
/// (classic radiosity) every landing is stored. Photon k uses the stream (seed, k), so the
/// result does not depend on `threads`.
PhotonShoot shoot_caustic_photons(const SpecularScene& scene, const PhotonOptions& options, int pass1_depth,
                                  unsigned threads, std::uint64_t seed, bool pass1_glass = false);

/// A kd-tree over photons (nanoflann) and the density estimate of their irradiance.
/// Thread safety: immutable after construction; irradiance() may be called concurrently.
class PhotonMap {
 public:
  PhotonMap();
  explicit PhotonMap(std::vector<Photon> photons);
  PhotonMap(PhotonMap&&) noexcept;
  PhotonMap& operator=(PhotonMap&&) noexcept;
  ~PhotonMap();

  bool empty() const { return photons_.empty(); }
  const std::vector<Photon>& photons() const { return photons_; }

  /// Irradiance (W/m^2) at `x` on a surface with unit normal `n`, from the `k` nearest photons
  /// within `max_radius` (Jensen 1996): sum of filter-weighted photon powers over the area of
  /// the disc that holds them. The disc's radius is the k-th photon's distance, or max_radius
  /// when fewer than k photons lie within it. Photons on surfaces whose normal differs from `n`
  /// by more than about 25 degrees are not counted (they belong to another surface).
  Rgb irradiance(const glm::vec3& x, const glm::vec3& n, int k, float max_radius, PhotonFilter filter) const;

 private:
  struct Tree;
  std::vector<Photon> photons_;
  std::unique_ptr<Tree> tree_;
};

}  // namespace radiosity::detail
