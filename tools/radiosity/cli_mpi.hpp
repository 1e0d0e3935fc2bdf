// The command line under mpirun (docs/MPI.md): MPI for the process's lifetime when the tool is
// built with it (RADIOSITY_HAS_MPI), the process's rank, and agreement on an error. Without MPI
// every function here is that of a single process, so the commands need no #if of their own
// beyond the split calls.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

#include "radiosity/version.hpp"

#if RADIOSITY_HAS_MPI
#include <mpi.h>
#endif

namespace cli {

#if RADIOSITY_HAS_MPI

/// Whether a launcher started this process as part of an MPI job: mpirun or mpiexec (Open MPI
/// sets OMPI_COMM_WORLD_SIZE; MPICH, Intel MPI and PMI-2 launchers PMI_SIZE or PMI_RANK; PMIx
/// launchers, srun among them, PMIX_RANK). Without one the command is one process and does not
/// start MPI at all: an Open MPI singleton start costs about 0.4 s, which every `radiosity
/// check` paid.
inline bool launched_by_mpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMI_RANK", "PMIX_RANK"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

/// Whether MPI runs in this process (MpiSession started it).
inline bool mpi_running() {
  int initialized = 0, finalized = 0;
  MPI_Initialized(&initialized);
  MPI_Finalized(&finalized);
  return initialized != 0 && finalized == 0;
}

/// This process's rank in MPI_COMM_WORLD (0 without mpirun).
inline int process_rank() {
  int rank = 0;
  if (mpi_running()) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

/// The processes of MPI_COMM_WORLD (1 without mpirun).
inline int process_count() {
  int size = 1;
  if (mpi_running()) MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

/// MPI from construction to destruction (main's first statement) when a launcher started the
/// process (launched_by_mpi()), initialised with MPI_THREAD_FUNNELED (the library calls MPI from
/// the main thread only); otherwise nothing, and the commands run as one process. Ranks other
/// than 0 send stdout and stderr to /dev/null: rank 0 prints the summary and writes the output,
/// and the errors every process meets alike (bad input, bad options) are printed once.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv) {
    if (!launched_by_mpi()) return;
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    started_ = true;
    if (process_rank() != 0) {
      if (!std::freopen("/dev/null", "w", stdout)) std::fclose(stdout);
      if (!std::freopen("/dev/null", "w", stderr)) std::fclose(stderr);
    }
  }
  ~MpiSession() {
    if (started_) MPI_Finalize();
  }
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

 private:
  bool started_ = false;
};

/// The first (lowest-rank) non-empty `error` of any process, on every process; "" when none
/// failed. Collective: for what may fail on one process only (writing its own file).
inline std::string agree_on_error(const std::string& error) {
  if (process_count() == 1) return error;
  int failing = error.empty() ? process_count() : process_rank(), first = 0;
  MPI_Allreduce(&failing, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == process_count()) return {};
  std::string message = error;
  int length = static_cast<int>(message.size());
  MPI_Bcast(&length, 1, MPI_INT, first, MPI_COMM_WORLD);
  message.resize(static_cast<std::size_t>(length));
  MPI_Bcast(message.data(), length, MPI_CHAR, first, MPI_COMM_WORLD);
  return message;
}

#else

inline int process_rank() { return 0; }
inline int process_count() { return 1; }

class MpiSession {
 public:
  MpiSession(int&, char**&) {}
};

inline std::string agree_on_error(const std::string& error) { return error; }

#endif

}  // namespace cli
