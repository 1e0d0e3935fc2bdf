// `radiosity check`: what a user needs to know before a long bake, without solving: counts,
// warnings, overlapping polygons, emitters facing away, and the size of the default solve.
#include "check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace cli {

namespace {

using Json = nlohmann::ordered_json;

struct CheckArgs {
  std::string scene;
  std::string format = "text";
  bool strict = false;
  bool photometric = false;
  bool two_sided = false;
  std::string reverse_winding;
  float max_patch_area = 0.0f, max_element_area = 0.0f;
};

/// The overlaps (text and JSON) and emitters facing away (text) listed one by one; the rest are counted.
constexpr std::size_t kOverlapsShown = 5;
constexpr std::size_t kEmittersShown = 10;

/// What `radiosity solve` would build and hold for the scene with these mesh options.
struct Estimate {
  std::size_t patches = 0, elements = 0;
  float max_patch_area = 0.0f, max_element_area = 0.0f;
  /// elements x patches x 4 bytes: the matrix of the matrix solvers with a dense estimator.
  std::size_t dense_matrix_bytes = 0;
  /// The Monte Carlo estimator's rows at most (FormFactorEstimator::max_row_entries():
  /// hemisphere_rays plus the emitting patches, at most the targets; an index and a float per
  /// entry): the bound the solvers check against the memory budget; rows hold only non-zeros.
  std::size_t sparse_rows_bytes = 0;
  /// What the default solve's Gauss-Seidel rows could need (rad::SolvePlan: the estimator, dense
  /// or sparse, bytes), and what it does: hierarchical when they exceed the memory budget
  /// (SolverMethod::automatic), and its specular depth (1 on a scene with mirror or glass
  /// materials, rad::SpecularPaths::automatic; 0 otherwise or when it is hierarchical).
  rad::FormFactorMethod default_method = rad::FormFactorMethod::ray_cast;
  bool default_dense = true;
  std::size_t default_bytes = 0;
  bool default_hierarchical = false;
  unsigned default_specular_depth = 0;
  std::size_t memory_budget = 0;  ///< SolveOptions::memory_budget_bytes as solve() applies it
  /// The contacts the default mesh's grading (rad::MeshOptions::grade_at_contacts) left with
  /// elements larger than what stands there.
  std::vector<rad::ContactGrading::Coarse> coarse_contacts;
};

struct CheckResult {
  std::string scene;
  std::size_t polygons = 0, materials = 0, emitters = 0, lights = 0, groups = 0;
  double area = 0.0;
  std::vector<std::string> warnings;
  std::vector<rad::PolygonOverlap> overlaps;
  std::size_t coincident = 0, interpenetrating = 0;
  /// Coincident pairs facing the same way: the only ones solve() warns about (the others are
  /// contact, lit correctly).
  std::size_t z_fighting = 0;
  std::vector<rad::PolygonId> facing_away;
  /// The camera `render` would take (rad::choose_camera()).
  rad::CameraChoice camera;
  std::optional<Estimate> estimate;
  std::string error;  ///< why `radiosity solve` would refuse the scene; empty when it would run
};

bool emits(const rad::Material& m) { return m.emission.x > 0.0f || m.emission.y > 0.0f || m.emission.z > 0.0f; }

Estimate estimate_default_solve(const rad::Scene& scene, const rad::MeshOptions& mesh) {
  // The default solve's choices are the library's own (Problem::plan()), so that what check
  // says is what solve does; the two what-if figures (dense matrix, sparse rows) are ours.
  rad::SolveOptions options;
  options.mesh = mesh;
  rad::Problem problem(scene, options);
  const rad::PatchHierarchy& hierarchy = problem.hierarchy();
  Estimate e;
  e.patches = hierarchy.patches().size();
  e.elements = hierarchy.leaves().size();
  e.max_patch_area = hierarchy.options().max_patch_area;
  e.max_element_area = hierarchy.options().max_element_area;
  std::size_t emitting_patches = 0, back_patches = 0, back_elements = 0;
  // A patch has a back side when its material is translucent or two-sided (as solve() decides).
  auto has_back = [](const rad::Material& m) {
    const rad::Rgb tau = m.diffuse_transmittance;
    return m.two_sided || tau.x > 0.0f || tau.y > 0.0f || tau.z > 0.0f;
  };
  for (const rad::Patch& p : hierarchy.patches()) {
    const rad::Material& m = scene.material(p.material);
    emitting_patches += emits(m) ? 1 : 0;
    back_patches += has_back(m) ? 1 : 0;
  }
  for (std::uint32_t leaf : hierarchy.leaves())
    back_elements += has_back(scene.material(hierarchy.patches()[hierarchy.element(leaf).patch].material)) ? 1 : 0;
  // Patches with a back are targets twice (front and back) and their elements have two rows.
  const std::size_t targets = e.patches + back_patches, rows = e.elements + back_elements;
  const std::size_t entry = 2 * sizeof(float);
  e.dense_matrix_bytes = e.elements * e.patches * sizeof(float);
  const std::size_t row_entries = std::size_t{rad::FormFactorOptions{}.hemisphere_rays} + emitting_patches;
  e.sparse_rows_bytes = rows * std::min(targets, row_entries) * entry;
  e.coarse_contacts = hierarchy.contact_grading().coarse;
  const rad::SolvePlan plan = problem.plan();
  e.default_method = plan.row_form_factor_method;
  e.default_dense = !plan.sparse_rows;
  e.default_bytes = plan.row_bytes;
  e.default_hierarchical = plan.method == rad::SolverMethod::hierarchical;
  e.default_specular_depth = plan.specular_depth;
  e.memory_budget = problem.options().memory_budget_bytes;
  return e;
}

/// A --max-element-area is suggested only when the scene would have at most this many elements.
constexpr double kMaxSuggestedElements = 4e6;

/// What stands on or passes through a polygon whose elements where they meet are larger than
/// it: its shadow and contact cannot show there. The default mesh is graded toward such
/// contacts (rad::MeshOptions::grade_at_contacts), so this is what the grading's limits left
/// (8 levels below the polygon's elements: a 0.7 m crate on a 10 km plot; twice as many new
/// elements as the mesh had: thousands of objects on one coarse ground), as the mesher found
/// it (rad::ContactGrading::coarse). One warning per pair of groups (of polygons, in a file of
/// one group), the first kShownPairs of them.
void coarse_contact_warnings(const rad::Scene& scene, const std::vector<rad::ContactGrading::Coarse>& coarse,
                             std::vector<std::string>& warnings) {
  constexpr std::size_t kShownPairs = 3;
  const std::vector<rad::Polygon>& polygons = scene.polygons();
  auto name = [&](rad::PolygonId p, bool by_polygon) {
    const std::string group = "group '" + scene.groups()[polygons[p].group] + "'";
    return by_polygon ? "polygon " + std::to_string(p) + " (" + group + ")" : group;
  };
  // One per pair of groups: coarse is by polygon, then group.
  std::vector<rad::ContactGrading::Coarse> shown;
  for (const rad::ContactGrading::Coarse& c : coarse) {
    const bool by_polygon = polygons[c.polygon].group == polygons[c.other].group;
    const auto same = std::find_if(shown.begin(), shown.end(), [&](const rad::ContactGrading::Coarse& q) {
      return by_polygon ? q.polygon == c.polygon && q.other == c.other
                        : polygons[q.polygon].group == polygons[c.polygon].group &&
                              polygons[q.other].group == polygons[c.other].group;
    });
    if (same == shown.end()) shown.push_back(c);
    else same->element = std::max(same->element, c.element);
  }
  for (std::size_t k = 0; k < shown.size() && k < kShownPairs; ++k) {
    const rad::ContactGrading::Coarse& q = shown[k];
    const bool by_polygon = polygons[q.polygon].group == polygons[q.other].group;
    const float suggested = 0.0625f * q.object * q.object;  // elements a quarter of its size
    char figures[96];
    std::snprintf(figures, sizeof figures, " has elements of %.3g across where ", q.element);
    char size[64];
    std::snprintf(size, sizeof size, " (%.3g) stands on or passes through it, larger than that", q.object);
    // The option only where the whole scene at that size stays a mesh one can solve.
    char hint[96] = "";
    if (scene.total_area() / static_cast<double>(suggested) <= kMaxSuggestedElements)
      std::snprintf(hint, sizeof hint, ", or lower --max-element-area (%.3g gives elements a quarter of its size)",
                    suggested);
    const std::string under = name(q.polygon, by_polygon);
    warnings.push_back(under + figures + name(q.other, by_polygon) + size + (by_polygon ? " polygon" : " group") +
                       ": its shadow and contact cannot show there (the mesh is graded toward contacts by at most 8 "
                       "levels and twice as many new elements as it had, at least 32768); cut " + under +
                       " finer around it in the model" + hint);
  }
  if (shown.size() > kShownPairs)
    warnings.push_back(std::to_string(shown.size() - kShownPairs) +
                       " more pairs where one stands on elements larger than itself");
}

const std::string& group_of(const rad::Scene& scene, rad::PolygonId p) {
  return scene.groups()[scene.polygons()[p].group];
}

/// A place in the file's coordinates (Scene::origin() added), with the digits georeferenced
/// coordinates need when there is an origin.
std::string place(const glm::vec3& p, const glm::dvec3& origin) {
  const bool moved = origin != glm::dvec3(0.0);
  char text[128];
  std::snprintf(text, sizeof text, moved ? "(%.10g, %.10g, %.10g)" : "(%.6g, %.6g, %.6g)",
                static_cast<double>(p.x) + origin.x, static_cast<double>(p.y) + origin.y,
                static_cast<double>(p.z) + origin.z);
  return text;
}

CheckResult check_scene(const CheckArgs& a, const rad::Scene& scene) {
  CheckResult r;
  r.scene = a.scene.empty() ? "cornell-box" : a.scene;
  r.polygons = scene.polygons().size();
  r.materials = scene.materials().size();
  r.groups = scene.groups().size();
  r.area = scene.total_area();
  for (const rad::Polygon& p : scene.polygons()) r.emitters += emits(scene.material(p.material)) ? 1 : 0;
  r.warnings = scene.warnings();
  r.camera = rad::choose_camera(scene);
  if (r.polygons == 0) {
    r.error = "the scene has no polygons";
    return r;
  }
  r.lights = scene.lights().size();
  if (r.emitters == 0 && r.lights == 0)
    r.warnings.push_back("the scene emits no light; every radiosity is 0 (render lights it by a uniform sky unless "
                         "--no-default-light)");
  r.overlaps = rad::find_overlaps(scene);
  for (const rad::PolygonOverlap& o : r.overlaps) {
    (o.kind == rad::OverlapKind::coincident ? r.coincident : r.interpenetrating) += 1;
    if (o.z_fighting()) ++r.z_fighting;
  }
  r.facing_away = rad::find_emitters_facing_away(scene);
  {
    // A closed model wound outward: most of the one-sided area sees nothing in front and
    // surfaces behind (a roof under an open sky does too, but it is not most of a scene).
    const rad::OutwardFacing outward = rad::find_polygons_facing_outward(scene, r.overlaps);
    if (outward.looks_wound_outward()) {
      char share[32];
      std::snprintf(share, sizeof share, "%.0f", 100.0 * outward.area / outward.one_sided_area);
      // Without light nothing tells a room wound outward from an object seen from outside.
      r.warnings.push_back(std::to_string(outward.polygons.size()) + " of " + std::to_string(scene.polygons().size()) +
                           " polygons (" + share +
                           " % of the one-sided area) see nothing in front of them and surfaces behind: a closed "
                           "model wound outward (a CAD solid's facets point out of it)" +
                           (has_light(scene) ? "? Its inside then stays dark"
                                             : ", or an object seen from outside (then all is well)? If it is an "
                                               "enclosure, its inside stays dark") +
                           " and its view factors are 0; reverse the winding (--reverse-winding outward), or use "
                           "two-sided materials (--two-sided) to light it");
    }
  }

  {
    // Polygons wound against their neighbours (a flipped face of a mesh): black with no other sign.
    const rad::InconsistentWinding inconsistent = rad::find_inconsistent_winding(scene);
    if (!inconsistent.polygons.empty()) {
      char area[32];
      std::snprintf(area, sizeof area, "%.3g", inconsistent.area);
      const rad::Polygon& p = scene.polygons()[inconsistent.polygons.front()];
      glm::vec3 centre(0.0f);
      for (const glm::vec3& v : p.vertices) centre += v;
      centre /= static_cast<float>(p.vertices.size());
      const bool one = inconsistent.polygons.size() == 1;
      r.warnings.push_back(std::to_string(inconsistent.polygons.size()) + (one ? " polygon is" : " polygons are") +
                           " wound opposite to the polygons " + (one ? "it shares" : "they share") + " edges with (" +
                           area + " units^2 in " + std::to_string(inconsistent.surfaces) +
                           (inconsistent.surfaces == 1 ? " surface" : " surfaces") + "; the first: polygon " +
                           std::to_string(inconsistent.polygons.front()) + " of group '" +
                           group_of(scene, inconsistent.polygons.front()) + "' at " + place(centre, scene.origin()) +
                           "): one-sided, " +
                           (one ? "it faces away from the light its neighbours take and comes"
                                : "they face away from the light their neighbours take and come") +
                           " out black; reverse the winding (--reverse-winding inconsistent) or use two-sided "
                           "materials (--two-sided)");
    }
  }

  rad::MeshOptions mesh;
  mesh.max_patch_area = a.max_patch_area;
  mesh.max_element_area = a.max_element_area;
  try {
    r.estimate = estimate_default_solve(scene, mesh);
  } catch (const rad::Error& e) {
    r.error = e.what();  // e.g. max_element_area > max_patch_area, or far too many elements
    return r;
  }
  coarse_contact_warnings(scene, r.estimate->coarse_contacts, r.warnings);
  if (r.z_fighting > 0)
    r.warnings.push_back(std::to_string(r.z_fighting) +
                         " pair(s) of coincident polygons face the same way (z-fighting): which is in front is "
                         "decided by rounding, remove one of each pair (listed under overlaps)");
  return r;
}

const char* kind_name(rad::OverlapKind k) {
  return k == rad::OverlapKind::coincident ? "coincident" : "interpenetrating";
}

std::string mib(std::size_t bytes) {
  char s[32];
  std::snprintf(s, sizeof s, "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  return s;
}

void print_text(const CheckResult& r, const rad::Scene& scene) {
  std::printf("scene: %s\n", r.scene.c_str());
  std::printf("polygons: %zu\nmaterials: %zu\nemitters: %zu\nlights: %zu\ngroups: %zu\narea: %.6g\n", r.polygons,
              r.materials, r.emitters, r.lights, r.groups, r.area);
  const glm::dvec3 origin = scene.origin();
  const std::string moved = origin_note(scene);
  if (!moved.empty()) std::printf("origin: %s\n", moved.c_str());
  std::printf("warnings: %zu\n", r.warnings.size());
  for (const std::string& w : r.warnings) std::printf("  warning: %s\n", w.c_str());
  // Contact (a box on a floor, a prop sunk into it) is lit correctly; only z-fighting is a problem.
  std::printf("overlaps: %zu (coincident %zu, interpenetrating %zu; z-fighting %zu, the rest contact)\n",
              r.overlaps.size(), r.coincident, r.interpenetrating, r.z_fighting);
  for (std::size_t k = 0; k < r.overlaps.size() && k < kOverlapsShown; ++k) {
    const rad::PolygonOverlap& o = r.overlaps[k];
    std::printf("  %s: polygon %u (group '%s') and polygon %u (group '%s') at %s\n", kind_name(o.kind), o.first,
                group_of(scene, o.first).c_str(), o.second, group_of(scene, o.second).c_str(),
                place(o.point, origin).c_str());
  }
  if (r.overlaps.size() > kOverlapsShown) std::printf("  ... and %zu more\n", r.overlaps.size() - kOverlapsShown);
  std::printf("emitters facing away: %zu\n", r.facing_away.size());
  for (std::size_t k = 0; k < r.facing_away.size() && k < kEmittersShown; ++k)
    std::printf("  polygon %u (group '%s'): its light leaves the scene; check its winding (vertex order)\n",
                r.facing_away[k], group_of(scene, r.facing_away[k]).c_str());
  if (r.facing_away.size() > kEmittersShown)
    std::printf("  ... and %zu more\n", r.facing_away.size() - kEmittersShown);
  if (r.estimate) {
    const Estimate& e = *r.estimate;
    std::printf("estimate: %zu patches, %zu elements (max patch area %.6g, max element area %.6g)\n", e.patches,
                e.elements, e.max_patch_area, e.max_element_area);
    std::printf("form factors: dense matrix %zu bytes (%s), sparse rows up to %zu bytes (%s)\n", e.dense_matrix_bytes,
                mib(e.dense_matrix_bytes).c_str(), e.sparse_rows_bytes, mib(e.sparse_rows_bytes).c_str());
    if (e.default_hierarchical)
      std::printf("default solve: hierarchical (automatic: gauss-seidel with %s form factors would need %s: %zu "
                  "bytes (%s), over the memory budget of %zu MiB)\n",
                  rad::to_string(e.default_method), e.default_dense ? "a dense matrix" : "sparse rows up to",
                  e.default_bytes, mib(e.default_bytes).c_str(), e.memory_budget >> 20);
    else
      std::printf("default solve: gauss-seidel, %s form factors (automatic), %s: %zu bytes (%s)\n",
                  rad::to_string(e.default_method), e.default_dense ? "dense matrix" : "sparse rows up to",
                  e.default_bytes, mib(e.default_bytes).c_str());
    if (e.default_specular_depth > 0)
      std::printf("default first pass: extended, specular depth %u (automatic: the scene has mirror or glass "
                  "materials, whose light it carries between diffuse surfaces)\n",
                  e.default_specular_depth);
  }
  std::printf("camera: %s\n", r.camera.reason.c_str());
  if (r.error.empty())
    std::printf("result: ok, the scene can be solved\n");
  else
    std::printf("result: cannot be solved: %s\n", r.error.c_str());
}

void print_json(const CheckResult& r, const rad::Scene& scene) {
  Json j;
  j["scene"] = r.scene;
  j["polygons"] = r.polygons;
  j["materials"] = r.materials;
  j["emitters"] = r.emitters;
  j["lights"] = r.lights;
  j["groups"] = r.groups;
  j["area"] = r.area;
  const glm::dvec3 origin = scene.origin();
  j["origin"] = {origin.x, origin.y, origin.z};
  j["warnings"] = r.warnings;
  Json first = Json::array();
  for (std::size_t k = 0; k < r.overlaps.size() && k < kOverlapsShown; ++k) {
    const rad::PolygonOverlap& o = r.overlaps[k];
    first.push_back(Json{{"kind", kind_name(o.kind)},
                         {"first", o.first},
                         {"first_group", group_of(scene, o.first)},
                         {"second", o.second},
                         {"second_group", group_of(scene, o.second)},
                         {"point", Json::array({o.point.x + origin.x, o.point.y + origin.y, o.point.z + origin.z})}});
  }
  j["overlaps"] = Json{{"coincident", r.coincident},
                       {"interpenetrating", r.interpenetrating},
                       {"z_fighting", r.z_fighting},
                       {"first", first}};
  Json away = Json::array();
  for (rad::PolygonId p : r.facing_away) away.push_back(Json{{"polygon", p}, {"group", group_of(scene, p)}});
  j["emitters_facing_away"] = std::move(away);
  const rad::Camera& c = r.camera.camera;
  j["camera"] = Json{{"eye", {c.eye.x + origin.x, c.eye.y + origin.y, c.eye.z + origin.z}},
                     {"look_at", {c.look_at.x + origin.x, c.look_at.y + origin.y, c.look_at.z + origin.z}},
                     {"up", {c.up.x, c.up.y, c.up.z}},
                     {"fov_deg", c.fov_deg},
                     {"reason", r.camera.reason}};
  if (r.estimate) {
    const Estimate& e = *r.estimate;
    j["estimate"] = Json{{"patches", e.patches},
                         {"elements", e.elements},
                         {"max_patch_area", e.max_patch_area},
                         {"max_element_area", e.max_element_area},
                         {"dense_matrix_bytes", e.dense_matrix_bytes},
                         {"sparse_rows_bytes", e.sparse_rows_bytes},
                         {"default_form_factors", rad::to_string(e.default_method)},
                         {"default_storage", e.default_dense ? "dense" : "sparse"},
                         {"default_bytes", e.default_bytes},
                         {"default_solver", e.default_hierarchical ? "hierarchical" : "gauss-seidel"},
                         {"default_specular_depth", e.default_specular_depth}};
  } else {
    j["estimate"] = nullptr;
  }
  j["solvable"] = r.error.empty();
  j["error"] = r.error.empty() ? Json(nullptr) : Json(r.error);
  // Group names come from scene files and may not be UTF-8: replace bad bytes rather than fail.
  const std::string text = j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
  std::fwrite(text.data(), 1, text.size(), stdout);
}

int run_check(const CheckArgs& a) {
  return run_guarded([&] {
    const rad::Scene scene = load(a.scene, a.strict, a.photometric, {a.two_sided, a.reverse_winding});
    const CheckResult r = check_scene(a, scene);
    if (a.format == "json")
      print_json(r, scene);
    else
      print_text(r, scene);
    std::fflush(stdout);
    if (r.error.empty()) return 0;
    std::fprintf(stderr, "radiosity: error: %s\n", r.error.c_str());
    return 1;
  });
}

}  // namespace

Command add_check_command(CLI::App& app) {
  auto args = std::make_shared<CheckArgs>();
  CheckArgs& a = *args;
  CLI::App* cmd = app.add_subcommand(
      "check", "Load and validate a scene without solving: counts, warnings, overlaps, emitters facing away, and the "
               "mesh and memory of the default solve; exit 0 when it can be solved");
  cmd->add_option("scene", a.scene, kSceneHelp);
  cmd->add_option("--format", a.format, "Output format")->check(CLI::IsMember({"text", "json"}))->capture_default_str();
  add_strict_flag(*cmd, a.strict);
  add_photometric_flag(*cmd, a.photometric);
  cmd->add_flag("--two-sided", a.two_sided, "Make every material two-sided, as render and solve --two-sided do");
  add_reverse_winding_option(*cmd, a.reverse_winding);
  cmd->add_option("--max-patch-area", a.max_patch_area, "Largest patch, scene units^2 (0 = derive)")
      ->check(non_negative<float>());
  cmd->add_option("--max-element-area", a.max_element_area, "Largest element, scene units^2 (0 = derive)")
      ->check(non_negative<float>());
  return Command{cmd, [args] { return run_check(*args); }};
}

}  // namespace cli
