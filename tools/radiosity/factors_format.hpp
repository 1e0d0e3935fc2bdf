// Output formats of `radiosity factors`: the group-to-group view-factor matrix as CSV or JSON,
// and the sparse polygon or element matrices as CSV triplets, JSON CSR or Matrix Market.
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

/// The dense group matrix of a group-level ViewFactorMatrix, for the group formats above.
inline radiosity::GroupViewFactors group_factors(const radiosity::ViewFactorMatrix& m, std::size_t patches) {
  radiosity::GroupViewFactors g;
  g.groups = m.names;
  g.area = m.area;
  const std::size_t n = m.rows();
  g.factors.assign(n * n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint64_t k = m.row_offsets[i]; k < m.row_offsets[i + 1]; ++k)
      g.factors[i * n + m.columns[k]] = static_cast<double>(m.values[k]);
  g.patch_count = patches;
  g.element_count = m.element_count;
  g.seconds = m.seconds;
  g.cancelled = m.cancelled;
  return g;
}

/// What a row or column of a polygon or element matrix names: the PolygonId or element id.
/// CSV: a header `from,to,factor` and one row per stored factor, row-major, `from` and `to`
/// being those ids (0-based).
inline std::string matrix_csv(const radiosity::ViewFactorMatrix& m) {
  std::string out = "from,to,factor\n";
  for (std::size_t i = 0; i < m.rows(); ++i)
    for (std::uint64_t k = m.row_offsets[i]; k < m.row_offsets[i + 1]; ++k)
      out += std::to_string(m.ids[i]) + "," + std::to_string(m.ids[m.columns[k]]) + "," +
             csv_number(static_cast<double>(m.values[k])) + "\n";
  return out;
}

/// The entries of Matrix Market's coordinate format, one line `row column factor` each, 1-based,
/// the rows of `m` numbered from first_row + 1.
inline void matrix_market_entries(const radiosity::ViewFactorMatrix& m, std::size_t first_row, std::string& out) {
  for (std::size_t i = 0; i < m.rows(); ++i)
    for (std::uint64_t k = m.row_offsets[i]; k < m.row_offsets[i + 1]; ++k)
      out += std::to_string(first_row + i + 1) + " " + std::to_string(m.columns[k] + 1) + " " +
             csv_number(static_cast<double>(m.values[k])) + "\n";
}

/// Matrix Market coordinate format (NIST), 1-based: row and column k are the matrix's k-th
/// surface (ids[k - 1]; the `%ids` comment lists them when they are not 0, 1, 2, ... in order).
inline std::string matrix_market(const radiosity::ViewFactorMatrix& m) {
  std::string out = "%%MatrixMarket matrix coordinate real general\n";
  out += std::string("% radiosity view factors F(row -> column): level ") + radiosity::to_string(m.level) + ", method " +
         m.method + "\n";
  bool identity = true;
  for (std::size_t i = 0; i < m.ids.size(); ++i) identity = identity && m.ids[i] == i;
  if (!identity) {
    out += "%ids";
    for (const std::uint32_t id : m.ids) out += " " + std::to_string(id);
    out += "\n";
  }
  out += std::to_string(m.rows()) + " " + std::to_string(m.rows()) + " " + std::to_string(m.non_zeros()) + "\n";
  matrix_market_entries(m, 0, out);
  return out;
}

/// One block of rows of a `total_rows`-square matrix (`factors --blocks`: a process's rows,
/// [first_row, first_row + block.rows())) in Matrix Market's coordinate format: a whole-size
/// matrix that holds the block's factors only, rows and columns numbered as in the whole matrix
/// (1-based), so the blocks' entries, concatenated in order, are the whole matrix's. The ids of
/// the rows are in the blocks' row files (row_sums_csv()).
inline std::string matrix_market_block(const radiosity::ViewFactorMatrix& block, std::size_t first_row,
                                       std::size_t total_rows, std::size_t index, std::size_t blocks) {
  std::string out = "%%MatrixMarket matrix coordinate real general\n";
  out += std::string("% radiosity view factors F(row -> column): level ") + radiosity::to_string(block.level) +
         ", method " + block.method + "\n";
  out += "% block " + std::to_string(index + 1) + " of " + std::to_string(blocks) + ": rows " +
         std::to_string(first_row + 1) + " to " + std::to_string(first_row + block.rows()) + " (1-based) of " +
         std::to_string(total_rows) + ", uncorrected; rows and columns number the whole matrix's rows\n";
  out += std::to_string(total_rows) + " " + std::to_string(total_rows) + " " + std::to_string(block.non_zeros()) + "\n";
  matrix_market_entries(block, first_row, out);
  return out;
}

/// JSON: {"level", "method", "correction", "rows", "non_zeros", "seconds", "ids", "area",
/// "row_offsets", "columns", "values", "sky", "sky_standard_error", and "row_standard_error" when the estimator states
/// one}: the CSR arrays as they are (0-based, columns index rows).
inline std::string matrix_json(const radiosity::ViewFactorMatrix& m, radiosity::ViewFactorCorrection correction) {
  nlohmann::ordered_json j;
  j["level"] = radiosity::to_string(m.level);
  j["method"] = m.method;
  j["correction"] = radiosity::to_string(correction);
  j["rows"] = m.rows();
  j["non_zeros"] = m.non_zeros();
  j["seconds"] = m.seconds;
  j["ids"] = m.ids;
  j["area"] = m.area;
  j["row_offsets"] = m.row_offsets;
  j["columns"] = m.columns;
  nlohmann::ordered_json values = nlohmann::ordered_json::array();
  for (const float v : m.values) values.push_back(static_cast<double>(v));
  j["values"] = std::move(values);
  j["sky"] = m.sky;
  j["sky_standard_error"] = m.sky_standard_error;
  if (!m.row_standard_error.empty()) j["row_standard_error"] = m.row_standard_error;
  return j.dump() + "\n";
}

/// Per row: `row,id,area,row_sum,sky,sky_standard_error,row_standard_error`: the row's sum of
/// factors, its sky view factor (ViewFactorMatrix::sky) with its standard error, and the row
/// sum's standard error where the estimator states one (empty otherwise); the group level names
/// the group in `id`. Rows are numbered from `first_row` (a block's, `factors --blocks`), 0-based.
inline std::string row_sums_csv(const radiosity::ViewFactorMatrix& m, std::size_t first_row = 0) {
  std::string out = "row,id,area,row_sum,sky,sky_standard_error,row_standard_error\n";
  for (std::size_t i = 0; i < m.rows(); ++i) {
    double sum = 0.0;
    for (std::uint64_t k = m.row_offsets[i]; k < m.row_offsets[i + 1]; ++k) sum += static_cast<double>(m.values[k]);
    const std::string id = m.names.empty() ? std::to_string(m.ids[i]) : csv_field(m.names[i]);
    out += std::to_string(first_row + i) + "," + id + "," + csv_number(m.area[i]) + "," + csv_number(sum) + "," +
           csv_number(m.sky[i]) + "," + csv_number(m.sky_standard_error[i]) + "," +
           (m.row_standard_error.empty() ? "" : csv_number(m.row_standard_error[i])) + "\n";
  }
  return out;
}

}  // namespace cli
