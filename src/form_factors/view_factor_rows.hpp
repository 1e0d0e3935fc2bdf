// view_factor_matrix() in stages, so that the MPI module (src/mpi/, docs/MPI.md) can compute a
// block of rows on each process: the rows of the polygon and element levels, any block of them
// at a time, and the end that needs the whole matrix (the enclosure check, the correction).
// A block's rows are bit for bit the whole matrix's: each element's row draws from its own
// random streams, and a row is summed over its own elements in element order.
// Private to the library.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/progress.hpp"
#include "radiosity/form_factors.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// The estimator options view_factor_matrix() applies: options.form_factors resolved, automatic
/// as ray_cast, front sides only (no transmission, no specular paths). Throws for bad options.
FormFactorOptions view_factor_estimator_options(const ViewFactorOptions& options);

/// The polygon or element level of view_factor_matrix(): the scene meshed, which polygons (or
/// elements) are rows, and each row's source elements.
/// Thread safety: const member functions may be called concurrently.
class ViewFactorRows {
 public:
  /// Selects the rows (options.groups), meshes the scene (options.mesh) and, for the element
  /// level, makes the scene whose polygons are the leaf elements. `options.level` must be
  /// polygon or element. Throws as view_factor_matrix() does for a bad group name. With
  /// `meshing` (a callback, not empty) the meshing reports Phase::meshing through it and stops
  /// when it returns false: then cancelled() and there are no rows.
  ViewFactorRows(const Scene& scene, const ViewFactorOptions& options, const ProgressFn* meshing = nullptr);
  ~ViewFactorRows();
  ViewFactorRows(const ViewFactorRows&) = delete;
  ViewFactorRows& operator=(const ViewFactorRows&) = delete;

  std::size_t rows() const;
  /// The meshing callback cancelled.
  bool cancelled() const;
  /// rows() + 1 entries: source_offsets()[r] is the number of source elements of rows [0, r)
  /// (what a block balanced by elements, not rows, splits).
  const std::vector<std::uint64_t>& source_offsets() const;
  /// find_overlaps() of the scene the rows are computed on: the given scene at the polygon
  /// level, the scene of its leaf elements at the element level.
  const std::vector<PolygonOverlap>& overlaps() const;

  /// Rows [begin, end) of the matrix into `out`: ids, area, row_offsets (end - begin + 1 of
  /// them, from 0), columns (every row's columns, numbered as the whole matrix's rows), values,
  /// row_standard_error (Monte Carlo), sky and sky_standard_error (rays per element, so a
/// block's are the whole matrix's), element_count (the block's source elements), method
  /// and level; cancelled when `gate` says so (the rows after the last whole chunk are left
  /// empty; in the exact mode, every row of the block). The exact mode (ray_cast) integrates
  /// polygon pairs without rays (exact_view_factors.hpp); the other estimators' element rows
  /// are summed per polygon. Makes its own estimator (Embree BVH). Reports Phase::form_factors with the
  /// fraction of the block done.
  void compute(std::size_t begin, std::size_t end, ProgressGate& gate, ViewFactorMatrix& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Zero sky view factors (and their errors) for a matrix cancelled before its sky was cast.
void fill_missing_sky(ViewFactorMatrix& m);

/// The end of view_factor_matrix() on the whole matrix `m` (of `scene`, made with `options`):
/// the enclosure check (throws Error{invalid_argument} for a scene that is no enclosure), the
/// correction options.correction names (with its report), the warnings and notes (z-fighting;
/// the rows that see no surface, told apart). `overlaps`: find_overlaps(scene) when the caller
/// has it, else null (then searched here). Nothing for a cancelled matrix but zero skies where
/// they are missing.
void finish_view_factor_matrix(const Scene& scene, const ViewFactorOptions& options,
                               const std::vector<PolygonOverlap>* overlaps, ViewFactorMatrix& m);

}  // namespace radiosity::detail
