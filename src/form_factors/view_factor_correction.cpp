// Corrections of an estimated sparse view-factor matrix (view_factor_correction.hpp).
// Based on:
//   J. van Leersum, "A method for determining a consistent set of radiation view factors from a
//     set of generated values", Int. J. Heat Mass Transfer 32(3), 1989 (the least-squares
//     adjustment under the reciprocity and closure constraints, solved by Lagrange multipliers).
//   D. A. Lawson, "An improved method for smoothing approximate exchange areas", Int. J. Heat
//     Mass Transfer 38(16), 1995 (weighting each correction by the factor's own size, so that
//     zero factors stay zero and no factor changes sign but where the estimate is far off).
//   G. N. Walton, "Calculation of obstructed view factors by adaptive integration", NISTIR 6925,
//     NIST 2002 (View3D's adjustment of enclosure rows, which this option replaces).
//   Y. Saad, "Iterative Methods for Sparse Linear Systems", 2nd ed., SIAM 2003, ch. 9
//     (conjugate gradients with a Jacobi preconditioner).
//
// With transports G_ij = A_i F_ij, reciprocity is G = G^T and closure sum_j G_ij = A_i. The
// reciprocity step takes G_ij = (A_i F_ij + A_j F_ji) / 2, the least-squares symmetric matrix
// nearest to the estimate. Closure then minimises sum_ij (G'_ij - G_ij)^2 / G_ij (changes
// weighted by the factor's own size) under sum_j G'_ij = A_i and G' = G'^T: the Lagrange
// conditions give G'_ij = G_ij (1 + l_i + l_j), with the multipliers l solving
//   (D + G) l = A - g,   g_i = sum_j G_ij,  D = diag(g),
// a symmetric positive semi-definite system (l^T (D + G) l = 1/2 sum_ij G_ij (l_i + l_j)^2),
// sparse like G itself, solved by preconditioned conjugate gradients.
#include "form_factors/view_factor_correction.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "core/assert.hpp"
#include "core/parallel.hpp"

namespace radiosity::detail {
namespace {

/// Rows per block of a deterministic parallel sum: each block's partial sum is made in row
/// order, and the partials are added in block order.
constexpr std::size_t kRowBlock = 4096;
/// Closure: the multipliers are solved until every row's residual is below this fraction of
/// its area (the row sums then hold to it, before the factors are rounded to float).
constexpr double kClosureTolerance = 1e-11;
constexpr int kMaxIterations = 20000;
/// Closure passes: after each, factors the correction made negative are dropped and the
/// multipliers solved again without them.
constexpr int kMaxClampPasses = 8;

template <typename RowFn>
double block_sum(unsigned threads, std::size_t rows, const RowFn& row_value) {
  const std::size_t blocks = (rows + kRowBlock - 1) / kRowBlock;
  std::vector<double> partial(blocks, 0.0);
  parallel_for(threads, blocks, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t b = begin; b < end; ++b) {
      double s = 0.0;
      for (std::size_t i = b * kRowBlock, last = std::min(rows, (b + 1) * kRowBlock); i < last; ++i) s += row_value(i);
      partial[b] = s;
    }
  });
  double sum = 0.0;
  for (const double p : partial) sum += p;
  return sum;
}

/// Rows per block of the reciprocity pass: enough blocks for the threads in a small matrix, few
/// enough in a large one that the blocks' binary searches (one per row a block reaches) stay
/// well below one per entry.
std::size_t lookup_block(std::size_t rows) { return std::clamp<std::size_t>(rows / 16, 64, kRowBlock); }

/// F_ji for the rows i of one block of consecutive rows, asked in increasing i: a cursor per row
/// j that only moves forward (rows are sorted by column), so a block costs its entries plus one
/// binary search per row it reaches. (A binary search per entry took an eighth of the exact
/// mode's time in the enclosure benchmark, rows of 2 600 entries; a transposed copy would cost
/// the matrix's memory again.) One per thread: it is the thread's cursors.
class TransposedLookup {
 public:
  explicit TransposedLookup(const SparseRowsF& m) : m_(m), cursor_(m.rows(), 0), block_(m.rows(), kNone) {}

  /// F_ji for i in the block whose first row is `first`.
  float at(std::size_t j, std::uint32_t i, std::uint32_t first) {
    std::uint64_t& c = cursor_[j];
    const std::uint64_t end = m_.offsets[j + 1];
    if (block_[j] != first) {
      block_[j] = first;
      const auto row = m_.columns.begin();
      c = static_cast<std::uint64_t>(std::lower_bound(row + static_cast<std::ptrdiff_t>(m_.offsets[j]),
                                                      row + static_cast<std::ptrdiff_t>(end), first) -
                                     row);
    }
    RADIOSITY_ASSERT(c == m_.offsets[j] || m_.columns[c - 1] < i);  // i increases within a block
    while (c < end && m_.columns[c] < i) ++c;
    return c < end && m_.columns[c] == i ? m_.values[c] : 0.0f;
  }

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;
  const SparseRowsF& m_;
  std::vector<std::uint64_t> cursor_;
  std::vector<std::uint32_t> block_;  ///< per row j: the block its cursor belongs to
};

/// G_ij = (A_i F_ij + A_j F_ji) / 2 on the union of the two patterns; measures reciprocity.
SparseRowsF symmetric_transport(const SparseRowsF& F, const std::vector<double>& area, unsigned threads,
                                double& reciprocity_before) {
  const std::size_t n = F.rows();
  // Entries (j, i) that row j lacks while row i has (i, j): G_ji = A_i F_ij / 2. Found per block
  // of rows, kept in block order, then sorted by (row, column), so the result does not depend
  // on the thread count.
  struct Missing {
    std::uint32_t row, column;
    float value;
  };
  const std::size_t block = lookup_block(n), blocks = (n + block - 1) / block;
  std::vector<std::vector<Missing>> missing(blocks);
  std::vector<double> worst(blocks, 0.0);
  parallel_for(threads, blocks, 1, [&](std::size_t begin, std::size_t end) {
    TransposedLookup transposed(F);
    for (std::size_t b = begin; b < end; ++b) {
      const auto first = static_cast<std::uint32_t>(b * block);
      for (std::size_t i = b * block, last = std::min(n, (b + 1) * block); i < last; ++i) {
        for (std::uint64_t k = F.offsets[i]; k < F.offsets[i + 1]; ++k) {
          const std::uint32_t j = F.columns[k];
          const double tij = area[i] * static_cast<double>(F.values[k]);
          const double tji = area[j] * static_cast<double>(transposed.at(j, static_cast<std::uint32_t>(i), first));
          // The change of F_ij that reciprocity asks for, in units of view factor.
          worst[b] = std::max(worst[b], std::fabs(tij - tji) / area[i]);
          if (tji == 0.0) missing[b].push_back({j, static_cast<std::uint32_t>(i), static_cast<float>(0.5 * tij)});
        }
      }
    }
  });
  reciprocity_before = 0.0;
  for (const double w : worst) reciprocity_before = std::max(reciprocity_before, w);
  std::vector<Missing> extra;
  {
    std::size_t total = 0;
    for (const auto& m : missing) total += m.size();
    extra.reserve(total);
    for (auto& m : missing) {
      extra.insert(extra.end(), m.begin(), m.end());
      m = {};
    }
  }
  std::sort(extra.begin(), extra.end(),
            [](const Missing& a, const Missing& b) { return std::tie(a.row, a.column) < std::tie(b.row, b.column); });

  SparseRowsF G;
  G.offsets.assign(n + 1, 0);
  std::vector<std::uint64_t> extra_first(n + 1, 0);
  for (const Missing& m : extra) ++extra_first[m.row + 1];
  for (std::size_t i = 0; i < n; ++i) extra_first[i + 1] += extra_first[i];
  for (std::size_t i = 0; i < n; ++i)
    G.offsets[i + 1] = G.offsets[i] + (F.offsets[i + 1] - F.offsets[i]) + (extra_first[i + 1] - extra_first[i]);
  G.columns.resize(G.offsets[n]);
  G.values.resize(G.offsets[n]);
  parallel_for(threads, blocks, 1, [&](std::size_t begin_block, std::size_t end_block) {
    TransposedLookup transposed(F);
    for (std::size_t i = begin_block * block, end = std::min(n, end_block * block); i < end; ++i) {
      const auto first = static_cast<std::uint32_t>(i / block * block);
      // Merge row i's own entries with the ones it lacked, both increasing by column.
      std::uint64_t a = F.offsets[i], a_end = F.offsets[i + 1], x = extra_first[i], x_end = extra_first[i + 1];
      std::uint64_t out = G.offsets[i];
      while (a < a_end || x < x_end) {
        if (x == x_end || (a < a_end && F.columns[a] < extra[x].column)) {
          const std::uint32_t j = F.columns[a];
          const double tij = area[i] * static_cast<double>(F.values[a]);
          const double tji = area[j] * static_cast<double>(transposed.at(j, static_cast<std::uint32_t>(i), first));
          G.columns[out] = j;
          G.values[out] = static_cast<float>(0.5 * (tij + tji));
          ++a;
        } else {
          G.columns[out] = extra[x].column;
          G.values[out] = extra[x].value;
          ++x;
        }
        ++out;
      }
      RADIOSITY_ASSERT(out == G.offsets[i + 1]);
    }
  });
  return G;
}

/// (D + G) x for the closure system, rows with g_i = 0 left out (their x is 0).
void closure_product(const SparseRowsF& G, const std::vector<double>& g, const std::vector<double>& x,
                     std::vector<double>& y, unsigned threads) {
  parallel_for(threads, G.rows(), kRowBlock, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      double s = g[i] * x[i];
      for (std::uint64_t k = G.offsets[i]; k < G.offsets[i + 1]; ++k) s += static_cast<double>(G.values[k]) * x[G.columns[k]];
      y[i] = s;
    }
  });
}

/// Solves (D + G) l = A - g by Jacobi-preconditioned conjugate gradients over the rows flagged
/// in `closed`; returns the iterations. The other rows keep l_i = 0: their sums are not
/// constrained (a row that saw nothing before the reciprocity step, which may have given it
/// tiny entries from grazing pairs, would otherwise need a huge multiplier).
int closure_multipliers(const SparseRowsF& G, const std::vector<double>& area, const std::vector<char>& closed,
                        unsigned threads, std::vector<double>& l) {
  const std::size_t n = G.rows();
  std::vector<double> g(n, 0.0), diagonal(n, 0.0);
  parallel_for(threads, n, kRowBlock, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      double s = 0.0, self = 0.0;
      for (std::uint64_t k = G.offsets[i]; k < G.offsets[i + 1]; ++k) {
        s += static_cast<double>(G.values[k]);
        if (G.columns[k] == i) self = static_cast<double>(G.values[k]);
      }
      g[i] = s;
      diagonal[i] = s + self;
    }
  });
  std::vector<char> active(n, 0);
  for (std::size_t i = 0; i < n; ++i) active[i] = closed[i] && g[i] > 0.0;
  l.assign(n, 0.0);
  std::vector<double> r(n, 0.0), z(n, 0.0), p(n, 0.0), q(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) r[i] = active[i] ? area[i] - g[i] : 0.0;
  auto converged = [&] {
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      if (active[i]) worst = std::max(worst, std::fabs(r[i]) / area[i]);
    return worst <= kClosureTolerance;
  };
  auto precondition = [&] {
    for (std::size_t i = 0; i < n; ++i) z[i] = active[i] ? r[i] / diagonal[i] : 0.0;
  };
  if (converged()) return 0;
  precondition();
  p = z;
  double rz = block_sum(threads, n, [&](std::size_t i) { return r[i] * z[i]; });
  int it = 0;
  while (it < kMaxIterations) {
    ++it;
    closure_product(G, g, p, q, threads);
    for (std::size_t i = 0; i < n; ++i)
      if (!active[i]) q[i] = 0.0;  // the equations of the unconstrained rows are not part of the system
    const double pq = block_sum(threads, n, [&](std::size_t i) { return p[i] * q[i]; });
    if (!(pq > 0.0)) break;  // singular direction: rows that cannot be closed (say, two plates alone)
    const double alpha = rz / pq;
    for (std::size_t i = 0; i < n; ++i) {
      l[i] += alpha * p[i];
      r[i] -= alpha * q[i];
    }
    if (converged()) break;
    precondition();
    const double rz_next = block_sum(threads, n, [&](std::size_t i) { return r[i] * z[i]; });
    const double beta = rz_next / rz;
    rz = rz_next;
    for (std::size_t i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
  }
  return it;
}

/// Sets to 0 the entries that G_ij (1 + l_i + l_j) would make negative (symmetric pairs
/// together, as l_i + l_j is), and returns how many there were: the caller solves again
/// without them.
std::size_t zero_negative(SparseRowsF& G, const std::vector<double>& l) {
  std::size_t negative = 0;
  for (std::size_t i = 0; i < G.rows(); ++i)
    for (std::uint64_t k = G.offsets[i]; k < G.offsets[i + 1]; ++k)
      if (G.values[k] > 0.0f && 1.0 + l[i] + l[G.columns[k]] < 0.0) {
        G.values[k] = 0.0f;
        ++negative;
      }
  return negative;
}

/// G'_ij = G_ij (1 + l_i + l_j), in place.
void scale_by_multipliers(SparseRowsF& G, const std::vector<double>& l) {
  for (std::size_t i = 0; i < G.rows(); ++i)
    for (std::uint64_t k = G.offsets[i]; k < G.offsets[i + 1]; ++k)
      G.values[k] = static_cast<float>(std::max(0.0, static_cast<double>(G.values[k]) * (1.0 + l[i] + l[G.columns[k]])));
}

/// Removes stored zeros.
void drop_zeros(SparseRowsF& m) {
  std::uint64_t out = 0, first = 0;
  for (std::size_t i = 0; i < m.rows(); ++i) {
    const std::uint64_t last = m.offsets[i + 1];
    for (std::uint64_t k = first; k < last; ++k)
      if (m.values[k] > 0.0f) {
        m.columns[out] = m.columns[k];
        m.values[out] = m.values[k];
        ++out;
      }
    first = last;
    m.offsets[i + 1] = out;
  }
  m.columns.resize(out);
  m.values.resize(out);
}

}  // namespace

ViewFactorCorrectionReport correct_view_factors(ViewFactorCorrection correction, const std::vector<double>& area,
                                                SparseRowsF& F, unsigned threads) {
  const std::size_t n = F.rows();
  RADIOSITY_ASSERT(area.size() == n);
  ViewFactorCorrectionReport report;
  // Closure before: |1 - row sum|, the largest and the area-weighted RMS, over the rows that
  // see something (the others are counted apart; the enclosure correction leaves them open).
  std::vector<char> closed(n, 0);
  {
    double total_area = 0.0, squares = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (F.offsets[i + 1] == F.offsets[i]) {
        ++report.empty_rows;
        continue;
      }
      closed[i] = 1;
      double s = 0.0;
      for (std::uint64_t k = F.offsets[i]; k < F.offsets[i + 1]; ++k) s += static_cast<double>(F.values[k]);
      const double e = std::fabs(1.0 - s);
      report.row_sum_error_before = std::max(report.row_sum_error_before, e);
      squares += area[i] * e * e;
      total_area += area[i];
    }
    report.row_sum_rms_before = total_area > 0.0 ? std::sqrt(squares / total_area) : 0.0;
  }
  SparseRowsF G = symmetric_transport(F, area, threads, report.reciprocity_before);
  if (correction == ViewFactorCorrection::none) return report;

  if (correction == ViewFactorCorrection::enclosure) {
    std::vector<double> l;
    for (int pass = 1;; ++pass) {
      report.iterations += closure_multipliers(G, area, closed, threads, l);
      if (pass == kMaxClampPasses) break;  // any factor still negative is clamped to 0 below
      const std::size_t negative = zero_negative(G, l);
      report.clamped += negative;
      if (negative == 0) break;
    }
    scale_by_multipliers(G, l);
    drop_zeros(G);
  }

  // Back to factors, and what changed against the estimate.
  double squares = 0.0;
  std::uint64_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double inverse = area[i] > 0.0 ? 1.0 / area[i] : 0.0;
    // Row i before (F) and after (G), both increasing by column: a change per column either
    // has, including estimates that the correction removed (clamped to 0).
    std::uint64_t a = F.offsets[i], a_end = F.offsets[i + 1];
    for (std::uint64_t k = G.offsets[i]; k < G.offsets[i + 1]; ++k) {
      for (; a < a_end && F.columns[a] < G.columns[k]; ++a) {
        const double removed = static_cast<double>(F.values[a]);
        report.largest_change = std::max(report.largest_change, removed);
        squares += removed * removed;
        ++count;
      }
      const bool both = a < a_end && F.columns[a] == G.columns[k];
      const double before = both ? static_cast<double>(F.values[a++]) : 0.0;
      G.values[k] = static_cast<float>(static_cast<double>(G.values[k]) * inverse);
      const double change = std::fabs(static_cast<double>(G.values[k]) - before);
      report.largest_change = std::max(report.largest_change, change);
      squares += change * change;
      ++count;
    }
    for (; a < a_end; ++a) {
      const double removed = static_cast<double>(F.values[a]);
      report.largest_change = std::max(report.largest_change, removed);
      squares += removed * removed;
      ++count;
    }
  }
  report.rms_change = count > 0 ? std::sqrt(squares / static_cast<double>(count)) : 0.0;
  F = std::move(G);
  return report;
}

}  // namespace radiosity::detail
