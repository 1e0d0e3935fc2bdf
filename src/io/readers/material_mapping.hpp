// How the scene readers turn a file format's material description into a Material and its
// view-pass model, shared so that the same description means the same thing in every format:
// MTL's Pr/Pm and glTF's metallic-roughness are one microfacet model, MTL's refracting illum
// modes and glTF's KHR_materials_transmission one dielectric, MTL's dissolve and an Assimp
// opacity one thin pane. The readers clamp and warn (reader_warnings.hpp) before calling these;
// here the values are in range.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "io/readers/reader_warnings.hpp"
#include "radiosity/brdf.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// "(r, g, b)", how the readers' messages show a colour.
std::string describe(const Rgb& c);

/// `c` with every channel below 0 raised to 0, and those at or above `at_or_above` set to
/// `upper` (a diffuse colour of 1 is clamped to kMaxForgivenAlbedo, 0.995 kept). A change is
/// forgiven (kind `kind`, at `where`) as "<what> (r, g, b) is <meaning> and must be <range>
/// per channel; clamped to (r', g', b')": an Error{invalid_scene} under strict.
Rgb clamp_colour(Rgb c, float upper, float at_or_above, ReaderWarnings& warnings, std::string_view kind,
                 const std::string& where, const std::string& what, const char* meaning, const char* range);

/// f = (1 - w) first + w second with the two parts' albedos `a` and `b` kept (w = b / (a + b));
/// `build_first(scale)` and `build_second(scale)` make the parts with their coefficients
/// multiplied by scale = 1 / weight. For the models make_brdf() has no field for (a tinted
/// Fresnel reflection, a PBR coat). A part of albedo 0 is left out.
std::shared_ptr<const Brdf> albedo_mixture(float a, float b,
                                           const std::function<std::shared_ptr<const Brdf>(float)>& build_first,
                                           const std::function<std::shared_ptr<const Brdf>(float)>& build_second);

/// A smooth dielectric (glass) over the material's diffuse part (`m.reflectance`): refraction
/// tinted by `transmittance` (each channel in [0, 1]) with index `ior` (> 0), Fresnel's
/// reflection tinted by `reflection_tint` (white: the plain interface). Sets m.transmittance,
/// m.ior and, for a tinted reflection, m.brdf (a mixture keeping the parts' albedos); no Phong
/// lobe, which would double the reflection and darken the glass.
void set_dielectric(Material& m, Rgb transmittance, float ior, Rgb reflection_tint);

/// glTF's KHR_materials_transmission over a dielectric base of colour `base`: the fraction
/// `transmission` (in (0, 1]) becomes a smooth dielectric of index `ior` whose refraction the
/// base colour tints, the rest stays diffuse (reflectance base (1 - transmission)); the
/// refracting MTL illum modes' model (set_dielectric()) with an untinted reflection.
void set_transmission(Material& m, Rgb base, float transmission, float ior);

/// The metallic-roughness model: base colour `base` (each channel in [0, 1)), `metallic` and
/// `roughness` in [0, 1] (GGX alpha = roughness^2, at least 0.001: the usual perceptual
/// mapping), dielectric F0 from `ior` (> 0). Radiosity sees the diffuse base, base (1 -
/// metallic) kept below what the coat leaves; the view pass gets a microfacet coat of F0 =
/// mix(((ior - 1)/(ior + 1))^2, base, metallic) mixed over that base (each part's albedo kept,
/// the coat's grazing Fresnel rise scaled down by its weight: an approximation of the layered
/// model the library has no BRDF for). A pure metal is exactly the microfacet model. Sets
/// m.reflectance and m.brdf.
void set_metallic_roughness(Material& m, Rgb base, float metallic, float roughness, float ior);

/// A thin pane (a window, ior 1) that passes a fraction 1 - `opacity` (in [0, 1]) of the light
/// straight through, tinted by `tint`; the surface's own parts keep the fraction `opacity`.
void set_thin_pane(Material& m, float opacity, Rgb tint);

}  // namespace radiosity::detail
