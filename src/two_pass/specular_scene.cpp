// The scene as the two-pass method traces it: each material split into the diffuse part that
// the radiosity pass carries and the specular part that the view pass and the photon tracer
// follow; emitter sampling and shadow-ray estimates of direct irradiance.
// Based on:
//   J. R. Wallace, M. F. Cohen & D. P. Greenberg, "A two-pass solution to the rendering
//     equation: a synthesis of ray tracing and radiosity methods", SIGGRAPH 1987 (the split of
//     each reflection into a diffuse and a specular component).
//   M. Pharr, W. Jakob & G. Humphreys, "Physically Based Rendering", 3rd ed. 2016, sec. 14.2
//     (area light sampling, the area-to-solid-angle change of variables).
#include "two_pass/specular_scene.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "form_factors/pass1_material.hpp"
#include "core/color.hpp"

namespace radiosity::detail {

namespace {

}  // namespace

SpecularScene::SpecularScene(const Scene& scene, const PatchHierarchy& hierarchy, const EmitterWeights* weights,
                             bool through_windows)
    : hierarchy_(&hierarchy),
      rays_(RayScene::from_leaves(hierarchy, RayScene::backs_inside(scene, hierarchy))),
      lights_(scene.lights(), weights ? &weights->light : nullptr) {
  const auto& polygons = scene.polygons();
  for (const Patch& p : hierarchy.patches())
    if (p.polygon >= polygons.size())
      throw Error(ErrorCode::invalid_argument, "render_two_pass: the solution was not made from this scene");
  if (through_windows) through_ = PassThrough::if_any(scene, true, hierarchy);

  // The specular part of a material is its model without the Lambertian term: make_brdf() of the
  // same material with zero diffuse reflectance (pass 1 carries the diffuse term). A material
  // with its own Brdf cannot be split, so pass 2 samples all of it.
  std::vector<std::shared_ptr<const Brdf>> specular(scene.materials().size());
  std::vector<bool> own_brdf(scene.materials().size(), false);
  for (std::size_t m = 0; m < scene.materials().size(); ++m) {
    const Material& material = scene.materials()[m];
    if (material.brdf) {
      specular[m] = material.brdf;
      own_brdf[m] = true;
      continue;
    }
    if (max_channel(material.specular) <= 0.0f && max_channel(material.transmittance) <= 0.0f) continue;
    Material part = material;
    part.reflectance = Rgb(0.0f);
    specular[m] = make_brdf(part);
  }

  surfaces_.resize(polygons.size());
  std::vector<double> powers;
  for (std::size_t p = 0; p < polygons.size(); ++p) {
    const Polygon& poly = polygons[p];
    const Material& m = scene.material(poly.material);
    SplitSurface& s = surfaces_[p];
    s.normal = poly.normal;
    s.origin = poly.vertices[0];
    s.emission = weights ? m.emission * weights->polygon[p] : m.emission;
    s.uses_pass1 = !own_brdf[poly.material];
    s.diffuse = s.uses_pass1 ? m.reflectance : Rgb(0.0f);
    s.specular = specular[poly.material];
    s.specular_is_delta = s.specular && s.specular->is_delta();
    s.two_sided = m.two_sided;
    s.pass1_mirror = pass1_mirror(m) > 0.0f;
    s.pass1_window = pass1_window(m) > 0.0f;
    s.pass1_glass = pass1_glass(m) > 0.0f;
    s.ior = m.ior;
    if (s.specular) has_specular_ = true;

    const double power = static_cast<double>(s.emission.x + s.emission.y + s.emission.z) * poly.area;
    if (!(power > 0.0)) continue;
    emitted_power_ += s.emission * poly.area;
    Emitter e;
    e.polygon = static_cast<std::uint32_t>(p);
    e.fan = PolygonFan(poly.vertices);
    emitters_.push_back(std::move(e));
    powers.push_back(power);
  }
  emitter_choice_ = DiscreteDistribution(powers);
  for (std::size_t i = 0; i < emitters_.size(); ++i)
    emitters_[i].pdf_area = static_cast<float>(emitter_choice_.probability(i) / polygons[emitters_[i].polygon].area);

  element_polygon_.resize(hierarchy.elements().size());
  for (std::size_t e = 0; e < element_polygon_.size(); ++e)
    element_polygon_[e] = hierarchy.patches()[hierarchy.elements()[e].patch].polygon;
  epsilon_ = std::max(1e-5f * scene.bounds().diagonal(), 1e-6f);
}

EmitterSample SpecularScene::sample_emitter(float u_emitter, const glm::vec2& u_point) const {
  const Emitter& e = emitters_[emitter_choice_.sample(u_emitter)];
  const SplitSurface& s = surfaces_[e.polygon];
  EmitterSample out;
  out.position = e.fan.sample(u_point);  // u_point.x picks the triangle and drives the point
  out.normal = s.normal;
  out.emission = s.emission;
  out.pdf_area = e.pdf_area;
  out.polygon = e.polygon;
  return out;
}

Rgb SpecularScene::direct_irradiance_one(const glm::vec3& x, const glm::vec3& n, float u_emitter,
                                         const glm::vec2& u_point) const {
  const EmitterSample y = sample_emitter(u_emitter, u_point);
  const glm::vec3 w = y.position - x;
  const float d2 = glm::dot(w, w);
  if (!(d2 > 0.0f)) return Rgb(0.0f);
  const glm::vec3 wi = w / std::sqrt(d2);
  const float cos_x = glm::dot(n, wi), cos_y = -glm::dot(y.normal, wi);
  if (cos_x <= 0.0f || cos_y <= 0.0f) return Rgb(0.0f);
  // Shadow ray between points lifted off both planes.
  const glm::vec3 from = x + epsilon_ * n, to = y.position + epsilon_ * y.normal;
  const glm::vec3 sw = to - from;
  const float dist = glm::length(sw);
  if (!(dist > 0.0f) || rays_.occluded(from, sw / dist, 0.0f, dist)) return Rgb(0.0f);
  // dE = L_e cos_x cos_y / r^2 dA with L_e = E / pi, divided by the area density.
  return y.emission * (cos_x * cos_y / (glm::pi<float>() * d2 * y.pdf_area));
}

}  // namespace radiosity::detail
