// The JSON scene format (docs/SCENE_JSON.md): materials with any reflection model of brdf.hpp,
// explicit polygons, the shape helpers of scene.hpp, OBJ includes, lights and a camera.
//
// nlohmann-json parses the text; this file walks the document and checks every value itself, so
// that each error names the document path of the offending value ("materials[2].brdf.alpha_x")
// and a misspelt key is an error instead of a silently used default.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "io/readers/reader_files.hpp"
#include "io/readers/reader_warnings.hpp"
#include "io/readers/readers.hpp"
#include "radiosity/brdf.hpp"
#include "radiosity/io.hpp"

namespace radiosity {
namespace detail {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

constexpr int kFormatVersion = 1;

std::string rgb_text(const Rgb& c) {
  std::ostringstream s;
  s << '[' << c.x << ", " << c.y << ", " << c.z << ']';
  return s.str();
}

std::string key_path(const std::string& loc, const char* key) { return loc.empty() ? key : loc + "." + key; }
std::string index_path(const std::string& loc, std::size_t i) { return loc + "[" + std::to_string(i) + "]"; }

/// A key that occurs twice in one object: nlohmann-json would keep the last silently, which
/// hides a pasted-over value as surely as a typo.
struct DuplicateKey {
  std::string path;
};

/// Parser callback state that tracks the document path and throws DuplicateKey.
class DuplicateKeyCheck {
 public:
  bool operator()(int /*depth*/, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        next_element();
        frames_.push_back({event == json::parse_event_t::object_start, {}, {}, static_cast<std::size_t>(-1)});
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!frames_.empty()) frames_.pop_back();
        break;
      case json::parse_event_t::key: {
        Frame& top = frames_.back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second) throw DuplicateKey{path()};
        break;
      }
      case json::parse_event_t::value:
        next_element();
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;    ///< objects: the key being read
    std::size_t index;  ///< arrays: the element being read
  };
  void next_element() {
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
  }
  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) p = f.object ? key_path(p, f.key.c_str()) : index_path(p, f.index);
    return p;
  }
  std::vector<Frame> frames_;
};

/// Walks one parsed document. Every accessor takes the value's document path for messages.
class SceneReader {
 public:
  SceneReader(std::string source, fs::path base_dir, const LoadOptions& options)
      : source_(std::move(source)), base_dir_(std::move(base_dir)), options_(options), warnings_(options.strict) {}

  Scene read(const json& root);

 private:
  [[noreturn]] void fail(ErrorCode code, const std::string& loc, const std::string& problem) const {
    throw Error(code, source_ + ": " + (loc.empty() ? std::string("top level") : loc) + ": " + problem);
  }
  /// Re-throws an error of a library call with the document path in front, keeping its code
  /// (invalid_argument becomes invalid_scene: in a file, a bad value is a bad scene).
  [[noreturn]] void rethrow(const Error& e, const std::string& loc) const {
    fail(e.code() == ErrorCode::invalid_argument ? ErrorCode::invalid_scene : e.code(), loc, e.what());
  }

  void expect_type(const json& j, const std::string& loc, bool ok, const char* expected) const {
    if (!ok) fail(ErrorCode::parse_error, loc, std::string("expected ") + expected + ", got " + j.type_name());
  }

  /// Checks that `j` is an object whose keys are all in `allowed` ("comment" is always allowed).
  void object(const json& j, const std::string& loc, std::initializer_list<const char*> allowed) const {
    expect_type(j, loc, j.is_object(), "an object");
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (it.key() == "comment") continue;
      bool known = false;
      for (const char* a : allowed) known = known || it.key() == a;
      if (known) continue;
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      fail(ErrorCode::parse_error, key_path(loc, it.key().c_str()), "unknown key (expected one of: " + list + ")");
    }
  }

  static const json* find(const json& obj, const char* key) {
    auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }
  const json& require(const json& obj, const std::string& loc, const char* key) const {
    const json* j = find(obj, key);
    if (!j) fail(ErrorCode::parse_error, key_path(loc, key), "missing (required)");
    return *j;
  }

  float number(const json& j, const std::string& loc) const {
    expect_type(j, loc, j.is_number(), "a number");
    const double v = j.get<double>();
    if (!std::isfinite(v) || std::fabs(v) > static_cast<double>(FLT_MAX))
      fail(ErrorCode::invalid_scene, loc, "must be a finite number within float range (got " + number_text(v) + ")");
    return static_cast<float>(v);
  }
  float positive(const json& j, const std::string& loc) const {
    const float v = number(j, loc);
    if (!(v > 0.0f)) fail(ErrorCode::invalid_scene, loc, "must be > 0 (got " + number_text(v) + ")");
    return v;
  }
  float non_negative(const json& j, const std::string& loc) const {
    const float v = number(j, loc);
    if (v < 0.0f) fail(ErrorCode::invalid_scene, loc, "must be >= 0 (got " + number_text(v) + ")");
    return v;
  }
  float fraction(const json& j, const std::string& loc) const {
    const float v = number(j, loc);
    if (v < 0.0f || v > 1.0f) fail(ErrorCode::invalid_scene, loc, "must be in [0, 1] (got " + number_text(v) + ")");
    return v;
  }
  int integer(const json& j, const std::string& loc) const {
    expect_type(j, loc, j.is_number_integer(), "an integer");
    const double v = j.get<double>();
    if (v < -1e9 || v > 1e9) fail(ErrorCode::invalid_scene, loc, "out of range (got " + number_text(v) + ")");
    return static_cast<int>(j.get<long long>());
  }
  std::string string(const json& j, const std::string& loc) const {
    expect_type(j, loc, j.is_string(), "a string");
    return j.get<std::string>();
  }
  bool boolean(const json& j, const std::string& loc) const {
    expect_type(j, loc, j.is_boolean(), "true or false");
    return j.get<bool>();
  }
  glm::vec3 vec3(const json& j, const std::string& loc) const {
    expect_type(j, loc, j.is_array() && j.size() == 3, "an array of 3 numbers");
    return {number(j[0], index_path(loc, 0)), number(j[1], index_path(loc, 1)), number(j[2], index_path(loc, 2))};
  }
  /// A colour: [r, g, b] or one number for grey.
  Rgb colour(const json& j, const std::string& loc) const {
    if (j.is_number()) return Rgb(number(j, loc));
    expect_type(j, loc, j.is_array() && j.size() == 3, "a number or an array of 3 numbers");
    return vec3(j, loc);
  }
  /// A colour with every channel in [0, upper] (or [0, upper) when `open`).
  Rgb bounded_colour(const json& j, const std::string& loc, float upper, bool open) const {
    const Rgb c = colour(j, loc);
    for (int k = 0; k < 3; ++k)
      if (c[k] < 0.0f || (open ? c[k] >= upper : c[k] > upper))
        fail(ErrorCode::invalid_scene, loc,
             "each channel must be in [0, " + number_text(upper) + (open ? ")" : "]") + " (got " + rgb_text(c) + ")");
    return c;
  }
  Rgb optional_colour(const json& obj, const std::string& loc, const char* key, Rgb fallback, float upper,
                      bool open) const {
    const json* j = find(obj, key);
    return j ? bounded_colour(*j, key_path(loc, key), upper, open) : fallback;
  }
  void check_sum(const Rgb& sum, const std::string& loc, const char* what, float upper, bool open) const {
    for (int k = 0; k < 3; ++k)
      if (open ? sum[k] >= upper : sum[k] > upper)
        fail(ErrorCode::invalid_scene, loc,
             std::string(what) + " must be " + (open ? "< " : "<= ") + number_text(upper) + " in every channel (got " +
                 rgb_text(sum) + ")");
  }
  fs::path file_path(const json& j, const std::string& loc) const {
    const std::string s = string(j, loc);
    if (s.empty()) fail(ErrorCode::parse_error, loc, "must not be empty");
    const fs::path p = fs::u8path(s);
    return p.is_absolute() ? p : base_dir_ / p;
  }

  /// A reflection model; `diffuse` receives the part that behaves as ideal diffuse reflection
  /// (the default of Material::reflectance for the radiosity pass).
  std::shared_ptr<const Brdf> brdf(const json& j, const std::string& loc, Rgb& diffuse) const;
  void camera(const json& j, Scene& scene) const;
  void materials(const json& j, Scene& scene);
  void lights(const json& j, Scene& scene) const;
  void surface(const json& j, const std::string& loc, Scene& scene) const;
  glm::mat4 transform(const json& j, const std::string& loc) const;
  MaterialId material_ref(const json& obj, const std::string& loc) const;
  void include_obj(const json& j, const std::string& loc, Scene& scene) const;

  /// A material's radiosity reflectance: [0, 1) per channel; 1 or more is clamped to 0.99
  /// under the forgiving policy (exported scenes say "white" as 1).
  Rgb reflectance(const json& j, const std::string& loc) const {
    const Rgb c = colour(j, loc);
    if (c.x < 0.0f || c.y < 0.0f || c.z < 0.0f)
      fail(ErrorCode::invalid_scene, loc, "each channel must be in [0, 1) (got " + rgb_text(c) + ")");
    const Rgb out = glm::min(c, Rgb(kMaxForgivenAlbedo));
    for (int k = 0; k < 3; ++k)
      if (c[k] >= 1.0f) {
        warnings_.forgive("reflectance >= 1", ErrorCode::invalid_scene, source_ + ": " + loc,
                          "each channel must be in [0, 1) (got " + rgb_text(c) + ")", "clamped to " + rgb_text(out));
        return out;
      }
    return c;
  }

  std::string source_;
  fs::path base_dir_;
  LoadOptions options_;
  /// Filled while reading (also from the const members that add surfaces), moved into the scene.
  mutable ReaderWarnings warnings_;
  std::map<std::string, MaterialId> material_ids_;
  std::vector<std::string> material_names_;
};

std::shared_ptr<const Brdf> SceneReader::brdf(const json& j, const std::string& loc, Rgb& diffuse) const {
  expect_type(j, loc, j.is_object(), "an object");
  const std::string type = string(require(j, loc, "type"), key_path(loc, "type"));
  auto call = [&](auto make) -> std::shared_ptr<const Brdf> {
    try {
      return make();
    } catch (const Error& e) {
      rethrow(e, loc);
    }
  };
  // The diffuse and specular parts of the lobe models must not add up to more than all light.
  auto lobe_parts = [&](Rgb& d, Rgb& s) {
    d = optional_colour(j, loc, "diffuse", Rgb(0.0f), 1.0f, false);
    s = bounded_colour(require(j, loc, "specular"), key_path(loc, "specular"), 1.0f, false);
    check_sum(d + s, loc, "diffuse + specular", 1.0f, false);
    diffuse = d;
  };

  if (type == "lambertian") {
    object(j, loc, {"type", "reflectance"});
    const Rgb r = bounded_colour(require(j, loc, "reflectance"), key_path(loc, "reflectance"), 1.0f, false);
    diffuse = r;
    return call([&] { return make_lambertian(r); });
  }
  if (type == "phong" || type == "blinn_phong") {
    object(j, loc, {"type", "diffuse", "specular", "exponent"});
    Rgb d, s;
    lobe_parts(d, s);
    const float n = non_negative(require(j, loc, "exponent"), key_path(loc, "exponent"));
    return call([&] { return type == "phong" ? make_phong(d, s, n) : make_blinn_phong(d, s, n); });
  }
  if (type == "ward") {
    object(j, loc, {"type", "diffuse", "specular", "alpha_x", "alpha_y"});
    Rgb d, s;
    lobe_parts(d, s);
    const float ax = positive(require(j, loc, "alpha_x"), key_path(loc, "alpha_x"));
    const float ay = positive(require(j, loc, "alpha_y"), key_path(loc, "alpha_y"));
    return call([&] { return make_ward(d, s, ax, ay); });
  }
  if (type == "microfacet") {
    object(j, loc, {"type", "f0", "roughness", "roughness_x", "roughness_y"});
    const Rgb f0 = bounded_colour(require(j, loc, "f0"), key_path(loc, "f0"), 1.0f, false);
    float rx = 0.0f, ry = 0.0f;
    if (const json* r = find(j, "roughness")) {
      if (find(j, "roughness_x") || find(j, "roughness_y"))
        fail(ErrorCode::parse_error, loc, "give either roughness or roughness_x and roughness_y, not both");
      rx = ry = positive(*r, key_path(loc, "roughness"));
    } else {
      if (!find(j, "roughness_x") && !find(j, "roughness_y"))
        fail(ErrorCode::parse_error, key_path(loc, "roughness"), "missing (required, or roughness_x and roughness_y)");
      rx = positive(require(j, loc, "roughness_x"), key_path(loc, "roughness_x"));
      ry = positive(require(j, loc, "roughness_y"), key_path(loc, "roughness_y"));
    }
    diffuse = Rgb(0.0f);
    return call([&] { return make_microfacet(f0, rx, ry); });
  }
  if (type == "mirror") {
    object(j, loc, {"type", "reflectance"});
    const Rgb r = bounded_colour(require(j, loc, "reflectance"), key_path(loc, "reflectance"), 1.0f, false);
    diffuse = Rgb(0.0f);
    return call([&] { return make_mirror(r); });
  }
  if (type == "dielectric") {
    object(j, loc, {"type", "eta", "tint"});
    const float eta = positive(require(j, loc, "eta"), key_path(loc, "eta"));
    const Rgb tint = optional_colour(j, loc, "tint", Rgb(1.0f), 1.0f, false);
    diffuse = Rgb(0.0f);
    return call([&] { return make_dielectric(eta, tint); });
  }
  if (type == "measured") {
    object(j, loc, {"type", "file"});
    const fs::path file = file_path(require(j, loc, "file"), key_path(loc, "file"));
    std::shared_ptr<const Brdf> b = call([&] { return load_measured(file); });
    // Its albedo at normal incidence stands in for the diffuse reflectance of the first pass.
    diffuse = b->albedo(glm::vec3(0.0f, 0.0f, 1.0f));
    return b;
  }
  if (type == "mix") {
    object(j, loc, {"type", "first", "second", "weight"});
    Rgb d1(0.0f), d2(0.0f);
    std::shared_ptr<const Brdf> first = brdf(require(j, loc, "first"), key_path(loc, "first"), d1);
    std::shared_ptr<const Brdf> second = brdf(require(j, loc, "second"), key_path(loc, "second"), d2);
    const float w = fraction(require(j, loc, "weight"), key_path(loc, "weight"));
    diffuse = (1.0f - w) * d1 + w * d2;
    return call([&] { return make_mix(first, second, w); });
  }
  fail(ErrorCode::parse_error, key_path(loc, "type"),
       "unknown model '" + type +
           "' (expected lambertian, phong, blinn_phong, ward, microfacet, mirror, dielectric, measured or mix)");
}

void SceneReader::camera(const json& j, Scene& scene) const {
  const std::string loc = "camera";
  object(j, loc, {"eye", "look_at", "up", "fov_deg"});
  Camera c;
  c.eye = vec3(require(j, loc, "eye"), key_path(loc, "eye"));
  c.look_at = vec3(require(j, loc, "look_at"), key_path(loc, "look_at"));
  if (const json* up = find(j, "up")) c.up = vec3(*up, key_path(loc, "up"));
  if (const json* fov = find(j, "fov_deg")) {
    c.fov_deg = number(*fov, key_path(loc, "fov_deg"));
    if (!(c.fov_deg > 0.0f && c.fov_deg < 180.0f))
      fail(ErrorCode::invalid_scene, key_path(loc, "fov_deg"), "must be in (0, 180) (got " + number_text(c.fov_deg) + ")");
  }
  try {
    scene.set_camera(c);
  } catch (const Error& e) {
    rethrow(e, loc);
  }
}

void SceneReader::lights(const json& j, Scene& scene) const {
  expect_type(j, "lights", j.is_array(), "an array");
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string loc = index_path("lights", i);
    const json& l = j[i];
    expect_type(l, loc, l.is_object(), "an object");
    const std::string type = string(require(l, loc, "type"), key_path(loc, "type"));
    Light light;
    // Each type takes only the keys that mean something for it, so a misplaced one is an error.
    if (type == "point") {
      light.type = LightType::point;
      object(l, loc, {"type", "name", "light_group", "color", "intensity", "position"});
    } else if (type == "spot") {
      light.type = LightType::spot;
      object(l, loc, {"type", "name", "light_group", "color", "intensity", "position", "direction", "inner_cone_deg",
                      "outer_cone_deg"});
    } else if (type == "directional") {
      light.type = LightType::directional;
      object(l, loc, {"type", "name", "light_group", "color", "intensity", "direction"});
    } else if (type == "sky") {
      light.type = LightType::sky;
      object(l, loc, {"type", "name", "light_group", "color", "intensity", "zenith", "model"});
    } else {
      fail(ErrorCode::parse_error, key_path(loc, "type"),
           "unknown light type '" + type + "' (expected point, spot, directional or sky)");
    }
    if (const json* n = find(l, "name")) light.name = string(*n, key_path(loc, "name"));
    if (const json* g = find(l, "light_group")) light.light_group = string(*g, key_path(loc, "light_group"));
    if (const json* c = find(l, "color")) {
      light.color = colour(*c, key_path(loc, "color"));
      if (light.color.x < 0.0f || light.color.y < 0.0f || light.color.z < 0.0f)
        fail(ErrorCode::invalid_scene, key_path(loc, "color"), "each channel must be >= 0 (got " + rgb_text(light.color) + ")");
    }
    // Radiometric as written (W/sr, W/m^2); candela and lux with LoadOptions::photometric.
    light.intensity = non_negative(require(l, loc, "intensity"), key_path(loc, "intensity"));
    if (options_.photometric) light.intensity = photometric_to_radiometric(light.intensity);
    if (light.type == LightType::point || light.type == LightType::spot)
      light.position = vec3(require(l, loc, "position"), key_path(loc, "position"));
    auto unit = [&](const char* key, bool required) {
      const json* d = required ? &require(l, loc, key) : find(l, key);
      if (!d) return;
      light.direction = vec3(*d, key_path(loc, key));
      if (light.direction == glm::vec3(0.0f)) fail(ErrorCode::invalid_scene, key_path(loc, key), "must not be [0, 0, 0]");
    };
    if (light.type == LightType::spot || light.type == LightType::directional) unit("direction", true);
    if (light.type == LightType::sky) unit("zenith", false);
    if (light.type == LightType::spot) {
      if (const json* c = find(l, "inner_cone_deg")) light.inner_cone_deg = number(*c, key_path(loc, "inner_cone_deg"));
      if (const json* c = find(l, "outer_cone_deg")) light.outer_cone_deg = number(*c, key_path(loc, "outer_cone_deg"));
      if (!(light.inner_cone_deg >= 0.0f && light.inner_cone_deg <= light.outer_cone_deg &&
            light.outer_cone_deg <= 90.0f))
        fail(ErrorCode::invalid_scene, key_path(loc, find(l, "inner_cone_deg") ? "inner_cone_deg" : "outer_cone_deg"),
             "cones must satisfy 0 <= inner_cone_deg <= outer_cone_deg <= 90 (got " + number_text(light.inner_cone_deg) +
                 " and " + number_text(light.outer_cone_deg) + ")");
    }
    if (const json* m = find(l, "model")) {
      const std::string model = string(*m, key_path(loc, "model"));
      if (model == "uniform")
        light.sky = SkyModel::uniform;
      else if (model == "cie_overcast")
        light.sky = SkyModel::cie_overcast;
      else
        fail(ErrorCode::parse_error, key_path(loc, "model"),
             "unknown sky model '" + model + "' (expected uniform or cie_overcast)");
    }
    try {
      scene.add_light(light);
    } catch (const Error& e) {
      rethrow(e, loc);
    }
  }
}

void SceneReader::materials(const json& j, Scene& scene) {
  expect_type(j, "materials", j.is_array(), "an array");
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string loc = index_path("materials", i);
    const json& m = j[i];
    object(m, loc,
           {"name", "emission", "radiance", "reflectance", "specular", "specular_exponent", "transmittance", "ior",
            "diffuse_transmittance", "two_sided", "brdf"});
    Material mat;
    mat.name = string(require(m, loc, "name"), key_path(loc, "name"));
    if (mat.name.empty()) fail(ErrorCode::parse_error, key_path(loc, "name"), "must not be empty");
    if (material_ids_.count(mat.name))
      fail(ErrorCode::parse_error, key_path(loc, "name"), "duplicate material name '" + mat.name + "'");

    // Emission is the exitance E of Material; `radiance` is the same for a Lambertian emitter
    // given as its radiance L (E = pi L), as the published Cornell box quotes it.
    const json* emission = find(m, "emission");
    const json* radiance = find(m, "radiance");
    if (emission && radiance) fail(ErrorCode::parse_error, loc, "give either emission or radiance, not both");
    auto non_negative_colour = [&](const json& c, const std::string& where) {
      const Rgb v = colour(c, where);
      if (v.x < 0.0f || v.y < 0.0f || v.z < 0.0f)
        fail(ErrorCode::invalid_scene, where, "each channel must be >= 0 (got " + rgb_text(v) + ")");
      return v;
    };
    if (emission) mat.emission = non_negative_colour(*emission, key_path(loc, "emission"));
    if (radiance) mat.emission = glm::pi<float>() * non_negative_colour(*radiance, key_path(loc, "radiance"));

    Rgb brdf_diffuse(0.0f);
    if (const json* b = find(m, "brdf")) mat.brdf = brdf(*b, key_path(loc, "brdf"), brdf_diffuse);
    if (const json* r = find(m, "reflectance")) {
      mat.reflectance = reflectance(*r, key_path(loc, "reflectance"));
    } else if (mat.brdf) {
      for (int k = 0; k < 3; ++k)
        if (brdf_diffuse[k] >= 1.0f)
          fail(ErrorCode::invalid_scene, key_path(loc, "brdf"),
               "its diffuse part " + rgb_text(brdf_diffuse) +
                   " would be the radiosity reflectance, which must be < 1; give reflectance explicitly");
      mat.reflectance = brdf_diffuse;
    }
    mat.specular = optional_colour(m, loc, "specular", mat.specular, 1.0f, false);
    if (const json* e = find(m, "specular_exponent"))
      mat.specular_exponent = non_negative(*e, key_path(loc, "specular_exponent"));
    mat.transmittance = optional_colour(m, loc, "transmittance", mat.transmittance, 1.0f, false);
    if (const json* ior = find(m, "ior")) mat.ior = positive(*ior, key_path(loc, "ior"));
    mat.diffuse_transmittance = optional_colour(m, loc, "diffuse_transmittance", mat.diffuse_transmittance, 1.0f, false);
    if (const json* t = find(m, "two_sided")) mat.two_sided = boolean(*t, key_path(loc, "two_sided"));
    // The parts that leave the surface in pass 1 must stay below 1; forgiven by scaling the
    // specular and diffuse transmittance down, as the OBJ reader scales Ks.
    const Rgb sum = mat.reflectance + mat.specular + mat.diffuse_transmittance;
    float scale = 1.0f;
    for (int k = 0; k < 3; ++k) {
      const float rest = mat.specular[k] + mat.diffuse_transmittance[k];
      if (sum[k] >= 1.0f && rest > 0.0f) scale = std::min(scale, std::max(0.0f, (kMaxForgivenAlbedo - mat.reflectance[k]) / rest));
    }
    if (scale < 1.0f) {
      warnings_.forgive("reflectance sum >= 1", ErrorCode::invalid_scene, source_ + ": " + loc,
                        "reflectance + specular + diffuse_transmittance must be < 1 in every channel (got " +
                            rgb_text(sum) + ")",
                        "specular and diffuse_transmittance scaled by " + number_text(scale));
      mat.specular *= scale;
      mat.diffuse_transmittance *= scale;
    }

    MaterialId id = 0;
    try {
      id = scene.add_material(mat);
    } catch (const Error& e) {
      rethrow(e, loc);
    }
    material_ids_.emplace(mat.name, id);
    material_names_.push_back(mat.name);
  }
}

MaterialId SceneReader::material_ref(const json& obj, const std::string& loc) const {
  const std::string where = key_path(loc, "material");
  const std::string name = string(require(obj, loc, "material"), where);
  auto it = material_ids_.find(name);
  if (it != material_ids_.end()) return it->second;
  std::string known;
  for (const std::string& n : material_names_) known += (known.empty() ? "" : ", ") + n;
  fail(ErrorCode::parse_error, where,
       "unknown material '" + name + "' (" + (known.empty() ? "no materials are defined" : "defined: " + known) + ")");
}

glm::mat4 SceneReader::transform(const json& j, const std::string& loc) const {
  object(j, loc, {"matrix", "scale", "rotate_deg", "translate"});
  if (const json* m = find(j, "matrix")) {
    if (find(j, "scale") || find(j, "rotate_deg") || find(j, "translate"))
      fail(ErrorCode::parse_error, loc, "give either matrix or scale/rotate_deg/translate, not both");
    const std::string mloc = key_path(loc, "matrix");
    expect_type(*m, mloc, m->is_array() && m->size() == 4, "an array of 4 rows");
    glm::mat4 out(1.0f);
    for (std::size_t r = 0; r < 4; ++r) {
      const json& row = (*m)[r];
      const std::string rloc = index_path(mloc, r);
      expect_type(row, rloc, row.is_array() && row.size() == 4, "an array of 4 numbers");
      for (std::size_t c = 0; c < 4; ++c) out[static_cast<int>(c)][static_cast<int>(r)] = number(row[c], index_path(rloc, c));
    }
    if (out[0][3] != 0.0f || out[1][3] != 0.0f || out[2][3] != 0.0f || out[3][3] != 1.0f)
      fail(ErrorCode::invalid_scene, index_path(mloc, 3), "the last row must be [0, 0, 0, 1] (affine)");
    return out;
  }
  glm::vec3 scale(1.0f), rotate(0.0f), translate(0.0f);
  if (const json* s = find(j, "scale")) {
    const std::string sloc = key_path(loc, "scale");
    scale = s->is_number() ? glm::vec3(number(*s, sloc)) : vec3(*s, sloc);
    for (int k = 0; k < 3; ++k)
      if (scale[k] == 0.0f) fail(ErrorCode::invalid_scene, sloc, "must not be 0 in any axis");
  }
  if (const json* r = find(j, "rotate_deg")) rotate = vec3(*r, key_path(loc, "rotate_deg"));
  if (const json* t = find(j, "translate")) translate = vec3(*t, key_path(loc, "translate"));
  // p' = T Rz Ry Rx S p: scale, then rotate about x, y, z (degrees), then translate.
  glm::mat4 m = glm::translate(glm::mat4(1.0f), translate);
  m = glm::rotate(m, glm::radians(rotate.z), glm::vec3(0, 0, 1));
  m = glm::rotate(m, glm::radians(rotate.y), glm::vec3(0, 1, 0));
  m = glm::rotate(m, glm::radians(rotate.x), glm::vec3(1, 0, 0));
  return glm::scale(m, scale);
}

void SceneReader::include_obj(const json& j, const std::string& loc, Scene& scene) const {
  object(j, loc, {"type", "file"});
  const fs::path file = file_path(require(j, loc, "file"), key_path(loc, "file"));
  Scene obj;
  try {
    // In the JSON scene's coordinates, which have no local origin (Scene::origin()): an OBJ
    // moved to one of its own would be placed wrongly.
    LoadOptions as_written = options_;
    as_written.local_origin = false;
    obj = load_obj(file, as_written);
  } catch (const Error& e) {
    fail(e.code(), key_path(loc, "file"), e.what());
  }
  // The OBJ's materials keep their own ids (its names may repeat the JSON's; they are separate).
  std::vector<MaterialId> ids;
  for (const Material& m : obj.materials()) ids.push_back(scene.add_material(m));
  for (const Polygon& p : obj.polygons()) scene.add_polygon(p.vertices, ids[p.material], obj.groups()[p.group]);
  for (const std::string& w : obj.warnings()) scene.add_warning(w);
}

void SceneReader::surface(const json& j, const std::string& loc, Scene& scene) const {
  expect_type(j, loc, j.is_object(), "an object");
  const std::string type = string(require(j, loc, "type"), key_path(loc, "type"));
  if (type == "obj") {
    include_obj(j, loc, scene);
    return;
  }
  auto group = [&]() -> std::string {
    const json* g = find(j, "group");
    return g ? string(*g, key_path(loc, "group")) : std::string();
  };
  // Under strict, what Scene would only warn about (a polygon triangulated) is an error too.
  auto refuse_new_warning = [&](std::size_t warnings_before) {
    if (options_.strict && scene.warnings().size() > warnings_before)
      fail(ErrorCode::invalid_scene, loc, scene.warnings()[warnings_before]);
  };
  // Scene's own error placed at the surface.
  auto add = [&](auto build) {
    const std::size_t warnings_before = scene.warnings().size();
    try {
      build();
    } catch (const Error& e) {
      rethrow(e, loc);
    }
    refuse_new_warning(warnings_before);
  };
  // Scene's own error escapes unchanged, for the caller to forgive.
  auto add_strict = [&](auto build) {
    const std::size_t warnings_before = scene.warnings().size();
    build();
    refuse_new_warning(warnings_before);
  };

  if (type == "polygon") {
    object(j, loc, {"type", "vertices", "material", "group"});
    const json& v = require(j, loc, "vertices");
    const std::string vloc = key_path(loc, "vertices");
    expect_type(v, vloc, v.is_array() && v.size() >= 3, "an array of at least 3 points");
    std::vector<glm::vec3> points;
    for (std::size_t i = 0; i < v.size(); ++i) points.push_back(vec3(v[i], index_path(vloc, i)));
    const MaterialId m = material_ref(j, loc);
    const std::string g = group();
    // A degenerate polygon is dropped (vertices are finite here, so that is all Scene refuses).
    try {
      add_strict([&] { scene.add_polygon(points, m, g); });
    } catch (const Error& e) {
      if (e.code() != ErrorCode::invalid_scene) throw;
      warnings_.forgive("degenerate polygon", e.code(), source_ + ": " + loc, e.what(), "dropped");
    }
  } else if (type == "quad") {
    object(j, loc, {"type", "origin", "edge_u", "edge_v", "material", "group"});
    const glm::vec3 o = vec3(require(j, loc, "origin"), key_path(loc, "origin"));
    const glm::vec3 u = vec3(require(j, loc, "edge_u"), key_path(loc, "edge_u"));
    const glm::vec3 w = vec3(require(j, loc, "edge_v"), key_path(loc, "edge_v"));
    const MaterialId m = material_ref(j, loc);
    const std::string g = group();
    add([&] { add_quad(scene, o, u, w, m, g); });
  } else if (type == "box") {
    object(j, loc, {"type", "lower", "upper", "transform", "material", "group"});
    const glm::vec3 lo = vec3(require(j, loc, "lower"), key_path(loc, "lower"));
    const glm::vec3 hi = vec3(require(j, loc, "upper"), key_path(loc, "upper"));
    for (int k = 0; k < 3; ++k)
      if (!(lo[k] < hi[k]))
        fail(ErrorCode::invalid_scene, key_path(loc, "upper"), "must be above lower in every coordinate (got upper " +
                                                                   rgb_text(hi) + ", lower " + rgb_text(lo) + ")");
    glm::mat4 t(1.0f);
    if (const json* tj = find(j, "transform")) t = transform(*tj, key_path(loc, "transform"));
    const MaterialId m = material_ref(j, loc);
    const std::string g = group();
    add([&] { add_box(scene, lo, hi, m, g, t); });
  } else if (type == "sphere") {
    object(j, loc, {"type", "centre", "radius", "segments", "material", "group"});
    const glm::vec3 c = vec3(require(j, loc, "centre"), key_path(loc, "centre"));
    const float r = positive(require(j, loc, "radius"), key_path(loc, "radius"));
    int segments = 32;
    if (const json* s = find(j, "segments")) {
      segments = integer(*s, key_path(loc, "segments"));
      if (segments < 4 || segments > 1024)
        fail(ErrorCode::invalid_scene, key_path(loc, "segments"), "must be in [4, 1024] (got " + std::to_string(segments) + ")");
    }
    const MaterialId m = material_ref(j, loc);
    const std::string g = group();
    add([&] { add_sphere(scene, c, r, m, g, segments); });
  } else {
    fail(ErrorCode::parse_error, key_path(loc, "type"),
         "unknown surface type '" + type + "' (expected polygon, quad, box, sphere or obj)");
  }
}

Scene SceneReader::read(const json& root) {
  object(root, "", {"version", "camera", "materials", "surfaces", "lights"});
  // Required, so that a file of a later version is never read as this one; the message says
  // what to write (a first file written by hand lacks it).
  if (!find(root, "version"))
    fail(ErrorCode::parse_error, "version",
         "missing (required: the format version; this library reads " + std::to_string(kFormatVersion) +
             ", so begin the object with \"version\": " + std::to_string(kFormatVersion) + ")");
  const json& version = require(root, "", "version");
  if (!version.is_number_integer() || version.get<long long>() != kFormatVersion)
    fail(ErrorCode::parse_error, "version",
         "unsupported format version " + version.dump() + " (this library reads " + std::to_string(kFormatVersion) + ")");
  Scene scene;
  if (const json* m = find(root, "materials")) materials(*m, scene);
  const json& surfaces = require(root, "", "surfaces");
  expect_type(surfaces, "surfaces", surfaces.is_array(), "an array");
  for (std::size_t i = 0; i < surfaces.size(); ++i) surface(surfaces[i], index_path("surfaces", i), scene);
  if (scene.polygons().empty()) fail(ErrorCode::invalid_scene, "surfaces", "the scene has no polygons");
  if (const json* c = find(root, "camera")) camera(*c, scene);
  if (const json* l = find(root, "lights")) lights(*l, scene);
  warnings_.move_to(scene);
  return scene;
}

}  // namespace

Scene load_scene_json(const fs::path& path, const LoadOptions& options) {
  return parse_scene_json(read_file(path, "JSON scene"), path.parent_path(), path.string(), options);
}

}  // namespace detail

inline namespace v1 {

Scene parse_scene_json(std::string_view text, const std::filesystem::path& base_dir, std::string_view source_name,
                       const LoadOptions& options) {
  const std::string source(source_name);
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(text.begin(), text.end(), detail::DuplicateKeyCheck());
  } catch (const detail::DuplicateKey& d) {
    throw Error(ErrorCode::parse_error, source + ": " + d.path + ": duplicate key");
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is 1-based: the position of the byte the parser stopped at. Its message repeats a
    // line and column of its own and a "[json.exception...]" tag; keep only the description.
    std::string what = e.what();
    const std::size_t colon = what.find(": ", what.find("parse error"));
    if (colon != std::string::npos) what = what.substr(colon + 2);
    throw Error(ErrorCode::parse_error, source + ":" + detail::line_column(text, e.byte > 0 ? e.byte - 1 : 0) +
                                            ": JSON syntax error: " + what);
  } catch (const nlohmann::json::exception& e) {
    // Not a syntax error but a value the JSON library cannot hold (a number such as 1e999).
    throw Error(ErrorCode::parse_error, source + ": JSON value error: " + e.what());
  }
  try {
    return detail::SceneReader(source, base_dir, options).read(root);
  } catch (const nlohmann::json::exception& e) {
    // A value the reader's checks let through to the JSON library (a number too large for its
    // type, ...): still the caller's bad input, reported as ours.
    throw Error(ErrorCode::parse_error, source + ": " + e.what());
  }
}

}  // namespace v1
}  // namespace radiosity
