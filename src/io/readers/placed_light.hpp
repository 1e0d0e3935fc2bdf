// A light of a scene-graph format (glTF's KHR_lights_punctual, Assimp's aiLight) placed in the
// world by its node's matrix and added to the Scene, with what the readers share at that step:
// LoadOptions::photometric and add_light()'s errors at the light's place in the file.
#pragma once

#include <string>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// Adds `light` (type, name, colour, cones as the file gives them; `intensity` as written)
/// placed by the affine `world` matrix: its position is world x `local_position`, its direction
/// the matrix's linear part times `local_direction` (add_light() normalises it). Under
/// options.photometric the intensity, candela or lux, becomes W/sr or W/m^2
/// (photometric_to_radiometric()). Throws add_light()'s Error with `where` in front
/// ("file: lights[2] 'lamp': ...").
void add_placed_light(Scene& scene, Light light, const glm::dmat4& world, const glm::dvec3& local_position,
                      const glm::dvec3& local_direction, const LoadOptions& options, const std::string& where);

}  // namespace radiosity::detail
