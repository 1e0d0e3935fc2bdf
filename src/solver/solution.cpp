#include "radiosity/solver.hpp"

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
  return hierarchy_.vertex_values(with_ambient ? radiosity_with_ambient() : radiosity_);
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

/// Area-weighted mean of `values` (per element id) over the patches of group `g`.
Rgb group_mean(const PatchHierarchy& hierarchy, const std::vector<Rgb>& values, GroupId g) {
  glm::dvec3 sum(0.0);
  double area = 0.0;
  for (const Patch& p : hierarchy.patches())
    if (p.group == g) {
      sum += static_cast<double>(p.area) * glm::dvec3(values[p.root]);
      area += p.area;
    }
  return area > 0.0 ? Rgb(sum / area) : Rgb(0.0f);
}

}  // namespace

Rgb Solution::group_radiosity(std::string_view group) const {
  return group_mean(hierarchy_, radiosity_, group_id(group));
}

Rgb Solution::group_back_radiosity(std::string_view group) const {
  const GroupId g = group_id(group);
  return back_radiosity_.empty() ? Rgb(0.0f) : group_mean(hierarchy_, back_radiosity_, g);
}

double Solution::group_area(std::string_view group) const {
  const GroupId g = group_id(group);
  double area = 0.0;
  for (const Patch& p : hierarchy_.patches())
    if (p.group == g) area += p.area;
  return area;
}

}  // namespace v1
}  // namespace radiosity
