// Which specular events the extended first pass carries (FormFactorOptions::specular_depth),
// and which surfaces it treats as translucent (FormFactorOptions::diffuse_transmission):
// one rule shared by the Monte Carlo form factors, which carry them, and the photon map of the
// second pass, which must then leave them out so that nothing is counted twice.
#pragma once

#include "radiosity/scene.hpp"
#include "core/color.hpp"

namespace radiosity::detail {

/// The mean reflectance with which pass 1 reflects off `m` as an ideal mirror, or 0: the
/// material's specular part when it is ideal (specular_exponent 0). Glossy lobes are not
/// carried.
inline float pass1_mirror(const Material& m) { return m.specular_exponent <= 0.0f ? channel_mean(m.specular) : 0.0f; }

/// The mean transmittance with which pass 1 passes straight through `m` as a window, or 0:
/// transmitting materials with ior 1 (thin panes, no refraction).
inline float pass1_window(const Material& m) { return m.ior == 1.0f ? channel_mean(m.transmittance) : 0.0f; }

/// The mean transmittance of refracting glass (ior != 1), or 0. Pass 1 passes straight through
/// it too (Fresnel-weighted, the bending ignored), but only for light that left a non-emitting
/// surface: light from emitters through glass is the photon map's (sharp caustics).
inline float pass1_glass(const Material& m) { return m.ior != 1.0f ? channel_mean(m.transmittance) : 0.0f; }

/// Whether pass 1 treats `m` as a translucent thin sheet (FormFactorOptions::
/// diffuse_transmission): some channel of diffuse_transmittance is > 0. Such a patch has a
/// radiosity on each side; each side sends on tau times what the other receives.
inline bool pass1_translucent(const Material& m) {
  return m.diffuse_transmittance.x > 0.0f || m.diffuse_transmittance.y > 0.0f || m.diffuse_transmittance.z > 0.0f;
}

/// Whether a patch of `m` has a radiosity of its own on its back (FormFactorOptions::
/// diffuse_transmission numbers such backs as targets): a translucent sheet, or a two-sided
/// material, whose back reflects as its front does (an opaque one transmits nothing, tau = 0).
inline bool pass1_has_back(const Material& m) { return pass1_translucent(m) || m.two_sided; }

/// What the back of `m` emits: a two-sided material emits on both sides (as a double-sided
/// emissive surface does in Blender and glTF, and in the path tracer), a one-sided one only
/// on its front.
inline Rgb pass1_back_emission(const Material& m) { return m.two_sided ? m.emission : Rgb(0.0f); }
/// The same when the front emits `front` instead of the material's emission (a relit solve).
inline Rgb pass1_back_emission(const Material& m, const Rgb& front) { return m.two_sided ? front : Rgb(0.0f); }

/// What the back of a translucent sheet of `m` reflects: like the front for a two-sided
/// material, nothing for a one-sided one (its back transmits only, as in the path tracer).
inline Rgb pass1_back_reflectance(const Material& m) { return m.two_sided ? m.reflectance : Rgb(0.0f); }

}  // namespace radiosity::detail
