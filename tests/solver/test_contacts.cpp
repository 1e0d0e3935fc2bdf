// Geometry as people model it: a box resting on a floor with its bottom face (coincident,
// facing the floor) and a sphere sunk into the floor (interpenetrating) are accepted and lit
// correctly, because rays and hemicubes that reach a back face are blocked there: the floor
// under the box and the sunk part are dark, and no light leaks along the contact lines. Checked
// against the reference path tracer, which treats backs the same way.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

#include "support/build.hpp"
#include "support/images.hpp"
#include "support/scenes.hpp"

namespace rad = radiosity;

namespace {

/// A 2 x 2 x 2 room (inward walls of reflectance `rho`) with a ceiling lamp; `prop` is set to
/// the material (rho 0.7, 0.5, 0.3) for what stands in it.
rad::Scene lit_room(float rho, rad::MaterialId& prop) {
  rad::Material wall, lamp, props;
  wall.name = "wall";
  wall.reflectance = rad::Rgb(rho);
  lamp.name = "lamp";
  lamp.emission = rad::Rgb(25.0f);
  lamp.reflectance = rad::Rgb(0.0f);
  props.name = "prop";
  props.reflectance = rad::Rgb(0.7f, 0.5f, 0.3f);
  const rad::Scene room = test::closed_box(wall, glm::vec3(2.0f));
  rad::Scene scene;
  const rad::MaterialId w = scene.add_material(wall), l = scene.add_material(lamp);
  prop = scene.add_material(props);
  for (const rad::Polygon& poly : room.polygons()) scene.add_polygon(poly.vertices, w, room.groups()[poly.group]);
  rad::add_quad(scene, {0.7f, 1.99f, 0.7f}, {0.6f, 0, 0}, {0, 0, 0.6f}, l, "lamp");  // facing down
  return scene;
}

/// lit_room(0.6) with a box [0.3, 0.9] x [0, 0.6] x [0.9, 1.5] resting on the floor with its
/// bottom face, and a sphere of radius 0.35 centred 0.15 below the floor at (1.4, -0.15, 0.8)
/// (its lower part is below the floor, outside the room).
rad::Scene props_on_floor() {
  rad::MaterialId p = 0;
  rad::Scene scene = lit_room(0.6f, p);
  rad::add_box(scene, {0.3f, 0.0f, 0.9f}, {0.9f, 0.6f, 1.5f}, p, "box");
  rad::add_sphere(scene, {1.4f, -0.15f, 0.8f}, 0.35f, p, "ball", 24);
  return scene;
}

/// lit_room(0.8) with a box [side, side + 0.6] x [0, 0.6] x [0.85, 1.45] resting on the floor
/// with its bottom face (or without it): its -x side at x = `side` cuts floor elements as a
/// user's box placed anywhere does.
rad::Scene box_across_elements(float side, bool with_box = true) {
  rad::MaterialId p = 0;
  rad::Scene scene = lit_room(0.8f, p);
  if (with_box) rad::add_box(scene, {side, 0.0f, 0.85f}, {side + 0.6f, 0.6f, 1.45f}, p, "box");
  return scene;
}

/// A wall from `a` to `b` (on the ground y = 0) of height `height`, cut into n x n quads as an
/// exporter writes a subdivided face, facing away from `centre`.
void faceted_wall(rad::Scene& scene, glm::vec3 a, glm::vec3 b, float height, int n, glm::vec3 centre,
                  rad::MaterialId m, const std::string& group) {
  glm::vec3 u = (b - a) / static_cast<float>(n);
  const glm::vec3 v(0.0f, height / static_cast<float>(n), 0.0f);
  const bool outward = glm::dot(glm::cross(u, v), 0.5f * (a + b) - centre) > 0.0f;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const glm::vec3 o = a + static_cast<float>(i) * u + static_cast<float>(j) * v;
      if (outward) rad::add_quad(scene, o, u, v, m, group);
      else rad::add_quad(scene, o, v, u, m, group);
    }
}

/// A 24 x 24 m ground of 4 m cells, each exported as two triangles, under a uniform sky of 100
/// W/m^2, with a 6 x 6 x 6 m building turned `degrees` about its vertical axis at `centre`,
/// its walls cut into 3 x 3 facets, its roof, and its bottom on the ground face to face (as
/// benchmarks/exported_block.py --turn writes them). Both materials reflect 0.5.
rad::Scene turned_building(float degrees, glm::vec3 centre) {
  rad::Scene scene;
  rad::Material ground, concrete;
  ground.name = "ground";
  ground.reflectance = rad::Rgb(0.5f);
  concrete.name = "concrete";
  concrete.reflectance = rad::Rgb(0.5f);
  const rad::MaterialId g = scene.add_material(ground), c = scene.add_material(concrete);
  for (float x = -12.0f; x < 12.0f; x += 4.0f)
    for (float z = -12.0f; z < 12.0f; z += 4.0f) {
      const glm::vec3 p0(x, 0, z), p1(x, 0, z + 4), p2(x + 4, 0, z + 4), p3(x + 4, 0, z);  // facing +y
      scene.add_polygon({p0, p1, p2}, g, "ground");
      scene.add_polygon({p0, p2, p3}, g, "ground");
    }
  const float t = degrees * 3.14159265f / 180.0f;
  const glm::vec3 along(std::cos(t), 0, std::sin(t)), across(-std::sin(t), 0, std::cos(t));
  std::vector<glm::vec3> corner;
  for (const auto& [s, r] : {std::pair{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}})
    corner.push_back(centre + 3.0f * s * along + 3.0f * r * across);
  for (int k = 0; k < 4; ++k) faceted_wall(scene, corner[k], corner[(k + 1) % 4], 6.0f, 3, centre, c, "walls");
  const glm::vec3 up(0, 6, 0);
  // Roof facing up and bottom facing down: the same corners in the two orders.
  const bool ccw_up = glm::cross(corner[1] - corner[0], corner[2] - corner[0]).y > 0.0f;
  const std::vector<glm::vec3> ring = ccw_up ? corner : std::vector<glm::vec3>(corner.rbegin(), corner.rend());
  scene.add_polygon({ring[0] + up, ring[1] + up, ring[2] + up, ring[3] + up}, c, "roof");
  scene.add_polygon({ring[3], ring[2], ring[1], ring[0]}, c, "bottom");
  rad::Light sky;
  sky.type = rad::LightType::sky;
  sky.intensity = 100.0f;
  sky.direction = {0, 1, 0};
  scene.add_light(sky);
  return scene;
}

}  // namespace

TEST_SUITE("solver") {
  TEST_CASE("a box whose sides cut the floor's elements: no light lost under it, and the floor beside it as the path "
            "tracer sees it" * test::release_only) {
    // A floor element half under the box gathers, by every estimator, nothing on its buried
    // half: its mean is half its open half's light. Before the exposure (session 21) the
    // solvers took that mean for the element's radiosity, showed a dark band around the box
    // (the user's room: -55 % beside it) and sent the element's light from its buried half as
    // well, which a closed room lost (escaped, measured below). Now its values are its open
    // half's and its targets weigh it by its open area (docs/ARCHITECTURE.md, "Contact and
    // light leaks").
    // The mesher grids the 2 m floor into 22 x 22 elements at 10 cm (2 / 22 m each): the box's
    // side at 3.5 of them cuts a column of elements in half.
    const float side = 3.5f * 2.0f / 22.0f;
    const rad::Scene scene = box_across_elements(side);
    const double pi = 3.14159265358979323846;
    rad::SolveOptions o;
    o.form_factors.method = rad::FormFactorMethod::monte_carlo;
    o.mesh.max_patch_area = 0.04f;
    o.mesh.max_element_area = 0.01f;
    o.tolerance = 1e-4;
    struct Case {
      const char* name;
      rad::SolverMethod method;
      rad::FormFactorMethod form_factors;
    };
    // Not the hemicube: its row is its element's centre's, which here lies on the box's side.
    std::optional<double> strip_path;
    for (const Case& c : {Case{"gauss-seidel", rad::SolverMethod::gauss_seidel, rad::FormFactorMethod::monte_carlo},
                          Case{"gauss-seidel, ray-cast", rad::SolverMethod::gauss_seidel, rad::FormFactorMethod::ray_cast},
                          Case{"progressive", rad::SolverMethod::progressive, rad::FormFactorMethod::monte_carlo},
                          Case{"hierarchical", rad::SolverMethod::hierarchical, rad::FormFactorMethod::monte_carlo}}) {
      CAPTURE(std::string(c.name));
      o.method = c.method;
      o.form_factors.method = c.form_factors;
      const rad::Solution sol = rad::solve(scene, o);
      REQUIRE(sol.status() == rad::SolveStatus::converged);
      // A closed room: what escapes (what the lamp's back takes from the ceiling 1 cm above it,
      // which the balance does not count as absorbed: 0.4-0.5 %) is the same with the box.
      auto escaped = [](const rad::Solution& s) { return s.report().escaped_power.x / s.report().emitted_power.x; };
      const double lost = escaped(sol) - escaped(rad::solve(box_across_elements(side, false), o));
      // The floor elements that the box's side cuts, along its middle (z in [1, 1.3]), each with
      // the share of it outside the box.
      const rad::PatchHierarchy& h = sol.hierarchy();
      double cut = 0.0, area = 0.0, low = 1.0, high = 0.0, near = 1e9, far = -1e9;
      int count = 0;
      for (std::uint32_t leaf : h.leaves()) {
        const rad::Element& e = h.element(leaf);
        if (scene.polygons()[h.patches()[e.patch].polygon].group != *scene.find_group("y0")) continue;
        if (e.centroid.z < 1.0f || e.centroid.z > 1.3f) continue;
        float x0 = 1e9f, x1 = -1e9f, z0 = 1e9f, z1 = -1e9f;
        for (int k = 0; k < e.corner_count(); ++k) {
          const glm::vec3 v = h.vertices()[e.corners[static_cast<std::size_t>(k)]];
          x0 = std::min(x0, v.x), x1 = std::max(x1, v.x), z0 = std::min(z0, v.z), z1 = std::max(z1, v.z);
        }
        if (!(x0 < side - 0.01f && x1 > side + 0.01f)) continue;
        const float x = sol.exposure().empty() ? 1.0f : sol.exposure()[leaf];
        CHECK(x == doctest::Approx((side - x0) / (x1 - x0)).epsilon(0.06));
        cut += e.area * sol.radiosity()[leaf].x;
        area += e.area;
        low = std::min(low, double{x0}), near = std::min(near, double{z0}), far = std::max(far, double{z1});
        high = std::max(high, double{x1});
        ++count;
      }
      REQUIRE(count >= 2);
      cut /= area;
      if (!strip_path) {
        // The path tracer on the open parts of those elements, from above.
        rad::PathTraceOptions view;
        const double width = side - low, length = far - near;
        view.width = 4;
        view.height = static_cast<int>(std::lround(4.0 * length / width));
        view.spp = 1024;
        view.camera = rad::Camera{{static_cast<float>(low + 0.5 * width), 1.0f, static_cast<float>(0.5 * (near + far))},
                                  {static_cast<float>(low + 0.5 * width), 0.0f, static_cast<float>(0.5 * (near + far))},
                                  {0, 0, 1},
                                  static_cast<float>(2.0 * std::atan(0.5 * length) * 180.0 / pi)};
        const rad::Image img = rad::render_path_traced(scene, view);
        double sum = 0.0;
        for (const rad::Rgb& px : img.pixels) sum += px.x;
        strip_path = pi * sum / static_cast<double>(img.pixels.size());
      }
      MESSAGE(std::string(c.name) << ": lost to the box " << lost << ", the " << count << " cut elements' radiosity " << cut
                     << " (path tracer on their open parts " << *strip_path << ")");
      // Measured (session 21): Gauss-Seidel +1.8 % against the path tracer and -0.02 % of the
      // power lost to the box, over ray-cast rows +1.1 % and -0.02 %, progressive +5.5 % and 0.00 %. Before, the box cost 0.4-0.5 % of
      // the power (1.2 % escaped against 0.8 % without it) and the cut elements showed their
      // area mean, about half. Hierarchical: +16.5 %, and the room gains 0.55 % with the box;
      // its floor along a box's side is too bright with or without anything buried (with the
      // box's side on an element border: +8 % against Gauss-Seidel one element away, before and
      // after this; docs/HIERARCHICAL.md, "Buried parts"), so it is held to 20 % here.
      const bool hierarchical = c.method == rad::SolverMethod::hierarchical;
      CHECK(std::fabs(lost) < (hierarchical ? 0.008 : 0.003));
      CHECK(cut > 0.9 * *strip_path);
      CHECK(cut < (hierarchical ? 1.2 : 1.1) * *strip_path);
    }
  }


  TEST_CASE("a box resting on the floor and a sphere sunk into it are lit as the path tracer lights them"
            * test::release_only) {
    const rad::Scene scene = props_on_floor();
    // The geometry really touches: the box's bottom lies on the floor, the ball crosses it.
    bool coincident = false, crossing = false;
    for (const rad::PolygonOverlap& o : rad::find_overlaps(scene)) {
      coincident = coincident || o.kind == rad::OverlapKind::coincident;
      crossing = crossing || o.kind == rad::OverlapKind::interpenetrating;
    }
    CHECK(coincident);
    CHECK(crossing);

    const double pi = 3.14159265358979323846;
    // The three matrix estimators with Gauss-Seidel, then the hierarchical solver (its links'
    // shadow rays find buried points as these do; what receiving clusters push down is given to
    // each part by the share of it that is not buried: docs/HIERARCHICAL.md, "Buried parts").
    const std::vector<rad::FormFactorMethod> methods{rad::FormFactorMethod::ray_cast, rad::FormFactorMethod::hemicube,
                                                     rad::FormFactorMethod::monte_carlo, rad::FormFactorMethod::automatic};
    for (rad::FormFactorMethod method : methods) {
      const bool hierarchical = method == rad::FormFactorMethod::automatic;
      CAPTURE(static_cast<int>(method));
      CAPTURE(hierarchical);
      rad::SolveOptions o;
      o.form_factors.method = method;
      if (hierarchical) o.method = rad::SolverMethod::hierarchical;
      // 64 rather than 128: the same figures (display RMSE 0.049 against the path tracer, the
      // box's bottom at 3e-4 of the floor) at 60 % of the time.
      o.form_factors.hemicube_resolution = 64;
      o.mesh.max_element_area = 0.01f;  // 10 cm elements
      o.tolerance = 1e-4;
      const rad::Solution sol = rad::solve(scene, o);
      for (const std::string& w : sol.report().warnings) CHECK(w.find("z-fighting") == std::string::npos);

      // Dark where nothing can reach: the floor under the box (inset by an element), the box's
      // bottom face, the floor inside the ball and the ball below the floor.
      const double floor_mean = test::leaf_mean(sol, scene, "y0", [](glm::vec3) { return true; });
      auto under_box = [](glm::vec3 c) { return c.x > 0.4f && c.x < 0.8f && c.z > 1.0f && c.z < 1.4f; };
      double area = 0.0;
      const double under = test::leaf_mean(sol, scene, "y0", under_box, false, &area);
      CHECK(area > 0.1);
      const double bottom = test::leaf_mean(sol, scene, "box", [](glm::vec3 c) { return c.y < 1e-4f; });
      const double in_ball = test::leaf_mean(sol, scene, "y0", [](glm::vec3 c) {
        return glm::length(glm::vec2(c.x - 1.4f, c.z - 0.8f)) < 0.27f;  // the cut circle has radius 0.317
      });
      const double ball_below = test::leaf_mean(sol, scene, "ball", [](glm::vec3 c) { return c.y < -0.03f; });
      MESSAGE("floor mean " << floor_mean << "; under the box " << under << ", box bottom " << bottom
                            << ", floor inside the ball " << in_ball << ", ball below the floor " << ball_below);
      CHECK(under < 1e-3 * floor_mean);
      CHECK(in_ball < 1e-3 * floor_mean);
      if (!hierarchical) {
        CHECK(bottom < 1e-3 * floor_mean);
        CHECK(ball_below < 1e-3 * floor_mean);
      } else {
        // The box's bottom (its rays start below the floor it lies on and leave the room) and
        // the ball below the floor (outside the room) are not buried, only out of sight of
        // everything: their light comes from receiving clusters pushed down (measured 1.9e-3
        // and 1.7e-2 of the floor's mean, session 19). The floor under the box and inside the
        // ball are buried and get none.
        CHECK(bottom < 5e-3 * floor_mean);
        CHECK(ball_below < 3e-2 * floor_mean);
      }

      // No bright seam: a patch of floor 3-15 cm outside the box's -x side is no brighter than
      // the path tracer says (it is partly shadowed by the box).
      const double strip = test::leaf_mean(sol, scene, "y0", [](glm::vec3 c) {
        return c.x > 0.15f && c.x < 0.27f && c.z > 1.14f && c.z < 1.26f;
      });
      MESSAGE("strip beside the box: radiosity " << strip);
      // The view a user would look at: radiosity's display against the path tracer, looking
      // down at both props from above the room's middle.
      rad::RenderOptions ro;
      ro.width = 48;
      ro.height = 48;
      ro.spp = 16;
      ro.camera = rad::Camera{{1.0f, 1.8f, 0.1f}, {0.9f, 0.0f, 1.1f}, {0, 1, 0}, 55.0f};
      const rad::Image radiosity_view = rad::render(scene, sol, ro);
      rad::PathTraceOptions po;
      po.width = 48;
      po.height = 48;
      po.spp = 400;
      po.camera = ro.camera;
      static const rad::Image path_view = rad::render_path_traced(scene, po);
      auto blocks = [](const rad::Image& image) {
        rad::Image out(image.width / 4, image.height / 4);
        for (int y = 0; y < out.height * 4; ++y)
          for (int x = 0; x < out.width * 4; ++x) out.at(x / 4, y / 4) += image.at(x, y) / 16.0f;
        return out;
      };
      const double rmse = test::relative_rmse(blocks(radiosity_view), blocks(path_view));
      const double ratio = test::mean_ratio(radiosity_view, path_view);
      MESSAGE("radiosity display vs path tracer: 4x4-block relative RMSE " << rmse << ", mean ratio " << ratio);
      CHECK(rmse < 0.06);
      CHECK(std::fabs(ratio - 1.0) < 0.03);

      // The strip against the path tracer, seen straight from above (a narrow view of it).
      rad::PathTraceOptions strip_view;
      strip_view.width = 8;
      strip_view.height = 8;
      strip_view.spp = 1024;
      strip_view.camera = rad::Camera{{0.21f, 1.0f, 1.2f}, {0.21f, 0.0f, 1.2f}, {0, 0, 1}, 6.87f};
      static const double strip_path = [&] {
        const rad::Image img = rad::render_path_traced(scene, strip_view);
        double sum = 0.0;
        for (const rad::Rgb& px : img.pixels) sum += px.x;
        return pi * sum / static_cast<double>(img.pixels.size());
      }();
      MESSAGE("strip beside the box: path tracer " << strip_path);
      // Hierarchical: its floor along a box's side is too bright (the test above; docs/
      // HIERARCHICAL.md, "Buried parts"): measured +9.8 % (session 22) and +10.9 % since
      // session 23's push took the clusters' directions, which brought the Cornell box's floor
      // beside its blocks from +2.8 % to +1.8 % against Gauss-Seidel; held to 15 %.
      CHECK(strip < (hierarchical ? 1.15 : 1.1) * strip_path);
      CHECK(strip > 0.85 * strip_path);
    }
  }
  TEST_CASE("a house on a large plot casts its shadow: the default mesh is graded toward it, and the shadow's area is the "
            "closed form's") {
    // A 10 x 3 x 10 m black house on a 1 km plot under a low sun. The default elements are
    // 21.7 m across, larger than the house: without the grading (MeshOptions::
    // grade_at_contacts) no ground element lies wholly in the shadow, which is spread over the
    // elements around the house (measured: 0 of them dark, 69 with the grading; the deficit's
    // area 151.1 m^2 and 152.2 m^2).
    // The shadow on the ground is the footprint swept along the sun's offset from the eaves,
    // (3, 2.25) m: 100 + 10 x 3 + 10 x 2.25 = 152.5 m^2, the footprint (buried under the
    // house) included.
    rad::Scene scene;
    rad::Material grass, black;
    grass.name = "grass";
    grass.reflectance = rad::Rgb(0.3f);
    black.name = "house";
    black.reflectance = rad::Rgb(0.0f);
    const rad::MaterialId g = scene.add_material(grass), h = scene.add_material(black);
    scene.add_polygon({{-500, 0, 500}, {500, 0, 500}, {500, 0, -500}, {-500, 0, -500}}, g, "ground");
    rad::add_box(scene, {-5, 0, -5}, {5, 3, 5}, h, "house");
    rad::Light sun;
    sun.type = rad::LightType::directional;
    sun.intensity = 1000.0f;
    sun.direction = {0.4f, -0.4f, 0.3f};
    scene.add_light(sun);
    const double open = 1000.0 * 0.4 / std::sqrt(0.16 + 0.16 + 0.09);  // W/m^2 on open ground
    const rad::Solution sol = rad::solve(scene, rad::SolveOptions{});
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    const rad::PatchHierarchy& mesh = sol.hierarchy();
    const std::vector<rad::Rgb> direct = sol.element_values(rad::Quantity::direct_irradiance);
    const std::vector<float>& exposure = sol.exposure();
    // A point is in the shadow when it lies in the footprint moved back toward the sun by
    // t x (3, 2.25) for some t in [0, 1].
    auto shadowed = [](float x, float z) {
      const float lo = std::max({0.0f, (x - 5.0f) / 3.0f, (z - 5.0f) / 2.25f});
      const float hi = std::min({1.0f, (x + 5.0f) / 3.0f, (z + 5.0f) / 2.25f});
      return lo <= hi;
    };
    double deficit = 0.0, worst_dark = 0.0, worst_lit = 0.0;
    int dark = 0;
    for (std::uint32_t leaf : mesh.leaves()) {
      const rad::Element& e = mesh.element(leaf);
      if (scene.polygons()[mesh.patches()[e.patch].polygon].group != *scene.find_group("ground")) continue;
      const double x = exposure.empty() ? 1.0 : static_cast<double>(exposure[leaf]);
      deficit += (open - static_cast<double>(direct[leaf].y) * x) * static_cast<double>(e.area);
      int inside = 0;
      float lo_x = 1e9f, hi_x = -1e9f, lo_z = 1e9f, hi_z = -1e9f;
      for (int c = 0; c < e.corner_count(); ++c) {
        const glm::vec3 v = mesh.vertices()[e.corners[static_cast<std::size_t>(c)]];
        inside += shadowed(v.x, v.z) ? 1 : 0;
        lo_x = std::min(lo_x, v.x), hi_x = std::max(hi_x, v.x), lo_z = std::min(lo_z, v.z), hi_z = std::max(hi_z, v.z);
      }
      const bool beside = lo_x >= 5.0f || hi_x <= -5.0f || lo_z >= 5.0f || hi_z <= -5.0f;  // outside the footprint
      const double share = static_cast<double>(direct[leaf].y) / open;
      if (inside == e.corner_count() && beside) {
        ++dark;
        worst_dark = std::max(worst_dark, share);
      } else if (inside == 0 && beside && lo_x > -20.0f && hi_x < 20.0f && lo_z > -20.0f && hi_z < 20.0f) {
        worst_lit = std::max(worst_lit, std::fabs(share - 1.0));  // near the house, in the sun
      }
    }
    MESSAGE("ground elements wholly in the shadow: " << dark << " (the brightest at " << worst_dark
                                                     << " of the open ground's light); lit ones near the house off by "
                                                     << worst_lit << "; deficit " << deficit / open << " m^2");
    CHECK(dark >= 5);
    CHECK(worst_dark < 0.01);
    CHECK(worst_lit < 0.01);
    CHECK(deficit / open == doctest::Approx(152.5).epsilon(0.03));
  }

  TEST_CASE("a turned building on exported ground triangles: its feet cut the ground, and no dark wedges along them") {
    // Its feet cross the ground's triangles at 27 degrees, facet by facet, and its corners stand
    // inside triangles: every foot ends inside the triangle it stands on. Before the mesher cut
    // such triangles along the feet (chains of contact segments from border to border,
    // scene/overlap.cpp), they were meshed whole, partly under the building; the solvers take a
    // leaf under kMinExposure open as wholly open, so a triangle with a sliver beside the
    // building showed at a tenth of its light, and the vertex values interpolated it across
    // the ground (session 40: dark wedges at every turned building's feet in
    // exported_block.py --turn). Measured on the old code: 54 ground leaves partly under the
    // building, and open leaves' corners at 0 (a leaf less than kMinExposure open is taken as
    // open, its light diluted by the part under the building); now 7, the darkest corner at
    // 0.67 of the open ground's radiosity.
    const rad::Scene scene = turned_building(27.0f, {0.7f, 0.0f, 1.3f});
    const rad::Solution sol = rad::solve(scene, rad::SolveOptions{});
    REQUIRE(sol.status() == rad::SolveStatus::converged);
    const rad::PatchHierarchy& mesh = sol.hierarchy();
    const std::vector<float>& exposure = sol.exposure();
    REQUIRE(!exposure.empty());
    const rad::GroupId ground = *scene.find_group("ground");
    const std::vector<rad::Rgb> at_vertex = sol.vertex_radiosity();
    int partly = 0, partly_large = 0, buried = 0;
    double darkest = 1e30;
    for (std::uint32_t leaf : mesh.leaves()) {
      const rad::Element& e = mesh.element(leaf);
      if (scene.polygons()[mesh.patches()[e.patch].polygon].group != ground) continue;
      if (exposure[leaf] == 0.0f) {
        ++buried;
        continue;
      }
      if (exposure[leaf] != 1.0f) {
        ++partly;
        partly_large += e.area > 0.5f ? 1 : 0;
      }
      for (int c = 0; c < e.corner_count(); ++c)
        darkest = std::min(darkest, static_cast<double>(at_vertex[e.corners[static_cast<std::size_t>(c)]].y));
    }
    // Open ground: rho x 100 = 50 W/m^2. At the foot of a 6 m wall a point sees at least half
    // the sky (the building is convex) and the lit wall: over 0.5 x (50 + 12) = 31 W/m^2.
    const double open = 50.0;
    MESSAGE("ground leaves under the building " << buried << ", partly under it " << partly << " (" << partly_large
                                                << " of them over 0.5 m^2); the darkest corner of an open ground leaf at "
                                                << darkest / open << " of the open ground's radiosity");
    // What stays partly under it: graded leaves (0.22 m^2) where a corner clips a triangle
    // with feet shorter than a quarter of its diameter (scene/overlap.cpp, kMinDividingChain).
    // (The old code's 54 were graded too: the count, not their size, tells the two apart.)
    CHECK(partly_large == 0);
    CHECK(partly < 16);
    CHECK(buried > 0);
    CHECK(darkest > 0.45 * open);
  }
}

