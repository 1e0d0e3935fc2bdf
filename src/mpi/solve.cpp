// solve() as a Jacobi iteration split among MPI processes (radiosity/mpi.hpp, docs/MPI.md):
// the solver's own code (detail::solve_split()) with an MPI communicator.
#include "mpi/mpi_communicator.hpp"
#include "radiosity/mpi.hpp"
#include "solver/split_solve.hpp"

namespace radiosity {
inline namespace v1 {
namespace mpi {

Solution solve(const Scene& scene, const SolveOptions& options, MPI_Comm comm) {
  const detail::MpiCommunicator split(comm);
  return detail::solve_split(scene, options, split);
}

}  // namespace mpi
}  // namespace v1
}  // namespace radiosity
