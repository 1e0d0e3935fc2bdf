// bench_mpi: strong scaling of the work radiosity/mpi.hpp splits among MPI processes
// (docs/MPI.md), on issue #15's procedural city (city.hpp, a few thousand facets by default):
//  - the polygon-level view factors (Monte Carlo rows), uncorrected and with the reciprocity
//    correction (which rank 0 applies alone, after the gather);
//  - the distributed Jacobi solve under the city's sky (the lights' first shot and the rows
//    split by blocks of unknowns, one all-gather of H per sweep);
// each on the first k processes of MPI_COMM_WORLD for k = 1, 2, 4, ... up to its size, one
// thread per process (the processes that wait do not spin), then the exchange of one sweep
// alone (MPI_Allgatherv of the unknowns' 12 bytes, and the all-reduce of a flag), timed over many
// repetitions, and the bytes it moves. It checks that every split result is bit for bit the
// one-process result, and states each process's form-factor memory and peak RSS. As a
// shared-memory reference, rank 0 also runs both with every hardware thread in one process.
//
// Run: mpirun -n 2 --bind-to none build/bin/bench_mpi [--blocks N] [--facet METRES] [--rays N]
// (--bind-to none: else OpenMPI pins each process to one core, and the threaded reference too).
#include <mpi.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include <radiosity/mpi.hpp>
#include <radiosity/radiosity.hpp>

#include "bench_common.hpp"
#include "city.hpp"
#include "core/communicator.hpp"

namespace rad = radiosity;

namespace {

struct Args {
  bench::CityOptions city{1, 1.5, 1};  ///< one block of 1.5 m facets: about 5 000 facets
  std::uint32_t rays = rad::FormFactorOptions{}.hemisphere_rays;
};

int usage(const char* bad) {
  if (bad) std::fprintf(stderr, "bench_mpi: bad argument '%s'\n", bad);
  std::fprintf(stderr, "usage: mpirun -n P --bind-to none bench_mpi [--blocks N] [--facet METRES] [--rays N]\n");
  return bad ? 2 : 0;
}

int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

int world_size() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

/// Waits for every process of MPI_COMM_WORLD without spinning (a spinning idle process would
/// take a core from the ones that work).
void quiet_barrier() {
  MPI_Request request;
  MPI_Ibarrier(MPI_COMM_WORLD, &request);
  int done = 0;
  while (!done) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (!done) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

/// This process's CPU time, s (every thread's).
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// The smallest of `value` over `comm`, on every process.
double min_over(double value, MPI_Comm comm) {
  double out = 0.0;
  MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_MIN, comm);
  return out;
}

/// The sum of `value` over `comm`, on every process.
double sum_over(double value, MPI_Comm comm) {
  double out = 0.0;
  MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_SUM, comm);
  return out;
}

/// The largest of `value` over `comm`, on every process.
double max_over(double value, MPI_Comm comm) {
  double out = 0.0;
  MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_MAX, comm);
  return out;
}

template <typename T>
bool same(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool same_matrix(const rad::ViewFactorMatrix& a, const rad::ViewFactorMatrix& b) {
  return a.ids == b.ids && a.row_offsets == b.row_offsets && a.columns == b.columns && same(a.values, b.values) &&
         same(a.sky, b.sky) && same(a.row_standard_error, b.row_standard_error);
}

bool same_solution(const rad::Solution& a, const rad::Solution& b) {
  return same(a.radiosity(), b.radiosity()) && same(a.irradiance(), b.irradiance()) &&
         same(a.direct_irradiance(), b.direct_irradiance()) && a.report().iterations == b.report().iterations &&
         same(a.report().residual_history, b.report().residual_history);
}

/// One run on k processes: wall times (the slowest process's) and the figures to print.
struct Run {
  int processes = 1;
  double factors = 0.0, factors_corrected = 0.0;  ///< s, view_factor_matrix without / with reciprocity
  double factors_fastest = 0.0;                   ///< s, the fastest process's wall time (uncorrected)
  double factors_cpu = 0.0, solve_cpu = 0.0;      ///< s, CPU time summed over the processes
  double solve = 0.0;                             ///< s, the whole Jacobi solve
  double solve_lights = 0.0, solve_factors = 0.0, solve_sweeps = 0.0;  ///< s, its parts (slowest process)
  int iterations = 0;
  double factor_mib = 0.0;  ///< the solve's form-factor rows per process, MiB (the largest)
  bool identical = true;    ///< bit for bit the one-process results (rank 0 compares)
};

}  // namespace

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    char* end = nullptr;
    if (arg == "--help" || arg == "-h") {
      MPI_Finalize();
      return usage(nullptr);
    } else if (arg == "--blocks" && has_value) {
      a.city.blocks = static_cast<int>(std::strtol(argv[++i], &end, 10));
    } else if (arg == "--facet" && has_value) {
      a.city.facet_size = std::strtod(argv[++i], &end);
    } else if (arg == "--rays" && has_value) {
      a.rays = static_cast<std::uint32_t>(std::strtoul(argv[++i], &end, 10));
    } else {
      MPI_Finalize();
      return usage(argv[i]);
    }
    if (end && *end != '\0') {
      MPI_Finalize();
      return usage(argv[i]);
    }
  }
  const int rank = world_rank(), size = world_size();
  const bool speak = rank == 0;

  const bench::City city = bench::city(a.city);
  const rad::Scene& scene = city.scene;
  if (speak)
    std::printf("bench_mpi: city of %d x %d blocks, facets of %.2f m: %zu facets; %d MPI processes, %u hardware threads\n",
                a.city.blocks, a.city.blocks, a.city.facet_size, city.facets(), size,
                std::thread::hardware_concurrency());

  rad::ViewFactorOptions vf;
  vf.level = rad::ViewFactorLevel::polygon;
  vf.form_factors.method = rad::FormFactorMethod::monte_carlo;
  vf.form_factors.hemisphere_rays = a.rays;
  vf.form_factors.threads = 1;
  rad::ViewFactorOptions vf_corrected = vf;
  vf_corrected.correction = rad::ViewFactorCorrection::reciprocity;
  rad::SolveOptions so;
  so.method = rad::SolverMethod::jacobi;
  so.form_factors.method = rad::FormFactorMethod::monte_carlo;
  so.form_factors.hemisphere_rays = a.rays;
  so.threads = 1;

  std::vector<int> counts;
  for (int k = 1; k < size; k *= 2) counts.push_back(k);
  counts.push_back(size);

  std::vector<Run> runs;
  rad::ViewFactorMatrix reference_factors, reference_corrected;
  rad::Solution reference_solution;
  std::size_t unknowns = 0;
  for (const int k : counts) {
    MPI_Comm comm = MPI_COMM_NULL;
    MPI_Comm_split(MPI_COMM_WORLD, rank < k ? 0 : MPI_UNDEFINED, rank, &comm);
    Run run;
    run.processes = k;
    if (comm != MPI_COMM_NULL) {
      MPI_Barrier(comm);
      auto t0 = std::chrono::steady_clock::now();
      double c0 = cpu_seconds();
      rad::ViewFactorMatrix m = rad::mpi::view_factor_matrix(scene, vf, comm);
      run.factors = max_over(bench::seconds_since(t0), comm);
      run.factors_fastest = min_over(bench::seconds_since(t0), comm);
      run.factors_cpu = sum_over(cpu_seconds() - c0, comm);
      MPI_Barrier(comm);
      t0 = std::chrono::steady_clock::now();
      rad::ViewFactorMatrix corrected = rad::mpi::view_factor_matrix(scene, vf_corrected, comm);
      run.factors_corrected = max_over(bench::seconds_since(t0), comm);
      MPI_Barrier(comm);
      t0 = std::chrono::steady_clock::now();
      c0 = cpu_seconds();
      rad::Solution s = rad::mpi::solve(scene, so, comm);
      run.solve = max_over(bench::seconds_since(t0), comm);
      run.solve_cpu = sum_over(cpu_seconds() - c0, comm);
      const rad::SolveReport& r = s.report();
      run.solve_lights = max_over(r.seconds_lights, comm);
      run.solve_factors = max_over(r.seconds_form_factors, comm);
      run.solve_sweeps = max_over(r.seconds_solving, comm);
      run.iterations = r.iterations;
      run.factor_mib = max_over(static_cast<double>(r.form_factor_bytes) / (1 << 20), comm);
      unknowns = r.element_count;
      if (rank == 0) {
        if (k == 1) {
          reference_factors = std::move(m);
          reference_corrected = std::move(corrected);
          reference_solution = std::move(s);
        } else {
          run.identical = same_matrix(m, reference_factors) && same_matrix(corrected, reference_corrected) &&
                          same_solution(s, reference_solution);
        }
      }
      MPI_Comm_free(&comm);
    }
    quiet_barrier();
    runs.push_back(run);
  }

  // One sweep's exchange alone, on every process: the all-gather of H's blocks and the flag.
  const std::vector<std::size_t> blocks = rad::detail::even_blocks(unknowns, size);  // the solver's blocks
  std::vector<int> gather_counts(static_cast<std::size_t>(size)), displacements(static_cast<std::size_t>(size));
  for (std::size_t r = 0; r < static_cast<std::size_t>(size); ++r) {
    gather_counts[r] = static_cast<int>(3 * (blocks[r + 1] - blocks[r]));
    displacements[r] = static_cast<int>(3 * blocks[r]);
  }
  std::vector<float> H(3 * unknowns, 1.0f);
  constexpr int kRepeats = 200;
  MPI_Barrier(MPI_COMM_WORLD);
  auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < kRepeats; ++i) {
    MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, H.data(), gather_counts.data(), displacements.data(), MPI_FLOAT,
                   MPI_COMM_WORLD);
    int flag = 0, any = 0;
    MPI_Allreduce(&flag, &any, 1, MPI_INT, MPI_LOR, MPI_COMM_WORLD);
  }
  const double exchange = max_over(bench::seconds_since(t0), MPI_COMM_WORLD) / kRepeats;

  // The shared-memory reference: one process, every hardware thread (rank 0; the others wait).
  double threaded_factors = 0.0, threaded_solve = 0.0;
  if (rank == 0) {
    rad::ViewFactorOptions vt = vf;
    vt.form_factors.threads = 0;
    rad::SolveOptions st = so;
    st.threads = 0;
    t0 = std::chrono::steady_clock::now();
    const rad::ViewFactorMatrix m = rad::view_factor_matrix(scene, vt);
    threaded_factors = bench::seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    const rad::Solution s = rad::solve(scene, st);
    threaded_solve = bench::seconds_since(t0);
  }
  quiet_barrier();
  const double rss = bench::peak_rss_mib();
  std::vector<double> rss_all(static_cast<std::size_t>(size));
  MPI_Gather(&rss, 1, MPI_DOUBLE, rss_all.data(), 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);

  if (speak) {
    std::printf("view factors (polygon level, Monte Carlo, %u rays per element, 1 thread per process):\n", a.rays);
    std::printf("  processes  uncorrected  speedup  (fastest process, CPU in all)  + reciprocity (rank 0)  speedup\n");
    for (const Run& r : runs)
      std::printf("  %9d  %9.3f s  %7.2f  (%7.3f s, %7.3f s)  %29.3f s  %7.2f%s\n", r.processes, r.factors,
                  runs[0].factors / r.factors, r.factors_fastest, r.factors_cpu, r.factors_corrected,
                  runs[0].factors_corrected / r.factors_corrected, r.identical ? "" : "  NOT bit-identical");
    std::printf("Jacobi solve under the sky (%zu unknowns, %d sweeps, 1 thread per process):\n", unknowns,
                runs[0].iterations);
    std::printf("  processes      total  speedup  CPU in all   lights  form factors   sweeps  rows per process\n");
    for (const Run& r : runs)
      std::printf("  %9d  %7.3f s  %7.2f  %8.3f s  %5.3f s  %10.3f s  %5.3f s  %12.1f MiB%s\n", r.processes, r.solve,
                  runs[0].solve / r.solve, r.solve_cpu, r.solve_lights, r.solve_factors, r.solve_sweeps, r.factor_mib,
                  r.identical ? "" : "  NOT bit-identical");
    bool all = true;
    for (const Run& r : runs) all = all && r.identical;
    std::printf("bit-identical to one process (matrix and solution): %s\n", all ? "yes" : "NO");
    const double n = static_cast<double>(unknowns), P = static_cast<double>(size);
    std::printf("per sweep: all-gather of %zu x 12 bytes = %.1f KiB (each process receives %.1f KiB, %.1f KiB move "
                "in all, %.1f KiB counting each process's copy: unknowns x 3 floats x processes) and an all-reduce of "
                "4 bytes: %.3f ms on %d processes (this machine's shared memory)\n",
                unknowns, 12.0 * n / 1024.0, 12.0 * n * (P - 1.0) / P / 1024.0, 12.0 * n * (P - 1.0) / 1024.0,
                12.0 * n * P / 1024.0, 1e3 * exchange, size);
    std::printf("one process, %u threads (shared memory reference): view factors %.3f s, Jacobi solve %.3f s\n",
                std::thread::hardware_concurrency(), threaded_factors, threaded_solve);
    std::printf("peak RSS per process (rank 0 also ran the one-process runs and the reference):");
    for (const double v : rss_all) std::printf(" %.0f MiB", v);
    std::printf("\n");
  }
  MPI_Finalize();
  return 0;
}
