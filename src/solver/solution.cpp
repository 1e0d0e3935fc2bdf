#include <cmath>
#include <string>

#include "radiosity/solver.hpp"

#include "core/parallel.hpp"

namespace radiosity {
inline namespace v1 {

Solution::Solution(PatchHierarchy hierarchy, std::vector<Rgb> radiosity, std::vector<std::string> groups,
                   SolveStatus status, SolveReport report, Rgb ambient, std::vector<Rgb> ambient_radiosity,
                   std::vector<Rgb> back_radiosity, std::vector<Rgb> irradiance,
                   std::vector<Rgb> direct_irradiance)
    : hierarchy_(std::move(hierarchy)),
      radiosity_(std::move(radiosity)),
      groups_(std::move(groups)),
      status_(status),
      report_(std::move(report)),
      ambient_(ambient),
      ambient_radiosity_(std::move(ambient_radiosity)),
      back_radiosity_(std::move(back_radiosity)),
      irradiance_(std::move(irradiance)),
      direct_irradiance_(std::move(direct_irradiance)) {
  if (!back_radiosity_.empty() && back_radiosity_.size() != hierarchy_.elements().size())
    throw Error(ErrorCode::invalid_argument, "Solution: back_radiosity must be empty or have one value per element");
  if (!direct_irradiance_.empty() && direct_irradiance_.size() != hierarchy_.elements().size())
    throw Error(ErrorCode::invalid_argument, "Solution: direct_irradiance must be empty or have one value per element");
  if (!irradiance_.empty() && irradiance_.size() != hierarchy_.elements().size())
    throw Error(ErrorCode::invalid_argument, "Solution: irradiance must be empty or have one value per element");
  if (!ambient_radiosity_.empty() && ambient_radiosity_.size() != hierarchy_.elements().size())
    throw Error(ErrorCode::invalid_argument, "Solution: ambient_radiosity must be empty or have one value per element");
  if (radiosity_.size() != hierarchy_.elements().size())
    throw Error(ErrorCode::invalid_argument, "Solution: " + std::to_string(radiosity_.size()) +
                                                 " radiosity values for " +
                                                 std::to_string(hierarchy_.elements().size()) + " elements");
}

Rgb Solution::patch_radiosity(std::uint32_t patch) const {
  return radiosity_.at(hierarchy_.patches().at(patch).root);
}

std::vector<Rgb> Solution::radiosity_with_ambient() const {
  std::vector<Rgb> out = radiosity_;
  for (std::size_t i = 0; i < ambient_radiosity_.size(); ++i) out[i] += ambient_radiosity_[i];
  return out;
}

std::vector<Rgb> Solution::vertex_radiosity(bool with_ambient) const {
  return hierarchy_.vertex_values(with_ambient ? radiosity_with_ambient() : radiosity_, exposure_);
}

std::vector<Rgb> Solution::vertex_back_radiosity() const {
  if (back_radiosity_.empty()) return {};
  return hierarchy_.vertex_values(back_radiosity_);
}

GroupId Solution::group_id(std::string_view group) const {
  for (std::size_t i = 0; i < groups_.size(); ++i)
    if (groups_[i] == group) return static_cast<GroupId>(i);
  std::string known;
  for (const std::string& g : groups_) known += (known.empty() ? "" : ", ") + g;
  throw Error(ErrorCode::invalid_argument,
              "no group named '" + std::string(group) + "' in the scene (groups: " + known + ")");
}

namespace {

/// The weight of element `e`'s value, of area `area`, in a mean over area: the area times its
/// exposure (Solution::exposure(); empty: 1), since its value is its open part's.
double open_area(float area, const std::vector<float>& exposure, std::uint32_t e) {
  const double a = area;
  return exposure.empty() ? a : a * static_cast<double>(exposure[e]);
}

/// Area-weighted mean of `values` (per element id) over the patches of group `g`, buried parts
/// counting as 0.
Rgb group_mean(const PatchHierarchy& hierarchy, const std::vector<Rgb>& values, const std::vector<float>& exposure,
               GroupId g) {
  glm::dvec3 sum(0.0);
  double area = 0.0;
  for (const Patch& p : hierarchy.patches())
    if (p.group == g) {
      sum += open_area(p.area, exposure, p.root) * glm::dvec3(values[p.root]);
      area += p.area;
    }
  return area > 0.0 ? Rgb(sum / area) : Rgb(0.0f);
}

}  // namespace

Rgb Solution::group_radiosity(std::string_view group) const {
  return group_mean(hierarchy_, radiosity_, exposure_, group_id(group));
}

Rgb Solution::group_back_radiosity(std::string_view group) const {
  const GroupId g = group_id(group);
  return back_radiosity_.empty() ? Rgb(0.0f) : group_mean(hierarchy_, back_radiosity_, {}, g);
}

const std::vector<LightGroupSolution>& Solution::light_groups() const {
  static const std::vector<LightGroupSolution> none;
  return light_groups_ ? *light_groups_ : none;
}

const LightGroupSolution& Solution::solved_light_group(std::size_t light_group, const char* caller) const {
  if (light_group >= light_groups().size())
    throw Error(ErrorCode::invalid_argument, std::string("Solution::") + caller + ": light group " +
                                                 std::to_string(light_group) + " does not exist (" +
                                                 std::to_string(light_groups().size()) + " light groups)");
  return (*light_groups_)[light_group];
}

Rgb Solution::light_group_radiosity(std::size_t light_group, std::string_view group) const {
  const LightGroupSolution& g = solved_light_group(light_group, "light_group_radiosity");
  return light_group_weights_[light_group] * group_mean(hierarchy_, g.radiosity, exposure_, group_id(group));
}

double Solution::group_area(std::string_view group) const {
  const GroupId g = group_id(group);
  double area = 0.0;
  for (const Patch& p : hierarchy_.patches())
    if (p.group == g) area += p.area;
  return area;
}

namespace {

/// `quantity` from a solution's (or a light group's) radiosity B, irradiance H and its direct
/// part D, per element id; `n` elements.
std::vector<Rgb> quantity_values(std::size_t n, const std::vector<Rgb>& B, const std::vector<Rgb>& H,
                                 const std::vector<Rgb>& D, Quantity quantity) {
  auto held = [&](const std::vector<Rgb>& v, const char* what) -> const std::vector<Rgb>& {
    if (v.size() != n)
      throw Error(ErrorCode::invalid_argument, std::string("Solution: no ") + what +
                                                   " in this solution (a cancelled solve has no direct irradiance)");
    return v;
  };
  switch (quantity) {
    case Quantity::radiosity: return B;
    case Quantity::irradiance: return held(H, "irradiance");
    case Quantity::direct_irradiance: return held(D, "direct irradiance");
    case Quantity::indirect_irradiance: {
      const std::vector<Rgb>& h = held(H, "irradiance");
      const std::vector<Rgb>& d = held(D, "direct irradiance");
      std::vector<Rgb> out(h.size());
      // Rounding may leave a hair below 0 where all light is direct.
      for (std::size_t e = 0; e < h.size(); ++e) out[e] = glm::max(h[e] - d[e], Rgb(0.0f));
      return out;
    }
  }
  throw Error(ErrorCode::invalid_argument, "Solution: unknown quantity");
}

}  // namespace

std::vector<Rgb> Solution::element_values(Quantity quantity) const {
  return quantity_values(hierarchy_.elements().size(), radiosity_, irradiance_, direct_irradiance_, quantity);
}

std::vector<Rgb> Solution::light_group_values(std::size_t light_group, Quantity quantity) const {
  const LightGroupSolution& g = solved_light_group(light_group, "light_group_values");
  std::vector<Rgb> out =
      quantity_values(hierarchy_.elements().size(), g.radiosity, g.irradiance, g.direct_irradiance, quantity);
  for (Rgb& v : out) v *= light_group_weights_[light_group];
  return out;
}

const SolvedMesh& Solution::solved_mesh(MeshId mesh) const {
  if (mesh >= meshes_.size())
    throw Error(ErrorCode::invalid_argument, "Solution: mesh " + std::to_string(mesh) + " does not exist (the scene had " +
                                                 std::to_string(meshes_.size()) + " meshes)");
  return meshes_[mesh];
}

namespace {

/// Per polygon, its first patch and patch count (PatchHierarchy meshes polygons in order, so a
/// polygon's patches are consecutive); sized to cover every polygon the hierarchy and `mesh`
/// name, so a lookup never leaves the table.
std::vector<std::pair<std::uint32_t, std::uint32_t>> patches_by_polygon(const PatchHierarchy& h, const SolvedMesh& mesh) {
  std::size_t polygons = 0;
  for (const Patch& p : h.patches()) polygons = std::max<std::size_t>(polygons, p.polygon + std::size_t{1});
  for (PolygonId p : mesh.triangle_polygon)
    if (p != kNone) polygons = std::max<std::size_t>(polygons, p + std::size_t{1});
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out(polygons, {kNone, 0});
  for (std::uint32_t j = 0; j < h.patches().size(); ++j) {
    auto& range = out[h.patches()[j].polygon];
    if (range.first == kNone) range.first = j;
    ++range.second;
  }
  return out;
}

}  // namespace

std::vector<Rgb> Solution::mesh_triangle_values(MeshId mesh, Quantity quantity) const {
  const SolvedMesh& m = solved_mesh(mesh);
  const std::vector<Rgb> values = element_values(quantity);
  const auto ranges = patches_by_polygon(hierarchy_, m);
  std::vector<Rgb> out(m.triangle_polygon.size(), Rgb(0.0f));
  for (std::size_t t = 0; t < out.size(); ++t) {
    const PolygonId p = m.triangle_polygon[t];
    if (p == kNone || ranges[p].first == kNone) continue;
    glm::dvec3 sum(0.0);
    double area = 0.0;
    for (std::uint32_t j = ranges[p].first; j < ranges[p].first + ranges[p].second; ++j) {
      const Patch& patch = hierarchy_.patches()[j];
      sum += open_area(patch.area, exposure_, patch.root) * glm::dvec3(values[patch.root]);
      area += patch.area;
    }
    if (area > 0.0) out[t] = Rgb(sum / area);
  }
  return out;
}

std::vector<Rgb> Solution::mesh_vertex_values(MeshId mesh, Quantity quantity) const {
  const SolvedMesh& m = solved_mesh(mesh);
  const std::vector<Rgb> at_vertex = hierarchy_.vertex_values(element_values(quantity), exposure_);
  const auto ranges = patches_by_polygon(hierarchy_, m);
  std::vector<glm::dvec3> sum(m.positions.size(), glm::dvec3(0.0));
  std::vector<double> weight(m.positions.size(), 0.0);
  for (std::size_t t = 0; t < m.triangle_polygon.size(); ++t) {
    const PolygonId p = m.triangle_polygon[t];
    if (p == kNone || ranges[p].first == kNone) continue;
    double area = 0.0;
    for (std::uint32_t j = ranges[p].first; j < ranges[p].first + ranges[p].second; ++j)
      area += hierarchy_.patches()[j].area;
    // Each corner of the triangle is the hierarchy vertex of its patches at that position: the
    // polygon's corners are the host's positions bit for bit, and the lattice keeps them, so
    // the search stops at the exact one (nearest stays the rule should that ever change). A
    // vertex shared with smooth neighbours has the same value from every triangle around it.
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = m.indices[3 * t + static_cast<std::size_t>(k)];
      std::uint32_t nearest = kNone;
      float best = 0.0f;
      for (std::uint32_t j = ranges[p].first; j < ranges[p].first + ranges[p].second; ++j) {
        const Element& root = hierarchy_.element(hierarchy_.patches()[j].root);
        for (int c = 0; c < root.corner_count(); ++c) {
          const std::uint32_t id = root.corners[static_cast<std::size_t>(c)];
          const glm::vec3 d = hierarchy_.vertices()[id] - m.positions[v];
          const float d2 = glm::dot(d, d);
          if (nearest == kNone || d2 < best) {
            nearest = id;
            best = d2;
          }
        }
        if (best == 0.0f) break;
      }
      sum[v] += area * glm::dvec3(at_vertex[nearest]);
      weight[v] += area;
    }
  }
  std::vector<Rgb> out(m.positions.size(), Rgb(0.0f));
  for (std::size_t v = 0; v < out.size(); ++v)
    if (weight[v] > 0.0) out[v] = Rgb(sum[v] / weight[v]);
  return out;
}

void Solution::set_exposure(std::vector<float> exposure) {
  if (!exposure.empty() && exposure.size() != hierarchy_.elements().size())
    throw Error(ErrorCode::invalid_argument, "Solution::set_exposure: " + std::to_string(exposure.size()) +
                                                 " values for " + std::to_string(hierarchy_.elements().size()) +
                                                 " elements");
  exposure_ = std::move(exposure);
}

void Solution::set_light_groups(std::vector<LightGroupSolution> groups) {
  const std::size_t n = hierarchy_.elements().size();
  for (const LightGroupSolution& g : groups) {
    auto check = [&](const std::vector<Rgb>& v, const char* what, bool may_be_empty) {
      if (v.size() != n && !(may_be_empty && v.empty()))
        throw Error(ErrorCode::invalid_argument, "Solution::set_light_groups: light group '" + g.name + "' has " +
                                                     std::to_string(v.size()) + " " + what + " values for " +
                                                     std::to_string(n) + " elements");
    };
    check(g.radiosity, "radiosity", false);
    check(g.back_radiosity, "back radiosity", true);
    check(g.irradiance, "irradiance", false);
    check(g.direct_irradiance, "direct irradiance", false);
  }
  light_group_weights_.assign(groups.size(), Rgb(1.0f));
  light_groups_ = groups.empty() ? nullptr
                                 : std::make_shared<const std::vector<LightGroupSolution>>(std::move(groups));
}

Solution Solution::relight(const std::vector<Rgb>& weights) const {
  const std::vector<LightGroupSolution>& groups = light_groups();
  if (weights.size() != groups.size())
    throw Error(ErrorCode::invalid_argument, "Solution::relight: " + std::to_string(weights.size()) +
                                                 " weights for " + std::to_string(groups.size()) +
                                                 " light groups (solve with SolveOptions::separate_light_groups)");
  for (std::size_t k = 0; k < weights.size(); ++k)
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(weights[k][c]))
        throw Error(ErrorCode::invalid_argument,
                    "Solution::relight: the weight of light group '" + groups[k].name + "' is not finite");
  const std::size_t n = hierarchy_.elements().size();
  const bool backs = !back_radiosity_.empty();
  std::vector<Rgb> B(n, Rgb(0.0f)), back(backs ? n : 0, Rgb(0.0f)), H(n, Rgb(0.0f)), direct(n, Rgb(0.0f));
  // The weighted sums, elements split among threads; the groups are read, never copied.
  auto weigh = [&](std::size_t begin, std::size_t end, std::vector<Rgb> LightGroupSolution::*field,
                   std::vector<Rgb>& sum) {
    for (std::size_t k = 0; k < groups.size(); ++k) {
      const std::vector<Rgb>& from = groups[k].*field;
      if (from.empty()) continue;
      const Rgb w = weights[k];
      for (std::size_t e = begin; e < end; ++e) sum[e] += w * from[e];
    }
  };
  detail::parallel_for(0, n, 4096, [&](std::size_t begin, std::size_t end) {
    weigh(begin, end, &LightGroupSolution::radiosity, B);
    weigh(begin, end, &LightGroupSolution::irradiance, H);
    weigh(begin, end, &LightGroupSolution::direct_irradiance, direct);
    if (backs) weigh(begin, end, &LightGroupSolution::back_radiosity, back);
  });
  Solution out(PatchHierarchy(hierarchy_), std::move(B), groups_, status_, report_, Rgb(0.0f), {}, std::move(back),
               std::move(H), std::move(direct));
  out.meshes_ = meshes_;
  out.origin_ = origin_;
  out.exposure_ = exposure_;
  out.light_groups_ = light_groups_;
  out.light_group_weights_ = weights;
  return out;
}

}  // namespace v1
}  // namespace radiosity
