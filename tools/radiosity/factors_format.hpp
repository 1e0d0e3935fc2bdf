// Output formats of `radiosity factors`: the group-to-group view-factor matrix as CSV or JSON.
// Header-only and free of CLI11, so the test suite can check the formats. The formats are a
// contract that scripts parse: see docs/FORM_FACTORS.md.
#pragma once

#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "radiosity/form_factors.hpp"

namespace cli {

/// One CSV field: quoted (with doubled quotes) when it holds a comma, a quote or a line break.
inline std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

/// A factor with 9 significant digits (the estimators compute single-precision rows).
inline std::string csv_number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.9g", x);
  return buffer;
}

/// Dense: a header row `,g1,g2,...` and one row `gi,F(gi->g1),F(gi->g2),...` per source group.
/// Sparse: a header row `from,to,factor` and one row per non-zero factor, row-major.
inline std::string factors_csv(const radiosity::GroupViewFactors& v, bool sparse) {
  std::string out;
  const std::size_t n = v.groups.size();
  if (sparse) {
    out += "from,to,factor\n";
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < n; ++k)
        if (v.at(i, k) != 0.0)
          out += csv_field(v.groups[i]) + "," + csv_field(v.groups[k]) + "," + csv_number(v.at(i, k)) + "\n";
    return out;
  }
  for (std::size_t k = 0; k < n; ++k) out += "," + csv_field(v.groups[k]);
  out += "\n";
  for (std::size_t i = 0; i < n; ++i) {
    out += csv_field(v.groups[i]);
    for (std::size_t k = 0; k < n; ++k) out += "," + csv_number(v.at(i, k));
    out += "\n";
  }
  return out;
}

/// {"method", "patches", "elements", "seconds", "groups": [{"name", "area"}...], and either
/// "factors": [[F(g0->g0), F(g0->g1), ...], ...] (dense, row = source) or, when sparse,
/// "factors": [{"from", "to", "factor"}...] with the non-zero entries only}.
inline std::string factors_json(const radiosity::GroupViewFactors& v, bool sparse, const std::string& method) {
  nlohmann::ordered_json j;
  j["method"] = method;
  j["patches"] = v.patch_count;
  j["elements"] = v.element_count;
  j["seconds"] = v.seconds;
  nlohmann::ordered_json groups = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < v.groups.size(); ++i) groups.push_back({{"name", v.groups[i]}, {"area", v.area[i]}});
  j["groups"] = std::move(groups);
  nlohmann::ordered_json factors = nlohmann::ordered_json::array();
  const std::size_t n = v.groups.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (sparse) {
      for (std::size_t k = 0; k < n; ++k)
        if (v.at(i, k) != 0.0) factors.push_back({{"from", v.groups[i]}, {"to", v.groups[k]}, {"factor", v.at(i, k)}});
    } else {
      nlohmann::ordered_json row = nlohmann::ordered_json::array();
      for (std::size_t k = 0; k < n; ++k) row.push_back(v.at(i, k));
      factors.push_back(std::move(row));
    }
  }
  j["factors"] = std::move(factors);
  return j.dump(2) + "\n";
}

}  // namespace cli
