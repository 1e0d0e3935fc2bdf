// solve() split among processes (docs/MPI.md), for the MPI module (src/mpi/): the same
// Problem, with a Communicator. Private to the library.
#pragma once

#include "core/communicator.hpp"
#include "radiosity/solver.hpp"

namespace radiosity::detail {

/// solve(scene, options) split among the processes of `split`: each holds the whole problem,
/// computes the form-factor rows of its block of unknowns and its share of the lights' first
/// shot, and gathers every sweep's irradiance, so every process returns the Solution one process would
/// (bit for bit; the report's timings and form_factor_bytes are the process's own). Collective.
/// Throws Error{invalid_argument} unless options.method is SolverMethod::jacobi, and as
/// solve() does.
Solution solve_split(const Scene& scene, const SolveOptions& options, const Communicator& split);

}  // namespace radiosity::detail
