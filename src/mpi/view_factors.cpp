// The view-factor matrix with its rows split among MPI processes (radiosity/mpi.hpp,
// docs/MPI.md): each process computes a block of rows balanced by source elements
// (detail::ViewFactorRows, the single process's code), and rank 0 gathers them and corrects the
// whole matrix, or each process keeps its block (view_factor_block()).
#include <algorithm>
#include <chrono>
#include <string>

#include "form_factors/view_factor_rows.hpp"
#include "mpi/mpi_communicator.hpp"
#include "radiosity/mpi.hpp"

namespace radiosity {
inline namespace v1 {
namespace mpi {

namespace {

using detail::MpiCommunicator;

/// Values per message of the gather, below an int's range.
constexpr std::size_t kMessageValues = std::size_t{1} << 28;

/// Gathers each process's `local` (count[r] values on process r) into `all` on rank 0, in rank
/// order, by point-to-point messages of at most kMessageValues values (a gathered matrix may
/// hold more than an int counts). Collective.
template <typename T>
void gather_to_root(const MpiCommunicator& comm, const std::vector<T>& local, const std::vector<std::uint64_t>& count,
                    MPI_Datatype type, std::vector<T>& all) {
  constexpr int kTag = 1607;
  if (comm.rank() != 0) {
    for (std::size_t at = 0; at < local.size(); at += kMessageValues) {
      const std::size_t n = std::min(kMessageValues, local.size() - at);
      MPI_Send(local.data() + at, static_cast<int>(n), type, 0, kTag, comm.comm());
    }
    return;
  }
  std::uint64_t total = 0;
  for (const std::uint64_t c : count) total += c;
  all.resize(static_cast<std::size_t>(total));
  std::copy(local.begin(), local.end(), all.begin());
  std::size_t offset = local.size();
  for (int r = 1; r < comm.size(); ++r) {
    const auto size = static_cast<std::size_t>(count[static_cast<std::size_t>(r)]);
    for (std::size_t at = 0; at < size; at += kMessageValues) {
      const std::size_t n = std::min(kMessageValues, size - at);
      MPI_Recv(all.data() + offset + at, static_cast<int>(n), type, r, kTag, comm.comm(), MPI_STATUS_IGNORE);
    }
    offset += size;
  }
}

/// One process's block of rows and where every block lies.
struct Block {
  ViewFactorMatrix rows;
  std::vector<std::size_t> offsets;  ///< rank r's rows are [offsets[r], offsets[r + 1])
  std::size_t total_rows = 0;
  /// find_overlaps() of the scene at the polygon level (the rows' own), for the end of the
  /// matrix; empty at the element level, whose rows are a scene of their own.
  std::vector<PolygonOverlap> overlaps;
};

/// Checks as view_factor_matrix() does, then computes this process's rows; errors and cancel
/// are collective. Polygon and element levels only.
Block compute_block(const Scene& scene, const ViewFactorOptions& options, const MpiCommunicator& comm) {
  Block block;
  detail::collectively(comm, [&] {
    if (scene.polygons().empty()) throw Error(ErrorCode::invalid_scene, "view_factor_matrix: the scene has no polygons");
    detail::view_factor_estimator_options(options);  // throws for options out of range, as view_factor_matrix()
    if (options.method == ViewFactorMethod::hierarchical && !(options.epsilon > 0.0f && options.epsilon <= 1.0f))
      throw Error(ErrorCode::invalid_argument,
                  "view_factor_matrix: epsilon must be in (0, 1], got " + std::to_string(options.epsilon));
    detail::ProgressGate gate(options.on_progress);
    Progress start;
    start.phase = Phase::form_factors;
    const bool cancelled = !gate.report(start, true);
    const detail::ViewFactorRows rows(scene, options);
    block.offsets = detail::weighted_blocks(rows.source_offsets(), comm.size());
    block.total_rows = rows.rows();
    const std::size_t first = block.offsets[static_cast<std::size_t>(comm.rank())];
    const std::size_t last = cancelled ? first : block.offsets[static_cast<std::size_t>(comm.rank()) + 1];
    // compute() names the method that ran, and why when FormFactorMethod::automatic chose it
    // (the same choice on every process: the estimate's pairs come from the seed's stream).
    rows.compute(first, last, gate, block.rows);
    if (options.level == ViewFactorLevel::polygon) block.overlaps = rows.overlaps();
    block.rows.cancelled = block.rows.cancelled || cancelled;
  });
  block.rows.cancelled = comm.any(block.rows.cancelled);
  return block;
}

/// The scene's overlaps when the block has them (the polygon level), else null.
const std::vector<PolygonOverlap>* polygon_overlaps(const Block& block) {
  return block.rows.level == ViewFactorLevel::polygon ? &block.overlaps : nullptr;
}

}  // namespace

ViewFactorMatrix view_factor_matrix(const Scene& scene, const ViewFactorOptions& options, MPI_Comm mpi_comm) {
  const auto t0 = std::chrono::steady_clock::now();
  const MpiCommunicator comm(mpi_comm);
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };

  if (options.level == ViewFactorLevel::group) {
    // Group sums run over every element in turn: not split (rank 0 alone).
    ViewFactorMatrix out;
    out.level = options.level;
    out.row_offsets.assign(1, 0);
    detail::collectively(comm, [&] {
      if (comm.rank() == 0) out = radiosity::view_factor_matrix(scene, options);
    });
    if (comm.rank() != 0) out.seconds = seconds();
    return out;
  }

  Block block = compute_block(scene, options, comm);
  ViewFactorMatrix& own = block.rows;
  if (own.cancelled || comm.size() == 1) {
    // Nothing gathered: each process keeps what it computed (one process: the whole matrix).
    detail::collectively(comm, [&] {
      if (comm.size() == 1) {
        detail::finish_view_factor_matrix(scene, options, polygon_overlaps(block), own);
      } else {
        detail::fill_missing_sky(own);
      }
    });
    own.seconds = seconds();
    return own;
  }

  // Rank 0 gathers the blocks in rank order: rows, then their factors.
  const auto ranks = static_cast<std::size_t>(comm.size());
  std::vector<std::uint64_t> rows(ranks), entries(ranks), elements(ranks);
  for (std::size_t r = 0; r < ranks; ++r) rows[r] = block.offsets[r + 1] - block.offsets[r];
  std::uint64_t own_entries = own.non_zeros(), own_elements = own.element_count;
  MPI_Gather(&own_entries, 1, MPI_UINT64_T, entries.data(), 1, MPI_UINT64_T, 0, comm.comm());
  MPI_Gather(&own_elements, 1, MPI_UINT64_T, elements.data(), 1, MPI_UINT64_T, 0, comm.comm());
  std::vector<std::uint64_t> own_counts(own.rows());
  for (std::size_t i = 0; i < own.rows(); ++i) own_counts[i] = own.row_offsets[i + 1] - own.row_offsets[i];
  const bool monte_carlo = own.method == to_string(FormFactorMethod::monte_carlo);  // the same on every process

  ViewFactorMatrix out;
  std::vector<std::uint64_t> counts;
  gather_to_root(comm, own.ids, rows, MPI_UINT32_T, out.ids);
  gather_to_root(comm, own.area, rows, MPI_DOUBLE, out.area);
  gather_to_root(comm, own_counts, rows, MPI_UINT64_T, counts);
  gather_to_root(comm, own.columns, entries, MPI_UINT32_T, out.columns);
  gather_to_root(comm, own.values, entries, MPI_FLOAT, out.values);
  if (monte_carlo) gather_to_root(comm, own.row_standard_error, rows, MPI_DOUBLE, out.row_standard_error);
  gather_to_root(comm, own.sky, rows, MPI_DOUBLE, out.sky);
  gather_to_root(comm, own.sky_standard_error, rows, MPI_DOUBLE, out.sky_standard_error);

  if (comm.rank() != 0) {
    detail::fill_missing_sky(own);
    // Rank 0's correction may fail (an open scene under the enclosure correction): then here too.
    detail::collectively(comm, [] {});
    own.seconds = seconds();
    return own;
  }
  out.level = own.level;
  out.method = own.method;
  out.method_reason = own.method_reason;
  out.row_offsets.assign(counts.size() + 1, 0);
  for (std::size_t i = 0; i < counts.size(); ++i) out.row_offsets[i + 1] = out.row_offsets[i] + counts[i];
  for (const std::uint64_t e : elements) out.element_count += static_cast<std::size_t>(e);
  detail::collectively(comm, [&] { detail::finish_view_factor_matrix(scene, options, polygon_overlaps(block), out); });
  out.seconds = seconds();
  return out;
}

ViewFactorBlock view_factor_block(const Scene& scene, const ViewFactorOptions& options, MPI_Comm mpi_comm) {
  const auto t0 = std::chrono::steady_clock::now();
  const MpiCommunicator comm(mpi_comm);
  detail::collectively(comm, [&] {
    if (options.level == ViewFactorLevel::group)
      throw Error(ErrorCode::invalid_argument,
                  "mpi::view_factor_block: the group level is not split into blocks (use mpi::view_factor_matrix())");
    if (options.method == ViewFactorMethod::hierarchical)
      throw Error(ErrorCode::invalid_argument,
                  "mpi::view_factor_block: the hierarchical links' factors are made reciprocal over the whole matrix: "
                  "use mpi::view_factor_matrix()");
    if (options.correction != ViewFactorCorrection::none)
      throw Error(ErrorCode::invalid_argument,
                  std::string("mpi::view_factor_block: the ") + to_string(options.correction) +
                      " correction needs the whole matrix: blocks are uncorrected (correction none), or use "
                      "mpi::view_factor_matrix()");
  });
  Block block = compute_block(scene, options, comm);
  ViewFactorBlock out;
  const auto rank = static_cast<std::size_t>(comm.rank());
  out.first_row = block.offsets[rank];
  out.total_rows = block.total_rows;
  detail::fill_missing_sky(block.rows);
  // Every block's figures, for a manifest.
  const std::uint64_t own[2] = {block.rows.non_zeros(), block.rows.element_count};
  std::vector<std::uint64_t> all(2 * static_cast<std::size_t>(comm.size()));
  MPI_Allgather(own, 2, MPI_UINT64_T, all.data(), 2, MPI_UINT64_T, comm.comm());
  for (std::size_t r = 0; r < static_cast<std::size_t>(comm.size()); ++r)
    out.blocks.push_back(RowBlock{block.offsets[r], block.offsets[r + 1], all[2 * r], static_cast<std::size_t>(all[2 * r + 1])});
  out.rows = std::move(block.rows);
  out.rows.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace mpi
}  // namespace v1
}  // namespace radiosity
