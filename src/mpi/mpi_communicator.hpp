// detail::Communicator over an MPI communicator, and collective errors: what src/mpi/'s
// functions share. Private to the library.
#pragma once

#include <mpi.h>

#include <functional>
#include <vector>

#include "core/communicator.hpp"

namespace radiosity::detail {

/// Communicator's collectives as MPI calls on `comm` (not owned).
/// Thread safety: the calling thread only.
class MpiCommunicator final : public Communicator {
 public:
  /// Throws Error{invalid_argument} when MPI is not initialised or `comm` is MPI_COMM_NULL.
  explicit MpiCommunicator(MPI_Comm comm);

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void all_gather(std::vector<Rgb>& values, const std::vector<std::size_t>& offsets) const override;
  bool any(bool flag) const override;
  std::uint64_t sum(std::uint64_t value) const override;

  MPI_Comm comm() const { return comm_; }

 private:
  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
};

/// Runs `body` on every process of `comm` and makes its failure collective: when it throws on
/// some process, every process throws, the lowest failing rank's Error (code and message; an
/// exception of another type as ErrorCode::internal). Collective.
void collectively(const MpiCommunicator& comm, const std::function<void()>& body);

/// The count of an MPI call, which is an int: throws Error{invalid_argument} naming `what`
/// when `count` does not fit.
int mpi_count(std::size_t count, const char* what);

}  // namespace radiosity::detail
