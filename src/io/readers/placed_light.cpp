// add_placed_light() (placed_light.hpp): world placement of a reader's light.
#include "io/readers/placed_light.hpp"

#include <glm/mat3x3.hpp>

namespace radiosity::detail {

void add_placed_light(Scene& scene, Light light, const glm::dmat4& world, const glm::dvec3& local_position,
                      const glm::dvec3& local_direction, const LoadOptions& options, const std::string& where) {
  if (options.photometric) light.intensity = photometric_to_radiometric(light.intensity);
  light.position = glm::vec3(glm::dvec3(world * glm::dvec4(local_position, 1.0)));
  light.direction = glm::vec3(glm::dmat3(world) * local_direction);
  try {
    scene.add_light(light);
  } catch (const Error& e) {
    throw Error(e.code(), where + ": " + e.what());
  }
}

}  // namespace radiosity::detail
