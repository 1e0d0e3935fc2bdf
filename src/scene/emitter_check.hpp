// Where the light of a scene's emitters goes, by rays: the checks behind
// radiosity::find_emitters_facing_away() (scene.hpp) and solve()'s warnings about light that
// leaves the scene.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "radiosity/common.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// Rays per emitting polygon; fewer (down to kMinEmitterRays) when the scene has so many
/// emitters that kEmitterRayBudget rays would be exceeded.
inline constexpr std::size_t kEmitterRays = 256;
inline constexpr std::size_t kMinEmitterRays = 64;
inline constexpr std::size_t kEmitterRayBudget = std::size_t{1} << 22;

/// What the front of one emitting polygon sees.
struct EmitterReach {
  PolygonId polygon = 0;
  double power = 0.0;  ///< area x the sum of the emission's channels, W
  /// Of the cosine-distributed rays leaving its front (from stratified points, so weighted as
  /// its light is), the fraction that hit some polygon, front or back.
  double hit_fraction = 0.0;
  /// The fraction that hit one within kNearEmitterShare of the emitter's size (the square root
  /// of its area): a lamp wound to face the ceiling it hangs 1 cm under sees it with almost all.
  double near_fraction = 0.0;
};

/// What near_fraction counts as right in front of an emitter, as a share of its size.
inline constexpr double kNearEmitterShare = 0.1;
/// solve() warns about an emitter when at least this fraction of its rays is caught so near.
inline constexpr double kCaughtEmitterFraction = 0.9;

/// Every emitting polygon (emission > 0 in some channel), in polygon order. Each casts
/// kEmitterRays rays (see above) from stratified points just in front of it, in stratified
/// cosine-distributed directions, against every polygon of the scene; the streams have a fixed
/// seed, so the answer is the same at any thread count. `emission`: one value per polygon in
/// place of the materials' (polygon_emission()), or null. Throws Error{internal} if Embree
/// cannot create a device. Thread safety: concurrent calls are safe.
std::vector<EmitterReach> emitter_reach(const Scene& scene, unsigned threads = 0,
                                        const std::vector<Rgb>* emission = nullptr);

/// The warnings of solve() about escaped light, given the power balance of a solve:
/// - emitters whose front sees no polygon at all (named with their polygons and groups), those
///   that lie against a polygon facing them (find_overlaps(): coincident, opposite normals) in
///   a warning of their own (turning them would not help);
/// - when `balanced` (the solve converged, so emitted - absorbed is light that left rather than
///   light not yet propagated), more than 95 % of the emitters' light meets a surface directly
///   (the scene looks closed) and yet more than half of the emitted power escaped: light that
///   arrives at the backs of one-sided polygons is lost, so they probably face outwards;
/// - when `balanced` and more than half escaped but the emitters' own rays leave too (a light
///   fixture wound outward inside a room wound outward), the same when
///   find_polygons_facing_outward() finds most of the one-sided area wound outward.
/// `emitted` and `escaped` are W per channel; nothing is cast when nothing emits. `emission` as
/// for emitter_reach().
std::vector<std::string> escaped_light_warnings(const Scene& scene, const Rgb& emitted, const Rgb& escaped,
                                                bool balanced, unsigned threads = 0,
                                                const std::vector<Rgb>* emission = nullptr);

/// The warning of solve() about two-sided groups lit mainly on their backs: the groups whose
/// two-sided opaque polygons (Material::two_sided, no diffuse transmission) send, over their
/// leaf elements, more than four times as much power from their backs as from their fronts
/// (`front` and `back`: radiosity per element id of `hierarchy`, W/m^2; `back` empty: none).
/// Such a group's normals face away from its light (a room modelled as a box with outward
/// normals, made two-sided): solved and rendered right, but whatever reads one side per surface
/// (lightmaps, per-vertex values) shows its dark front. Empty when there is none; else one
/// warning naming the groups.
std::vector<std::string> back_lit_warnings(const Scene& scene, const PatchHierarchy& hierarchy,
                                           const std::vector<Rgb>& front, const std::vector<Rgb>& back);

}  // namespace radiosity::detail
