// Beyond one machine: the view-factor matrix's rows and Jacobi's sweeps split among the
// processes of an MPI communicator (docs/MPI.md). Built and installed only with the CMake
// option RADIOSITY_MPI (RADIOSITY_HAS_MPI is then 1 in radiosity/version.hpp, and the library
// links MPI::MPI_CXX); includes <mpi.h>.
//
// Every function here is collective: each process of `comm` calls it with the same scene and
// options, in the same order. Each process holds the whole scene and mesh and builds its own
// ray scene once; the work (rows) is split into contiguous blocks. The results are bit for bit
// those of one process with the same options and seed. The caller initialises MPI
// (MPI_Init_thread with at least MPI_THREAD_FUNNELED: the library calls MPI from the calling
// thread only, its worker threads never) and finalises it.
#pragma once

#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "radiosity/export.hpp"
#include "radiosity/form_factors.hpp"
#include "radiosity/solver.hpp"

namespace radiosity {
inline namespace v1 {
namespace mpi {

/// view_factor_matrix(scene, options) with its rows split among the processes of `comm`: at the
/// polygon and element levels each process computes a contiguous block of rows, the blocks
/// holding about equal numbers of source elements (a row's cost), and rank 0 gathers them and
/// applies options.correction. Rank 0 returns the whole matrix, bit for bit the single-process
/// result (seconds aside); every other rank returns its own block only, uncorrected (its rows
/// named by `ids`, its columns numbering the whole matrix's rows, `sky` from its row sums,
/// `correction` empty). With ViewFactorMethod::hierarchical every process refines the same
/// links (the whole scene's) and computes its block's rows from them. The group level is not
/// split: rank 0 computes it alone and the other ranks return an empty matrix of that level. Memory
/// per process: the scene, its mesh and ray scene, and its block's rows; rank 0 holds the whole
/// matrix as well. on_progress is called on every process for its block; a cancel stops that
/// process's block, and the matrix is then `cancelled` on every rank, which returns its own
/// (incomplete) block: nothing is gathered. Errors are collective:
/// an Error any process meets (bad options, an open scene refused by the enclosure
/// correction on rank 0) is thrown on every process, with the same code and message.
/// Thread safety: collective; one call at a time per communicator.
RADIOSITY_API ViewFactorMatrix view_factor_matrix(const Scene& scene, const ViewFactorOptions& options, MPI_Comm comm);

/// The rows [first_row, last_row) of one process, in view_factor_block().
struct RowBlock {
  std::size_t first_row = 0;
  std::size_t last_row = 0;
  std::uint64_t non_zeros = 0;        ///< factors stored in the block
  std::size_t source_elements = 0;    ///< the block's source elements (its cost)
};

/// One process's share of a view-factor matrix, for matrices larger than one node's memory:
/// nothing is gathered. Thread safety: a plain value.
struct ViewFactorBlock {
  /// This process's rows, [first_row, first_row + rows.rows()) of the whole matrix, uncorrected:
  /// ids, area, CSR (columns number the whole matrix's rows), sky from the row sums,
  /// row_standard_error (Monte Carlo), element_count of the block, method, cancelled (on every
  /// rank when any was cancelled); `correction` empty.
  ViewFactorMatrix rows;
  std::size_t first_row = 0;
  std::size_t total_rows = 0;       ///< rows of the whole matrix
  std::vector<RowBlock> blocks;     ///< every process's block, by rank (a manifest's contents)
};

/// The rows of this process only (see view_factor_matrix() for how they are split). The
/// correction needs the whole matrix: options.correction must be none. Polygon and element
/// levels only. Throws Error{invalid_argument} for ViewFactorLevel::group,
/// ViewFactorMethod::hierarchical (its factors are made reciprocal over the whole matrix) or a
/// correction, and as view_factor_matrix() does; errors are
/// collective. Memory per process: the scene, its mesh and ray scene, and its block.
/// Thread safety: collective; one call at a time per communicator.
RADIOSITY_API ViewFactorBlock view_factor_block(const Scene& scene, const ViewFactorOptions& options, MPI_Comm comm);

/// solve(scene, options) as a Jacobi iteration split among the processes of `comm`: every
/// process meshes the scene, computes and keeps the form-factor rows of its contiguous block of
/// unknowns (element sides, split evenly) and its share of the lights' first shot (every P-th
/// element: their costs vary), and per sweep computes its block of the irradiance H = F B; the blocks are exchanged
/// (MPI_Allgatherv: 12 bytes per unknown reach every process), after which every process
/// updates all of B and the residual in one process's order, and a flag is all-reduced (a
/// cancel asked for by any process's on_progress stops every process at the end of that
/// sweep, or of the form factors). Every rank returns the complete Solution, bit for bit that of
/// solve(scene, options) in one process (radiosity, irradiance, direct irradiance, back sides,
/// light groups, adaptive subdivision, the residual history); the report's timings and
/// form_factor_bytes are the process's own. options.method must be SolverMethod::jacobi:
/// Gauss-Seidel reads values of the sweep it is in, so block Jacobi between processes with
/// Gauss-Seidel within them would be another iteration, not bit-identical to a single
/// Gauss-Seidel solve. Any estimator (ray_cast, monte_carlo, hemicube, analytic). Memory per
/// process: the scene, mesh, ray scene and system, B and H of every unknown, and the rows of
/// its block (SolveOptions::memory_budget_bytes is checked against those). Throws
/// Error{invalid_argument} for another method, and as solve() does; errors in the options and
/// the scene are met by every process alike.
/// Thread safety: collective; one call at a time per communicator.
RADIOSITY_API Solution solve(const Scene& scene, const SolveOptions& options, MPI_Comm comm);

}  // namespace mpi
}  // namespace v1
}  // namespace radiosity
