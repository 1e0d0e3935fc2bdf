// Corrections of an estimated sparse view-factor matrix (view_factor_matrix(), docs/VIEW_FACTORS.md,
// "Correction"): reciprocity by averaging each pair's two directions, and closure of an
// enclosure by a weighted least-squares adjustment that keeps the sparsity.
// Private to the library.
#pragma once

#include <cstdint>
#include <vector>

#include "radiosity/form_factors.hpp"

namespace radiosity::detail {

/// A square sparse matrix in compressed rows, columns increasing within a row.
struct SparseRowsF {
  std::vector<std::uint64_t> offsets;  ///< rows + 1
  std::vector<std::uint32_t> columns;
  std::vector<float> values;

  std::size_t rows() const { return offsets.empty() ? 0 : offsets.size() - 1; }
};

/// Corrects the factors `F` (row i: F(i -> j), areas `area` per row, > 0 or 0 for a row that
/// sends nothing) in place as `correction` asks, and returns what it changed and how far the
/// estimates were from reciprocity and closure before. ViewFactorCorrection::none only
/// measures. Deterministic at any thread count (sums in row order or fixed blocks).
/// Thread safety: pure apart from `F`.
ViewFactorCorrectionReport correct_view_factors(ViewFactorCorrection correction, const std::vector<double>& area,
                                                SparseRowsF& F, unsigned threads);

}  // namespace radiosity::detail
