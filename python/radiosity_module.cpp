// The Python module `radiosity` (pybind11 + NumPy): scenes from files or NumPy arrays, solve(),
// and the sparse view-factor matrix as a scipy.sparse.csr_matrix. docs/PYTHON.md describes the
// API; python/tests/ tests it. One translation unit on purpose (its compile time counts in CI):
// values cross as NumPy arrays, dicts and lists built here, without pybind11/stl.h.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "radiosity/common.hpp"
#include "radiosity/form_factors.hpp"
#include "radiosity/io.hpp"
#include "radiosity/scene.hpp"
#include "radiosity/solver.hpp"

namespace py = pybind11;
namespace rad = radiosity;

namespace {

// ---- Names: the command line's spellings; '_' and '-' are the same on input ----

template <class E>
struct Name {
  const char* text;
  E value;
};

constexpr Name<rad::SolverMethod> kSolverMethods[] = {
    {"auto", rad::SolverMethod::automatic},     {"jacobi", rad::SolverMethod::jacobi},
    {"gauss-seidel", rad::SolverMethod::gauss_seidel}, {"progressive", rad::SolverMethod::progressive},
    {"hierarchical", rad::SolverMethod::hierarchical}};
constexpr Name<rad::FormFactorMethod> kFormFactorMethods[] = {
    {"auto", rad::FormFactorMethod::automatic},   {"ray-cast", rad::FormFactorMethod::ray_cast},
    {"hemicube", rad::FormFactorMethod::hemicube}, {"analytic", rad::FormFactorMethod::analytic},
    {"monte-carlo", rad::FormFactorMethod::monte_carlo}};
constexpr Name<rad::ViewFactorLevel> kLevels[] = {{"group", rad::ViewFactorLevel::group},
                                                  {"polygon", rad::ViewFactorLevel::polygon},
                                                  {"element", rad::ViewFactorLevel::element}};
constexpr Name<rad::ViewFactorCorrection> kCorrections[] = {{"none", rad::ViewFactorCorrection::none},
                                                            {"reciprocity", rad::ViewFactorCorrection::reciprocity},
                                                            {"enclosure", rad::ViewFactorCorrection::enclosure}};
constexpr Name<rad::SolveStatus> kStatuses[] = {{"converged", rad::SolveStatus::converged},
                                                {"iteration_cap", rad::SolveStatus::iteration_cap},
                                                {"cancelled", rad::SolveStatus::cancelled}};
constexpr Name<rad::Phase> kPhases[] = {{"meshing", rad::Phase::meshing},     {"form_factors", rad::Phase::form_factors},
                                        {"solving", rad::Phase::solving},     {"refining", rad::Phase::refining},
                                        {"rendering", rad::Phase::rendering}, {"lights", rad::Phase::lights}};
constexpr Name<rad::ErrorCode> kErrorCodes[] = {
    {"invalid_argument", rad::ErrorCode::invalid_argument}, {"invalid_scene", rad::ErrorCode::invalid_scene},
    {"file_not_found", rad::ErrorCode::file_not_found},     {"parse_error", rad::ErrorCode::parse_error},
    {"io_error", rad::ErrorCode::io_error},                 {"memory_budget", rad::ErrorCode::memory_budget},
    {"internal", rad::ErrorCode::internal}};

// Quantities per element: Solution::element_values()'s four, and the back sides' radiosity.
enum class Values { radiosity, irradiance, direct_irradiance, indirect_irradiance, back_radiosity };
constexpr Name<Values> kQuantities[] = {{"radiosity", Values::radiosity},
                                        {"irradiance", Values::irradiance},
                                        {"direct-irradiance", Values::direct_irradiance},
                                        {"indirect-irradiance", Values::indirect_irradiance},
                                        {"back-radiosity", Values::back_radiosity}};

std::string normalised(std::string text) {
  std::replace(text.begin(), text.end(), '_', '-');
  return text;
}

/// The value named `text`; ValueError naming the argument and the choices otherwise.
template <class E, std::size_t N>
E parse(const char* argument, const std::string& text, const Name<E> (&names)[N]) {
  const std::string key = normalised(text);
  std::string choices;
  for (const Name<E>& n : names) {
    if (normalised(n.text) == key) return n.value;
    choices += choices.empty() ? "'" : ", '";
    choices += n.text;
    choices += "'";
  }
  throw py::value_error(std::string(argument) + ": '" + text + "' is not one of " + choices);
}

template <class E, std::size_t N>
const char* name_of(E value, const Name<E> (&names)[N]) {
  for (const Name<E>& n : names)
    if (n.value == value) return n.text;
  return "?";
}

// ---- NumPy arrays out ----

using Doubles = py::array_t<double>;

Doubles rgb_rows(const std::vector<rad::Rgb>& values) {
  Doubles out(std::vector<py::ssize_t>{static_cast<py::ssize_t>(values.size()), 3});
  double* p = out.mutable_data();
  for (const rad::Rgb& v : values) {
    *p++ = v.x;
    *p++ = v.y;
    *p++ = v.z;
  }
  return out;
}

Doubles vec3(const glm::dvec3& v) {
  Doubles out(3);
  double* p = out.mutable_data();
  p[0] = v.x;
  p[1] = v.y;
  p[2] = v.z;
  return out;
}

template <class T, class Source>
py::array_t<T> vector_array(const std::vector<Source>& values) {
  py::array_t<T> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

py::list string_list(const std::vector<std::string>& strings) {
  py::list out;
  for (const std::string& s : strings) out.append(py::str(s));
  return out;
}

// ---- Errors ----

// radiosity.Error, created once at import and kept for the life of the process.
PyObject* g_error_type = nullptr;

void translate_error(std::exception_ptr error) {
  try {
    if (error) std::rethrow_exception(error);
  } catch (const rad::Error& e) {
    py::object instance = py::handle(g_error_type)(py::str(e.what()));
    instance.attr("code") = py::str(name_of(e.code(), kErrorCodes));
    PyErr_SetObject(g_error_type, instance.ptr());
  }
}

// ---- Progress ----

// A ProgressFn that calls `callback` (may be None) with a dict, holding the GIL only during the
// call, and turns Ctrl-C into a KeyboardInterrupt out of the computation. The library calls it
// on the thread that called solve() (common.hpp), so taking the GIL there cannot deadlock.
// It captures a pointer, not the object: std::function copies made while the GIL is released
// must not touch reference counts.
rad::ProgressFn progress_function(const py::object& callback) {
  const py::object* cb = &callback;
  return [cb](const rad::Progress& p) -> bool {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (cb->is_none()) return true;
    py::dict d;
    d["phase"] = name_of(p.phase, kPhases);
    d["fraction"] = p.fraction;
    d["iteration"] = p.iteration;
    d["residual"] = p.residual;
    const py::object keep_going = (*cb)(d);
    return keep_going.is_none() || keep_going.cast<bool>();
  };
}

// ---- Scenes from NumPy arrays ----

/// Per-face colours: None (every face `fallback`), shape (3,) (every face) or (faces, 3).
std::vector<rad::Rgb> face_colours(const char* argument, const py::object& colours, std::size_t faces,
                                   rad::Rgb fallback) {
  std::vector<rad::Rgb> out(faces, fallback);
  if (colours.is_none()) return out;
  const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(colours);
  if (!a) throw py::type_error(std::string(argument) + ": expected an array of floats");
  const bool one = a.ndim() == 1 && a.shape(0) == 3;
  const bool each = a.ndim() == 2 && static_cast<std::size_t>(a.shape(0)) == faces && a.shape(1) == 3;
  if (!one && !each)
    throw py::value_error(std::string(argument) + ": expected shape (3,) or (" + std::to_string(faces) + ", 3)");
  const float* p = a.data();
  for (std::size_t i = 0; i < faces; ++i) {
    const float* c = one ? p : p + 3 * i;
    out[i] = rad::Rgb(c[0], c[1], c[2]);
  }
  return out;
}

/// Per-face group names: None ("default"), one str, or a sequence of one str per face.
std::vector<std::string> face_groups(const py::object& groups, std::size_t faces) {
  if (groups.is_none()) return std::vector<std::string>(faces);
  if (py::isinstance<py::str>(groups)) return std::vector<std::string>(faces, groups.cast<std::string>());
  const py::sequence names = groups.cast<py::sequence>();
  if (names.size() != faces)
    throw py::value_error("groups: expected " + std::to_string(faces) + " names (one per face), got " +
                          std::to_string(names.size()));
  std::vector<std::string> out;
  out.reserve(faces);
  for (const py::handle name : names) out.push_back(py::str(name).cast<std::string>());
  return out;
}

rad::Scene scene_from_arrays(const py::array_t<float, py::array::c_style | py::array::forcecast>& vertices,
                             const py::array& faces_in, const py::object& groups, const py::object& reflectance,
                             const py::object& emission, bool two_sided) {
  if (vertices.ndim() != 2 || vertices.shape(1) != 3) throw py::value_error("vertices: expected shape (n, 3)");
  const char kind = faces_in.dtype().kind();
  if (kind != 'i' && kind != 'u') throw py::type_error("faces: expected an array of integers");
  const auto faces = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(faces_in);
  if (!faces || faces.ndim() != 2 || (faces.shape(1) != 3 && faces.shape(1) != 4))
    throw py::value_error("faces: expected shape (m, 3) or (m, 4)");
  const auto vertex_count = static_cast<std::size_t>(vertices.shape(0));
  const auto face_count = static_cast<std::size_t>(faces.shape(0));
  const auto corners = static_cast<std::size_t>(faces.shape(1));
  const std::int64_t* f = faces.data();
  const auto* positions = reinterpret_cast<const glm::vec3*>(vertices.data());
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be three packed floats");

  // Indices in range (a quad array's fourth column may be -1: a triangle).
  for (std::size_t i = 0; i < face_count; ++i)
    for (std::size_t c = 0; c < corners; ++c) {
      const std::int64_t v = f[i * corners + c];
      if (c == 3 && v == -1) continue;
      if (v < 0 || static_cast<std::size_t>(v) >= vertex_count)
        throw rad::Error(rad::ErrorCode::invalid_scene, "faces[" + std::to_string(i) + ", " + std::to_string(c) +
                                                            "]: vertex index " + std::to_string(v) +
                                                            " out of range [0, " + std::to_string(vertex_count) + ")");
    }

  const std::vector<rad::Rgb> rho = face_colours("reflectance", reflectance, face_count, rad::Material{}.reflectance);
  const std::vector<rad::Rgb> e = face_colours("emission", emission, face_count, rad::Rgb(0.0f));
  const std::vector<std::string> group = face_groups(groups, face_count);

  rad::Scene scene;
  // One material per distinct (reflectance, emission), in order of first use.
  std::map<std::array<float, 6>, rad::MaterialId> material_of;
  std::vector<rad::MaterialId> face_material(face_count);
  for (std::size_t i = 0; i < face_count; ++i) {
    const std::array<float, 6> key{rho[i].x, rho[i].y, rho[i].z, e[i].x, e[i].y, e[i].z};
    auto it = material_of.find(key);
    if (it == material_of.end()) {
      rad::Material m;
      m.name = "material " + std::to_string(material_of.size());
      m.reflectance = rho[i];
      m.emission = e[i];
      m.two_sided = two_sided;
      try {
        it = material_of.emplace(key, scene.add_material(m)).first;
      } catch (const rad::Error& error) {
        throw rad::Error(error.code(), "face " + std::to_string(i) + ": " + error.what());
      }
    }
    face_material[i] = it->second;
  }

  if (corners == 3) {
    // Triangles: one mesh (Scene::add_mesh()) per run of consecutive faces of one group, so
    // polygon i is face i and Solution.mesh_vertex_values() reaches them. A single run keeps
    // the whole vertex array; several runs each keep the vertices they use, in increasing order
    // (numpy.unique(faces[run])). Strict: a degenerate triangle is an error, not skipped.
    std::size_t runs = 0;
    for (std::size_t i = 0; i < face_count; ++i) runs += i == 0 || group[i] != group[i - 1];
    rad::LoadOptions strict;
    strict.strict = true;
    std::vector<std::uint32_t> local(vertex_count, rad::kNone);
    for (std::size_t first = 0; first < face_count;) {
      std::size_t last = first + 1;
      while (last < face_count && group[last] == group[first]) ++last;
      std::vector<std::uint32_t> indices(3 * (last - first));
      std::vector<glm::vec3> kept;
      if (runs == 1) {
        for (std::size_t k = 0; k < indices.size(); ++k) indices[k] = static_cast<std::uint32_t>(f[k]);
      } else {
        std::vector<std::uint32_t> used(f + 3 * first, f + 3 * last);
        std::sort(used.begin(), used.end());
        used.erase(std::unique(used.begin(), used.end()), used.end());
        kept.reserve(used.size());
        for (std::size_t k = 0; k < used.size(); ++k) {
          local[used[k]] = static_cast<std::uint32_t>(k);
          kept.push_back(positions[used[k]]);
        }
        for (std::size_t k = 0; k < indices.size(); ++k) indices[k] = local[static_cast<std::size_t>(f[3 * first + k])];
      }
      rad::MeshDesc desc;
      desc.positions = runs == 1 ? positions : kept.data();
      desc.vertex_count = runs == 1 ? vertex_count : kept.size();
      desc.indices = indices.data();
      desc.index_count = indices.size();
      desc.triangle_materials = face_material.data() + first;
      desc.group = group[first];
      scene.add_mesh(desc, strict);
      first = last;
    }
  } else {
    // Quads (and triangles, fourth index -1): one polygon each, which must stay one polygon.
    for (std::size_t i = 0; i < face_count; ++i) {
      const std::int64_t* q = f + 4 * i;
      std::vector<glm::vec3> polygon;
      for (std::size_t c = 0; c < 4; ++c)
        if (q[c] >= 0) polygon.push_back(positions[q[c]]);
      rad::PolygonRange added;
      try {
        added = scene.add_polygon(polygon, face_material[i], group[i]);
      } catch (const rad::Error& error) {
        throw rad::Error(error.code(), "faces[" + std::to_string(i) + "]: " + error.what());
      }
      if (added.count != 1)
        throw rad::Error(rad::ErrorCode::invalid_scene,
                         "faces[" + std::to_string(i) +
                             "]: the quad is not planar and convex (the scene would split it into triangles, "
                             "so polygons would no longer match faces): give it as two triangles");
    }
  }
  return scene;
}

// ---- Scene views ----

/// One polygon of a scene, copied out (with its group's name).
struct PyPolygon {
  rad::Polygon polygon;
  std::string group;
};

/// scene.polygons: a live sequence view of a scene's polygons.
struct PolygonList {
  const rad::Scene* scene;
};

py::dict material_dict(const rad::Material& m) {
  py::dict d;
  d["name"] = m.name;
  d["reflectance"] = vec3(m.reflectance);
  d["emission"] = vec3(m.emission);
  d["specular"] = vec3(m.specular);
  d["transmittance"] = vec3(m.transmittance);
  d["diffuse_transmittance"] = vec3(m.diffuse_transmittance);
  d["two_sided"] = m.two_sided;
  return d;
}

// ---- Solutions ----

/// A solve's result with the count of its scene's polygons (for per-polygon values).
struct PySolution {
  rad::Solution solution;
  std::size_t polygon_count = 0;
};

/// `quantity` per element id (inner nodes included).
std::vector<rad::Rgb> values_by_element_id(const rad::Solution& s, const std::string& quantity) {
  switch (parse("quantity", quantity, kQuantities)) {
    case Values::radiosity: return s.radiosity();
    case Values::irradiance: return s.element_values(rad::Quantity::irradiance);
    case Values::direct_irradiance: return s.element_values(rad::Quantity::direct_irradiance);
    case Values::indirect_irradiance: return s.element_values(rad::Quantity::indirect_irradiance);
    case Values::back_radiosity: {
      const std::vector<rad::Rgb>& back = s.back_radiosity();
      return back.empty() ? std::vector<rad::Rgb>(s.radiosity().size(), rad::Rgb(0.0f)) : back;
    }
  }
  return {};
}

rad::Quantity mesh_quantity(const std::string& quantity) {
  switch (parse("quantity", quantity, kQuantities)) {
    case Values::radiosity: return rad::Quantity::radiosity;
    case Values::irradiance: return rad::Quantity::irradiance;
    case Values::direct_irradiance: return rad::Quantity::direct_irradiance;
    case Values::indirect_irradiance: return rad::Quantity::indirect_irradiance;
    case Values::back_radiosity: break;
  }
  throw py::value_error("quantity: 'back_radiosity' is per element and per polygon only");
}

/// Area-weighted mean of `quantity` over each polygon's patches, (polygons, 3); buried parts
/// count as 0 (Solution::exposure(): a patch's value is its open part's).
Doubles polygon_values(const PySolution& s, const std::string& quantity) {
  const std::vector<rad::Rgb> by_id = values_by_element_id(s.solution, quantity);
  const std::vector<float>& exposure = s.solution.exposure();
  std::vector<glm::dvec3> sum(s.polygon_count, glm::dvec3(0.0));
  std::vector<double> area(s.polygon_count, 0.0);
  for (const rad::Patch& patch : s.solution.hierarchy().patches()) {
    if (patch.polygon >= s.polygon_count) continue;
    const double open = exposure.empty() ? 1.0 : static_cast<double>(exposure[patch.root]);
    sum[patch.polygon] += glm::dvec3(by_id[patch.root]) * static_cast<double>(patch.area) * open;
    area[patch.polygon] += patch.area;
  }
  Doubles out(std::vector<py::ssize_t>{static_cast<py::ssize_t>(s.polygon_count), 3});
  double* p = out.mutable_data();
  for (std::size_t i = 0; i < s.polygon_count; ++i)
    for (int c = 0; c < 3; ++c) *p++ = area[i] > 0 ? sum[i][c] / area[i] : 0.0;
  return out;
}

/// `quantity` per leaf element, in hierarchy leaves() order, (leaves, 3).
Doubles element_values(const PySolution& s, const std::string& quantity) {
  const std::vector<rad::Rgb> by_id = values_by_element_id(s.solution, quantity);
  const std::vector<std::uint32_t>& leaves = s.solution.hierarchy().leaves();
  std::vector<rad::Rgb> out(leaves.size());
  for (std::size_t k = 0; k < leaves.size(); ++k) out[k] = by_id[leaves[k]];
  return rgb_rows(out);
}

/// The estimator that ran, or None for the hierarchical solver (its links are its own transport).
py::object estimator_used(const rad::SolveReport& r) {
  return r.estimator_ran() ? py::object(py::str(rad::to_string(r.form_factor_method))) : py::none();
}

py::dict report_dict(const rad::Solution& s) {
  const rad::SolveReport& r = s.report();
  py::dict d;
  d["status"] = name_of(s.status(), kStatuses);
  d["iterations"] = r.iterations;
  d["residual"] = r.residual;
  d["residual_history"] = vector_array<double>(r.residual_history);
  d["time_history"] = vector_array<double>(r.time_history);
  d["method"] = name_of(r.method, kSolverMethods);
  d["method_choice"] = r.method_choice;
  d["form_factor_method"] = estimator_used(r);
  d["patch_count"] = r.patch_count;
  d["element_count"] = r.element_count;
  d["refined_elements"] = r.refined_elements;
  d["form_factor_bytes"] = r.form_factor_bytes;
  d["link_count"] = r.link_count;
  d["specular_depth"] = r.specular_depth;
  d["specular_depth_choice"] = r.specular_depth_choice;
  d["emitted_power"] = vec3(r.emitted_power);
  d["light_power"] = vec3(r.light_power);
  d["absorbed_power"] = vec3(r.absorbed_power);
  d["escaped_power"] = vec3(r.escaped_power);
  d["seconds_meshing"] = r.seconds_meshing;
  d["seconds_form_factors"] = r.seconds_form_factors;
  d["seconds_solving"] = r.seconds_solving;
  d["seconds_lights"] = r.seconds_lights;
  d["warnings"] = string_list(r.warnings);
  return d;
}

double total_seconds(const rad::SolveReport& r) {
  return r.seconds_meshing + r.seconds_form_factors + r.seconds_solving + r.seconds_lights;
}

// ---- solve() and view_factor_matrix() ----

PySolution solve(const rad::Scene& scene, const std::string& method, double tolerance, int max_iterations,
                 unsigned threads, std::uint64_t seed, const std::string& form_factors, double max_patch_area,
                 double max_element_area, std::uint32_t hemisphere_rays, bool adaptive, double epsilon,
                 std::size_t memory_budget_bytes, const py::object& specular_depth, const py::object& progress) {
  rad::SolveOptions o;
  o.method = parse("method", method, kSolverMethods);
  o.tolerance = tolerance;
  o.max_iterations = max_iterations;
  o.threads = threads;
  o.seed = seed;
  o.form_factors.method = parse("form_factors", form_factors, kFormFactorMethods);
  o.form_factors.hemisphere_rays = hemisphere_rays;
  o.mesh.max_patch_area = static_cast<float>(max_patch_area);
  o.mesh.max_element_area = static_cast<float>(max_element_area);
  o.adaptive.enabled = adaptive;
  o.hierarchical.epsilon = static_cast<float>(epsilon);
  o.memory_budget_bytes = memory_budget_bytes;
  o.on_progress = progress_function(progress);
  // specular_depth None: solve() chooses (rad::SpecularPaths::automatic, as `radiosity solve`:
  // the extended first pass on a scene with mirrors or glass, docs/CLI.md).
  if (!specular_depth.is_none()) {
    o.specular_paths = rad::SpecularPaths::as_given;
    o.form_factors.specular_depth = specular_depth.cast<std::uint32_t>();
    o.form_factors.emitted_through_glass = true;  // no photon pass follows
  }
  PySolution out;
  out.polygon_count = scene.polygons().size();
  py::gil_scoped_release release;
  out.solution = rad::solve(scene, o);
  return out;
}

py::object view_factor_matrix(const rad::Scene& scene, const std::string& level, const std::string& method,
                              const std::string& correction, std::uint32_t hemisphere_rays, std::uint64_t seed,
                              unsigned threads, const py::object& groups, double max_patch_area,
                              double max_element_area, double epsilon, std::size_t memory_budget_bytes,
                              const py::object& dtype, bool return_info, const py::object& progress) {
  rad::ViewFactorOptions o;
  o.level = parse("level", level, kLevels);
  if (normalised(method) == "hierarchical") {
    o.method = rad::ViewFactorMethod::hierarchical;
  } else {
    o.method = rad::ViewFactorMethod::estimator;
    o.form_factors.method = parse("method", method, kFormFactorMethods);
  }
  o.correction = parse("correction", correction, kCorrections);
  o.form_factors.hemisphere_rays = hemisphere_rays;
  o.form_factors.seed = seed;
  o.form_factors.threads = threads;
  o.mesh.max_patch_area = static_cast<float>(max_patch_area);
  o.mesh.max_element_area = static_cast<float>(max_element_area);
  o.epsilon = static_cast<float>(epsilon);
  o.memory_budget_bytes = memory_budget_bytes;
  if (!groups.is_none()) {
    if (py::isinstance<py::str>(groups)) throw py::type_error("groups: expected a sequence of names, not one str");
    for (const py::handle g : groups.cast<py::sequence>()) o.groups.push_back(py::str(g).cast<std::string>());
  }
  o.on_progress = progress_function(progress);
  const py::dtype value_type = py::dtype::from_args(dtype);
  if (value_type.kind() != 'f' || (value_type.itemsize() != 4 && value_type.itemsize() != 8))
    throw py::value_error("dtype: expected float32 or float64");

  rad::ViewFactorMatrix m;
  {
    py::gil_scoped_release release;
    m = rad::view_factor_matrix(scene, o);
  }

  // CSR arrays: 32-bit indices while they fit (scipy's own choice), else 64-bit.
  const std::size_t rows = m.rows();
  const bool narrow = m.non_zeros() <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()) &&
                      rows <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  py::array indices, indptr;
  if (narrow) {
    indices = vector_array<std::int32_t>(m.columns);
    indptr = vector_array<std::int32_t>(m.row_offsets);
  } else {
    indices = vector_array<std::int64_t>(m.columns);
    indptr = vector_array<std::int64_t>(m.row_offsets);
  }
  py::array data;
  if (value_type.itemsize() == 4)
    data = vector_array<float>(m.values);
  else
    data = vector_array<double>(m.values);
  const py::object csr_matrix = py::module_::import("scipy.sparse").attr("csr_matrix");
  const auto n = static_cast<py::ssize_t>(rows);
  py::object matrix = csr_matrix(py::make_tuple(data, indices, indptr), py::arg("shape") = py::make_tuple(n, n));
  if (!return_info) return matrix;

  py::dict info;
  info["level"] = rad::to_string(m.level);
  info["ids"] = vector_array<std::int64_t>(m.ids);
  info["names"] = string_list(m.names);
  info["area"] = vector_array<double>(m.area);
  info["sky"] = vector_array<double>(m.sky);
  info["sky_standard_error"] = vector_array<double>(m.sky_standard_error);
  info["row_standard_error"] = m.row_standard_error.empty() ? py::object(py::none())
                                                            : py::object(vector_array<double>(m.row_standard_error));
  py::dict c;
  c["name"] = rad::to_string(o.correction);
  c["reciprocity_before"] = m.correction.reciprocity_before;
  c["row_sum_error_before"] = m.correction.row_sum_error_before;
  c["row_sum_rms_before"] = m.correction.row_sum_rms_before;
  c["largest_change"] = m.correction.largest_change;
  c["rms_change"] = m.correction.rms_change;
  c["empty_rows"] = m.correction.empty_rows;
  c["clamped"] = m.correction.clamped;
  c["iterations"] = m.correction.iterations;
  info["correction"] = c;
  info["warnings"] = string_list(m.warnings);
  info["notes"] = string_list(m.notes);
  info["method"] = m.method;
  info["method_reason"] = m.method_reason;
  info["element_count"] = m.element_count;
  info["seconds"] = m.seconds;
  info["cancelled"] = m.cancelled;
  return py::make_tuple(matrix, info);
}

// ---- Docstrings ----

constexpr const char* kModuleDoc = R"(Radiosity global illumination and view factors (the C++ library radiosity, v1).

Scenes come from files (load_scene), from NumPy arrays (Scene) or cornell_box(); solve() returns
a Solution with per-polygon, per-element and per-vertex values as NumPy arrays;
view_factor_matrix() returns a scipy.sparse.csr_matrix. Library errors raise radiosity.Error
(a RuntimeError with the library's message and a `code`); a bad argument raises ValueError or
TypeError. Arrays returned are float64 copies, (n, 3) for RGB values in W/m^2 per scene unit^2.

Thread safety: solve(), view_factor_matrix() and load_scene() release the GIL while the library
computes, so calls from several Python threads run concurrently (each also uses `threads`
worker threads of its own: 0 = every core). Concurrent calls may share a Scene but must not
mutate it (make_two_sided, set_obstruction_only) meanwhile. A Solution is immutable. See
docs/PYTHON.md.)";

constexpr const char* kSceneDoc = R"(Planar convex polygons with materials and groups.

Scene(vertices, faces, groups=None, reflectance=None, emission=None, two_sided=False)

vertices: float array (n, 3), scene units. faces: integer array (m, 3) of triangles or (m, 4)
of quads (a fourth index of -1 makes that face a triangle), counter-clockwise seen from the
side the face lights (its normal by the right-hand rule). groups: None ("default"), one name,
or m names (per-face group names). reflectance: diffuse reflectance rho per channel in [0, 1),
shape (3,) for every face or (m, 3) per face; default 0.5. emission: emitted exitance E in W/m^2,
>= 0, (3,) or (m, 3); default 0. One material is made per distinct (reflectance, emission).
two_sided: every material reflects and emits on both sides.

Polygon i is face i: the input is taken strictly, so a degenerate face, a vertex index out of
range, a NaN, or a quad that is not planar and convex raises radiosity.Error naming the face.
Triangles become meshes (one per run of consecutive faces of one group) so that
Solution.mesh_vertex_values() gives per-vertex results: with a single run, mesh 0 has the whole
vertex array; with several, mesh k has the vertices its run uses, in the order of
numpy.unique(faces[run]).

Thread safety: const methods may be called concurrently; mutation needs exclusive access.)";

constexpr const char* kSolveDoc = R"(Meshes the scene, computes form factors and solves for radiosity (radiosity::solve).
method: 'auto' (Gauss-Seidel while its rows fit the memory budget, else hierarchical),
'jacobi', 'gauss-seidel', 'progressive' or 'hierarchical'. tolerance: stop when the unpropagated
power falls below this fraction of the emitted power. max_iterations: 0 = the library's cap.
threads: 0 = every core, 1 = the calling thread only; results do not depend on it. seed: every
random stream. form_factors: 'auto', 'ray-cast', 'hemicube', 'analytic', 'monte-carlo'.
max_patch_area, max_element_area: meshing, scene units^2 (0 = derived from the scene).
hemisphere_rays: Monte Carlo rays per element. adaptive: adaptive subdivision. epsilon: the
hierarchical solver's link refinement threshold. memory_budget_bytes: 0 = 4 GiB.
specular_depth: mirror reflections and window or glass passages carried between diffuse
surfaces (extended form factors, Monte Carlo only), and the lights' shadow rays through windows
and glass; None (the default) = 1 on a scene with mirror or glass materials, unless
form_factors names another estimator or method is 'hierarchical' (or, under method 'auto', its
rows would exceed the memory budget), else 0; report['specular_depth'] says which ran and
report['specular_depth_choice'] why.
progress: optional callable(dict) with keys phase, fraction, iteration, residual, called on the
calling thread at phase boundaries and at most every ~50 ms; return False to cancel (the
Solution's status is then 'cancelled'). An exception it raises, and Ctrl-C, propagate.

Raises radiosity.Error for bad options, a scene without polygons, overlapping polygons, or a
method over the memory budget. Thread safety: releases the GIL; concurrent calls are safe.)";

constexpr const char* kViewFactorDoc = R"(The sparse view-factor matrix F (radiosity::view_factor_matrix) as a scipy.sparse.csr_matrix of
shape (rows, rows), or (csr_matrix, info) with return_info=True: F[i, j] is the fraction of the
energy leaving surface i (diffusely) that arrives at surface j.
level: 'polygon' (rows are the scene's polygons in order, obstruction-only ones left out),
'element' (the leaves of the mesh that max_patch_area/max_element_area make) or 'group'.
method: 'auto' (at polygon and element level: 'ray-cast' while its thread time, estimated from
a sample of pairs, is at most a minute, else 'monte-carlo'; info['method_reason'] says which and
why), 'ray-cast' (polygon and element level: the exact mode, each pair integrated without rays;
group level: element rows, occlusion by rays), 'analytic' (no occlusion), 'hemicube',
'monte-carlo' (hemisphere_rays per element; rows x rays cost, for large scenes) or 'hierarchical'
(the links of hierarchical radiosity, epsilon their refinement threshold; reciprocal whatever the
correction).
correction: 'none', 'reciprocity' (A_i F_ij = A_j F_ji exactly) or 'enclosure' (reciprocity
and rows summing to 1, for closed enclosures). groups: names of the groups whose surfaces are
rows and columns (None = all). seed and threads as in solve(); the result does not depend on
threads. memory_budget_bytes: the most the matrix may take (8 bytes a factor; 0 = 4 GiB): one
estimated over it from a sample of its rows raises radiosity.Error (code 'memory_budget') before
the rest are made. dtype: float64 or float32 values.

return_info=True returns (matrix, info), info a dict with: 'level'; 'ids' (per row: the
PolygonId, element id or GroupId); 'names' (group level: the group names); 'area' (per row,
scene units^2); 'sky' (per row: the sky view factor, the part of the hemisphere in which no
polygon lies, estimated by rays; not 1 - row sum);
'row_standard_error' (per row, Monte Carlo; None for the other methods); 'correction' (dict:
name, reciprocity_before, row_sum_error_before, row_sum_rms_before, largest_change, rms_change,
empty_rows, clamped, iterations); 'warnings' (list of str: z-fighting polygons, polygons wound
against their neighbours, rows that see only the sky in a model wound outward); 'notes' (list of
str: rows in contact, rows that see only the sky, covered rows that see nothing); 'method' (the
estimator that ran); 'method_reason' (why, when 'auto' chose it; else empty); 'element_count';
'seconds'; 'cancelled' (the progress callback stopped it: rows are incomplete).

Raises radiosity.Error for a scene without polygons, bad options or an unknown group.
Thread safety: releases the GIL; concurrent calls are safe.)";

}  // namespace

PYBIND11_MODULE(radiosity, m) {
  m.doc() = kModuleDoc;
  m.attr("__version__") = rad::version();

  g_error_type = PyErr_NewExceptionWithDoc(
      "radiosity.Error",
      "An error of the radiosity library: bad input, an unreadable file, an option out of range. "
      "str(e) is the library's message (naming the field, file, line or polygon); e.code is its "
      "kind: 'invalid_argument', 'invalid_scene', 'file_not_found', 'parse_error', 'io_error', "
      "'memory_budget' or 'internal'.",
      PyExc_RuntimeError, nullptr);
  if (g_error_type == nullptr) throw py::error_already_set();
  m.add_object("Error", py::handle(g_error_type));
  py::register_exception_translator(&translate_error);

  py::class_<PyPolygon>(m, "Polygon", "One polygon of a Scene (a copy). Thread safety: immutable.")
      .def_property_readonly(
          "vertices",
          [](const PyPolygon& p) {
            const rad::PolygonVertices& v = p.polygon.vertices;
            Doubles out(std::vector<py::ssize_t>{static_cast<py::ssize_t>(v.size()), 3});
            double* d = out.mutable_data();
            for (const glm::vec3& c : v) {
              *d++ = c.x;
              *d++ = c.y;
              *d++ = c.z;
            }
            return out;
          },
          "Corners, (k, 3), counter-clockwise seen from the front.")
      .def_property_readonly("normal", [](const PyPolygon& p) { return vec3(p.polygon.normal); }, "Unit normal, (3,).")
      .def_property_readonly("area", [](const PyPolygon& p) { return static_cast<double>(p.polygon.area); },
                             "Area, scene units^2.")
      .def_property_readonly("group", [](const PyPolygon& p) { return p.group; }, "The group's name.")
      .def_property_readonly("group_id", [](const PyPolygon& p) { return p.polygon.group; })
      .def_property_readonly("material", [](const PyPolygon& p) { return p.polygon.material; },
                             "Material id: an index into Scene.materials.")
      .def_property_readonly("obstruction_only", [](const PyPolygon& p) { return p.polygon.obstruction_only; },
                             "Blocks light but has no row or column in view_factor_matrix().")
      .def("__repr__", [](const PyPolygon& p) {
        return "<radiosity.Polygon: " + std::to_string(p.polygon.vertices.size()) + " corners, area " +
               std::to_string(p.polygon.area) + ", group '" + p.group + "'>";
      });

  py::class_<PolygonList>(m, "PolygonList",
                          "scene.polygons: a sequence view of the scene's polygons (len, indexing, iteration); "
                          "each item is a Polygon copy. It keeps its scene alive and sees its changes. Thread "
                          "safety: as the scene's const methods.")
      .def("__len__", [](const PolygonList& l) { return l.scene->polygons().size(); })
      .def("__getitem__", [](const PolygonList& l, py::ssize_t i) {
        const auto n = static_cast<py::ssize_t>(l.scene->polygons().size());
        if (i < 0) i += n;
        if (i < 0 || i >= n) throw py::index_error("polygon index out of range");
        const rad::Polygon& p = l.scene->polygons()[static_cast<std::size_t>(i)];
        return PyPolygon{p, l.scene->groups()[p.group]};
      });

  py::class_<rad::Scene>(m, "Scene", kSceneDoc)
      .def(py::init(&scene_from_arrays), py::arg("vertices"), py::arg("faces"), py::arg("groups") = py::none(),
           py::arg("reflectance") = py::none(), py::arg("emission") = py::none(), py::arg("two_sided") = false)
      .def_property_readonly(
          "polygons", py::cpp_function([](const rad::Scene& s) { return PolygonList{&s}; }, py::keep_alive<0, 1>()),
          "A sequence of the polygons (Polygon), in PolygonId order.")
      .def("polygon_areas",
           [](const rad::Scene& s) {
             Doubles out(static_cast<py::ssize_t>(s.polygons().size()));
             double* p = out.mutable_data();
             for (const rad::Polygon& q : s.polygons()) *p++ = q.area;
             return out;
           },
           "Areas, (polygons,), scene units^2.")
      .def("polygon_normals",
           [](const rad::Scene& s) {
             std::vector<rad::Rgb> n;
             n.reserve(s.polygons().size());
             for (const rad::Polygon& q : s.polygons()) n.push_back(q.normal);
             return rgb_rows(n);
           },
           "Unit normals, (polygons, 3).")
      .def("polygon_group_ids",
           [](const rad::Scene& s) {
             py::array_t<std::int64_t> out(static_cast<py::ssize_t>(s.polygons().size()));
             std::int64_t* p = out.mutable_data();
             for (const rad::Polygon& q : s.polygons()) *p++ = q.group;
             return out;
           },
           "Group ids, (polygons,): indices into Scene.groups.")
      .def("polygon_material_ids",
           [](const rad::Scene& s) {
             py::array_t<std::int64_t> out(static_cast<py::ssize_t>(s.polygons().size()));
             std::int64_t* p = out.mutable_data();
             for (const rad::Polygon& q : s.polygons()) *p++ = q.material;
             return out;
           },
           "Material ids, (polygons,): indices into Scene.materials.")
      .def_property_readonly("groups", [](const rad::Scene& s) { return string_list(s.groups()); },
                             "Group names, by group id.")
      .def_property_readonly(
          "materials",
          [](const rad::Scene& s) {
            py::list out;
            for (const rad::Material& mat : s.materials()) out.append(material_dict(mat));
            return out;
          },
          "Materials (dicts: name, reflectance, emission, specular, transmittance, diffuse_transmittance, "
          "two_sided), by material id.")
      .def_property_readonly("mesh_count", [](const rad::Scene& s) { return s.meshes().size(); })
      .def("mesh",
           [](const rad::Scene& s, std::size_t k) {
             if (k >= s.meshes().size()) throw py::index_error("mesh index out of range");
             const rad::Mesh& mesh = s.meshes()[k];
             py::dict d;
             d["group"] = s.groups()[mesh.group];
             d["positions"] = rgb_rows(mesh.positions);
             py::array_t<std::int64_t> tri(std::vector<py::ssize_t>{static_cast<py::ssize_t>(mesh.indices.size() / 3), 3});
             std::copy(mesh.indices.begin(), mesh.indices.end(), tri.mutable_data());
             d["triangles"] = tri;
             py::array_t<std::int64_t> polygon(static_cast<py::ssize_t>(mesh.triangle_polygon.size()));
             for (std::size_t t = 0; t < mesh.triangle_polygon.size(); ++t)
               polygon.mutable_data()[t] = mesh.triangle_polygon[t] == rad::kNone
                                               ? std::int64_t{-1}
                                               : static_cast<std::int64_t>(mesh.triangle_polygon[t]);
             d["triangle_polygons"] = polygon;
             return d;
           },
           py::arg("mesh"),
           "Mesh `mesh` as the scene keeps it: dict of group, positions (n, 3), triangles (t, 3) and "
           "triangle_polygons (t,; -1 for a skipped triangle).")
      .def("total_area", &rad::Scene::total_area, "Sum of the polygons' areas, scene units^2.")
      .def("bounds",
           [](const rad::Scene& s) {
             const rad::Bounds b = s.bounds();
             return py::make_tuple(vec3(b.lower), vec3(b.upper));
           },
           "(lower, upper) corners of the bounding box.")
      .def_property_readonly("origin",
                             [](const rad::Scene& s) { return vec3(s.origin()); },
                             "(3,): the point of the file's coordinates that the scene's (0, 0, 0) stands for; "
                             "positions are relative to it. (0, 0, 0) unless the reader moved a model that lay far "
                             "from the origin for its size (georeferenced coordinates).")
      .def_property_readonly("light_count", [](const rad::Scene& s) { return s.lights().size(); },
                             "Lights that are not polygons (point, spot, directional, sky).")
      .def_property_readonly("warnings", [](const rad::Scene& s) { return string_list(s.warnings()); },
                             "Non-fatal problems met while building or loading the scene.")
      .def("set_obstruction_only", &rad::Scene::set_obstruction_only, py::arg("polygon"),
           py::arg("obstruction_only") = true,
           "Marks a polygon obstruction-only (it hides, but gets no row or column in view_factor_matrix()).")
      .def("make_two_sided", &rad::Scene::make_two_sided, "Makes every material two-sided.")
      .def(
          "reverse_winding",
          [](rad::Scene& s, const py::object& polygons) {
            if (polygons.is_none())
              s.reverse_winding();
            else
            {
              std::vector<rad::PolygonId> ids;
              for (const py::handle id : py::iterable(polygons)) ids.push_back(id.cast<rad::PolygonId>());
              s.reverse_winding(ids);
            }
          },
          py::arg("polygons") = py::none(),
          "Turns polygons over (reverses their winding; their meshes' triangles follow): the given polygon ids, or "
          "every polygon. For one-sided models wound the wrong way; radiosity.find_polygons_facing_outward(scene) "
          "lists the polygons of a closed room wound outwards.")
      .def("__repr__", [](const rad::Scene& s) {
        return "<radiosity.Scene: " + std::to_string(s.polygons().size()) + " polygons, " +
               std::to_string(s.groups().size()) + " groups, " + std::to_string(s.materials().size()) +
               " materials>";
      });

  py::class_<PySolution>(m, "Solution",
                         "The result of solve(): radiosity per element of the mesh it was solved on. Values are "
                         "W/m^2 per scene unit^2, (n, 3) float64 RGB. quantity is 'radiosity' (B, emission "
                         "included), 'irradiance' (H), 'direct_irradiance', 'indirect_irradiance' or (per "
                         "element and polygon) 'back_radiosity'. Thread safety: immutable; its methods may be "
                         "called concurrently.")
      .def_property_readonly("status", [](const PySolution& s) { return name_of(s.solution.status(), kStatuses); },
                             "'converged', 'iteration_cap' or 'cancelled'.")
      .def_property_readonly("iterations", [](const PySolution& s) { return s.solution.report().iterations; },
                             "Sweeps (matrix methods) or shooting steps (progressive).")
      .def_property_readonly("residual", [](const PySolution& s) { return s.solution.report().residual; })
      .def_property_readonly("method", [](const PySolution& s) { return name_of(s.solution.report().method, kSolverMethods); },
                             "The solver that ran (never 'auto').")
      .def_property_readonly("form_factor_method", [](const PySolution& s) { return estimator_used(s.solution.report()); },
                             "The form-factor estimator that ran, or None for the hierarchical solver (its links are "
                             "its own transport).")
      .def_property_readonly("seconds", [](const PySolution& s) { return total_seconds(s.solution.report()); },
                             "Wall time of meshing, lights, form factors and solving.")
      .def_property_readonly("report", [](const PySolution& s) { return report_dict(s.solution); },
                             "Every figure of the solve report, as a dict.")
      .def_property_readonly("groups", [](const PySolution& s) { return string_list(s.solution.groups()); })
      .def_property_readonly("mesh_count", [](const PySolution& s) { return s.solution.meshes().size(); })
      .def("polygon_values", &polygon_values, py::arg("quantity") = "radiosity",
           "Area-weighted mean of `quantity` over each polygon, (polygons, 3).")
      .def("polygon_radiosity", [](const PySolution& s) { return polygon_values(s, "radiosity"); },
           "polygon_values('radiosity').")
      .def("element_values", &element_values, py::arg("quantity") = "radiosity",
           "`quantity` per leaf element (the unknowns), (elements, 3).")
      .def("element_radiosity", [](const PySolution& s) { return element_values(s, "radiosity"); },
           "element_values('radiosity').")
      .def("element_polygons",
           [](const PySolution& s) {
             const rad::PatchHierarchy& h = s.solution.hierarchy();
             py::array_t<std::int64_t> out(static_cast<py::ssize_t>(h.leaves().size()));
             std::int64_t* p = out.mutable_data();
             for (const std::uint32_t e : h.leaves()) *p++ = h.patches()[h.element(e).patch].polygon;
             return out;
           },
           "The polygon of each leaf element, (elements,).")
      .def("element_areas",
           [](const PySolution& s) {
             const rad::PatchHierarchy& h = s.solution.hierarchy();
             Doubles out(static_cast<py::ssize_t>(h.leaves().size()));
             double* p = out.mutable_data();
             for (const std::uint32_t e : h.leaves()) *p++ = h.element(e).area;
             return out;
           },
           "Areas of the leaf elements, (elements,).")
      .def("element_exposure",
           [](const PySolution& s) {
             const rad::PatchHierarchy& h = s.solution.hierarchy();
             const std::vector<float>& exposure = s.solution.exposure();
             Doubles out(static_cast<py::ssize_t>(h.leaves().size()));
             double* p = out.mutable_data();
             for (const std::uint32_t e : h.leaves()) *p++ = exposure.empty() ? 1.0 : exposure[e];
             return out;
           },
           "The share of each leaf element's area that is not buried (inside a solid standing on it, such as "
           "the floor under a block resting on it), (elements,); all 1 where the solve did not measure it "
           "(radiosity::Solution::exposure()). A partly buried element's values are its open part's: its power "
           "is area x exposure x radiosity.")
      .def("element_centroids",
           [](const PySolution& s) {
             const rad::PatchHierarchy& h = s.solution.hierarchy();
             std::vector<glm::vec3> c;
             c.reserve(h.leaves().size());
             for (const std::uint32_t e : h.leaves()) c.push_back(h.element(e).centroid);
             return rgb_rows(c);
           },
           "Centroids of the leaf elements, (elements, 3).")
      .def("mesh_vertex_values",
           [](const PySolution& s, std::uint32_t mesh, const std::string& quantity) {
             return rgb_rows(s.solution.mesh_vertex_values(mesh, mesh_quantity(quantity)));
           },
           py::arg("mesh") = 0, py::arg("quantity") = "radiosity",
           "`quantity` per vertex of mesh `mesh` (Scene.mesh(mesh)['positions'] order), interpolated and "
           "averaged over the triangles that share the vertex, (vertices, 3).")
      .def("mesh_triangle_values",
           [](const PySolution& s, std::uint32_t mesh, const std::string& quantity) {
             return rgb_rows(s.solution.mesh_triangle_values(mesh, mesh_quantity(quantity)));
           },
           py::arg("mesh") = 0, py::arg("quantity") = "radiosity",
           "`quantity` per triangle of mesh `mesh`, (triangles, 3).")
      .def("group_radiosity",
           [](const PySolution& s, const std::string& group) { return vec3(s.solution.group_radiosity(group)); },
           py::arg("group"), "Area-weighted mean radiosity over a group, (3,).")
      .def("__repr__", [](const PySolution& s) {
        const rad::SolveReport& r = s.solution.report();
        return std::string("<radiosity.Solution: ") + name_of(s.solution.status(), kStatuses) + ", " +
               std::to_string(r.iterations) + " iterations, residual " + std::to_string(r.residual) + ", " +
               std::to_string(r.element_count) + " elements>";
      });

  m.def(
      "load_scene",
      [](const py::object& path, bool strict, bool photometric, bool local_origin) {
        const std::string file = py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
        rad::LoadOptions o;
        o.strict = strict;
        o.photometric = photometric;
        o.local_origin = local_origin;
        py::gil_scoped_release release;
        return rad::load_scene(file, o);
      },
      py::arg("path"), py::arg("strict") = false, py::arg("photometric") = false, py::arg("local_origin") = true,
      "load_scene(path, strict=False, photometric=False, local_origin=True) -> Scene\n\n"
      "Loads .obj (+ .mtl), .json, .gltf/.glb, .vs3 (View3D) or any format Assimp reads. strict: what a "
      "renderer would step over (degenerate faces, Kd >= 1, a missing MTL) is an error instead of a warning "
      "(Scene.warnings). photometric: light intensities in candela and lux. local_origin: an OBJ, glTF or .vs3 "
      "model far from the origin for its size (georeferenced coordinates) is held relative to a point near "
      "it (Scene.origin); False keeps the file's coordinates. Raises radiosity.Error naming "
      "the file and line. Thread safety: releases the GIL; concurrent calls are safe.");
  m.def(
      "find_polygons_facing_outward",
      [](const rad::Scene& scene) {
        rad::OutwardFacing outward;
        {
          py::gil_scoped_release release;
          outward = rad::find_polygons_facing_outward(scene);
        }
        py::list ids;
        for (const rad::PolygonId id : outward.polygons) ids.append(id);
        return ids;
      },
      py::arg("scene"),
      "find_polygons_facing_outward(scene) -> list of polygon ids\n\n"
      "The one-sided polygons whose front sees nothing while their back sees the scene all around, as the walls "
      "of a closed room or enclosure wound outwards do (radiosity check's warning): what "
      "scene.reverse_winding(ids) turns over. Deterministic (a fixed seed).");
  m.def(
      "find_inconsistent_winding",
      [](const rad::Scene& scene) {
        rad::InconsistentWinding found;
        {
          py::gil_scoped_release release;
          found = rad::find_inconsistent_winding(scene);
        }
        py::list ids;
        for (const rad::PolygonId id : found.polygons) ids.append(id);
        return ids;
      },
      py::arg("scene"),
      "find_inconsistent_winding(scene) -> list of polygon ids\n\n"
      "The one-sided polygons wound opposite to the polygons they share edges with (a flipped face of a mesh, "
      "black in a solve; radiosity check's warning): of each surface connected by shared edges, the orientation "
      "holding less area. What scene.reverse_winding(ids) turns over. No rays; deterministic.");
  m.def("cornell_box", &rad::cornell_box,
        "The Cornell box (geometry in mm, measured reflectances, light E = pi (17, 12, 4)); groups floor, ceiling, "
        "back_wall, red_wall, green_wall, light, short_block, tall_block. Thread safety: may be called "
        "concurrently.");
  m.def("solve", &solve, kSolveDoc, py::arg("scene"), py::arg("method") = "auto", py::kw_only(),
        py::arg("tolerance") = 1e-3, py::arg("max_iterations") = 0, py::arg("threads") = 0u, py::arg("seed") = 1u,
        py::arg("form_factors") = "auto", py::arg("max_patch_area") = 0.0, py::arg("max_element_area") = 0.0,
        py::arg("hemisphere_rays") = 1024u, py::arg("adaptive") = false, py::arg("epsilon") = 0.05,
        py::arg("memory_budget_bytes") = 0u, py::arg("specular_depth") = py::none(), py::arg("progress") = py::none());
  m.def("view_factor_matrix", &view_factor_matrix, kViewFactorDoc, py::arg("scene"), py::arg("level") = "polygon",
        py::kw_only(), py::arg("method") = "auto", py::arg("correction") = "none",
        py::arg("hemisphere_rays") = 1024u, py::arg("seed") = 1u, py::arg("threads") = 0u,
        py::arg("groups") = py::none(), py::arg("max_patch_area") = 0.0, py::arg("max_element_area") = 0.0,
        py::arg("epsilon") = 0.02, py::arg("memory_budget_bytes") = 0u, py::arg("dtype") = "float64",
        py::arg("return_info") = false, py::arg("progress") = py::none());
}
