// Which pipeline a scene needs (choose_render_mode) and the first pass the two-pass view wants
// (prepare_two_pass).
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "radiosity/brdf.hpp"
#include "radiosity/render.hpp"
#include "form_factors/pass1_material.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

bool any_channel(const Rgb& c) { return c.x > 0.0f || c.y > 0.0f || c.z > 0.0f; }

/// The materials that some polygon of `scene` uses.
std::vector<bool> used_materials(const Scene& scene) {
  std::vector<bool> used(scene.materials().size(), false);
  for (const Polygon& p : scene.polygons())
    if (p.material < used.size()) used[p.material] = true;
  return used;
}

/// Whether `brdf` behaves as a Lambertian reflector: not delta, and at a few fixed pairs of
/// directions eval() is one constant f with pi * f = albedo(wo). (A mix with a mirror keeps eval
/// constant but raises the albedo.)
bool is_lambertian(const Brdf& brdf) {
  if (brdf.is_delta()) return false;
  const glm::vec3 dirs[] = {glm::normalize(glm::vec3(0.0f, 0.0f, 1.0f)), glm::normalize(glm::vec3(0.6f, 0.1f, 0.8f)),
                            glm::normalize(glm::vec3(-0.3f, 0.7f, 0.4f)), glm::normalize(glm::vec3(0.9f, -0.2f, 0.15f))};
  const Rgb f0 = brdf.eval(dirs[0], dirs[0]);
  auto close = [](const Rgb& a, const Rgb& b, float rel) {
    for (int c = 0; c < 3; ++c)
      if (!(std::abs(a[c] - b[c]) <= rel * std::max({std::abs(a[c]), std::abs(b[c]), 1e-6f}))) return false;
    return true;
  };
  for (const glm::vec3& wo : dirs) {
    for (const glm::vec3& wi : dirs)
      if (!close(brdf.eval(wo, wi), f0, 1e-4f)) return false;
    if (!close(glm::pi<float>() * f0, brdf.albedo(wo), 1e-2f)) return false;
  }
  return true;
}

bool purely_diffuse(const Material& m) {
  if (any_channel(m.specular) || any_channel(m.transmittance)) return false;
  return !m.brdf || is_lambertian(*m.brdf);
}

}  // namespace

const char* to_string(RenderMode mode) {
  switch (mode) {
    case RenderMode::automatic: return "auto";
    case RenderMode::radiosity: return "radiosity";
    case RenderMode::two_pass: return "two-pass";
    case RenderMode::path: return "path";
  }
  return "unknown";
}

RenderMode choose_render_mode(const Scene& scene) {
  const std::vector<bool> used = used_materials(scene);
  for (std::size_t m = 0; m < used.size(); ++m)
    if (used[m] && !purely_diffuse(scene.materials()[m])) return RenderMode::two_pass;
  return RenderMode::radiosity;
}

bool needs_extended_first_pass(const Scene& scene) {
  const std::vector<bool> used = used_materials(scene);
  for (std::size_t m = 0; m < used.size(); ++m) {
    if (!used[m]) continue;
    const Material& material = scene.materials()[m];
    if (detail::pass1_mirror(material) > 0.0f || detail::pass1_window(material) > 0.0f ||
        detail::pass1_glass(material) > 0.0f)
      return true;
  }
  return false;
}

void prepare_two_pass(const Scene& scene, SolveOptions& options) {
  if (!needs_extended_first_pass(scene)) return;
  options.form_factors.method = FormFactorMethod::monte_carlo;
  options.form_factors.specular_depth = std::max(options.form_factors.specular_depth, 1u);
}

}  // namespace v1
}  // namespace radiosity
