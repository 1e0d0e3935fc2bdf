// detail::Communicator over MPI, and collective errors (mpi_communicator.hpp).
#include "mpi/mpi_communicator.hpp"

#include <climits>
#include <cstring>
#include <exception>
#include <string>

namespace radiosity::detail {

namespace {

/// Throws Error{internal} naming the call when an MPI call fails (the default MPI error handler
/// aborts before this; a communicator with MPI_ERRORS_RETURN gets here).
void check(int code, const char* call) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw Error(ErrorCode::internal, std::string(call) + " failed: " + std::string(text, static_cast<std::size_t>(length)));
}

}  // namespace

int mpi_count(std::size_t count, const char* what) {
  if (count > static_cast<std::size_t>(INT_MAX))
    throw Error(ErrorCode::invalid_argument, std::string(what) + ": " + std::to_string(count) +
                                                 " values in one MPI message, more than an int counts; use more "
                                                 "processes or mpi::view_factor_block()");
  return static_cast<int>(count);
}

MpiCommunicator::MpiCommunicator(MPI_Comm comm) : comm_(comm) {
  int initialised = 0, finalised = 0;
  MPI_Initialized(&initialised);
  MPI_Finalized(&finalised);
  if (!initialised || finalised)
    throw Error(ErrorCode::invalid_argument, "radiosity::mpi: MPI is not initialised (call MPI_Init_thread first)");
  if (comm == MPI_COMM_NULL) throw Error(ErrorCode::invalid_argument, "radiosity::mpi: the communicator is MPI_COMM_NULL");
  check(MPI_Comm_rank(comm, &rank_), "MPI_Comm_rank");
  check(MPI_Comm_size(comm, &size_), "MPI_Comm_size");
}

void MpiCommunicator::all_gather(std::vector<Rgb>& values, const std::vector<std::size_t>& offsets) const {
  static_assert(sizeof(Rgb) == 3 * sizeof(float), "Rgb is three floats");
  std::vector<int> counts(static_cast<std::size_t>(size_)), displacements(static_cast<std::size_t>(size_));
  for (std::size_t r = 0; r < counts.size(); ++r) {
    counts[r] = mpi_count(3 * (offsets[r + 1] - offsets[r]), "all_gather");
    displacements[r] = mpi_count(3 * offsets[r], "all_gather");
  }
  check(MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, values.data(), counts.data(), displacements.data(),
                       MPI_FLOAT, comm_),
        "MPI_Allgatherv");
}

bool MpiCommunicator::any(bool flag) const {
  int local = flag ? 1 : 0, global = 0;
  check(MPI_Allreduce(&local, &global, 1, MPI_INT, MPI_LOR, comm_), "MPI_Allreduce");
  return global != 0;
}

std::uint64_t MpiCommunicator::sum(std::uint64_t value) const {
  std::uint64_t global = 0;
  check(MPI_Allreduce(&value, &global, 1, MPI_UINT64_T, MPI_SUM, comm_), "MPI_Allreduce");
  return global;
}

void collectively(const MpiCommunicator& comm, const std::function<void()>& body) {
  int code = 0;
  std::string message;
  try {
    body();
  } catch (const Error& e) {
    code = static_cast<int>(e.code()) + 1;
    message = e.what();
  } catch (const std::exception& e) {
    code = static_cast<int>(ErrorCode::internal) + 1;
    message = e.what();
  }
  // The lowest failing rank speaks for all.
  int failing = code != 0 ? comm.rank() : comm.size(), first = 0;
  check(MPI_Allreduce(&failing, &first, 1, MPI_INT, MPI_MIN, comm.comm()), "MPI_Allreduce");
  if (first == comm.size()) return;
  long long length = static_cast<long long>(message.size());
  check(MPI_Bcast(&code, 1, MPI_INT, first, comm.comm()), "MPI_Bcast");
  check(MPI_Bcast(&length, 1, MPI_LONG_LONG, first, comm.comm()), "MPI_Bcast");
  message.resize(static_cast<std::size_t>(length));
  check(MPI_Bcast(message.data(), static_cast<int>(length), MPI_CHAR, first, comm.comm()), "MPI_Bcast");
  throw Error(static_cast<ErrorCode>(code - 1), message);
}

}  // namespace radiosity::detail
