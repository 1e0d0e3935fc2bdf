// Solver benchmark: the obstructed Cornell box meshed into about N patches of one element each,
// form factors plus solve to tolerance 1e-3 with each method on 2 threads. Each configuration
// runs in its own child process, so its peak memory (getrusage max RSS) is its own.
//
// Usage: bench_solvers [patches...]   (default: 4000; the second size is 16000)
// Prints one line per configuration: patches, elements, method, seconds (form factors, solve),
// iterations, residual reached, peak RSS.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <radiosity/radiosity.hpp>

namespace {

int run(std::size_t target_patches, radiosity::SolverMethod method, const char* name) {
  const radiosity::Scene scene = radiosity::cornell_box();
  radiosity::SolveOptions opt;
  opt.method = method;
  opt.tolerance = 1e-3;
  opt.threads = 2;
  // Patches are at most this large, so there are somewhat more than target_patches of them.
  opt.mesh.max_patch_area = static_cast<float>(scene.total_area() / static_cast<double>(target_patches));
  opt.mesh.max_element_area = opt.mesh.max_patch_area;
  const auto t0 = std::chrono::steady_clock::now();
  const radiosity::Solution sol = radiosity::solve(scene, opt);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const radiosity::SolveReport& r = sol.report();
  std::printf("%7zu patches %7zu elements  %-13s total %7.2f s (form factors %7.2f s, solve %6.2f s)  "
              "%6d iterations  residual %.2e  peak RSS %7.1f MiB  form factors %7.1f MiB\n",
              r.patch_count, r.element_count, name, seconds, r.seconds_form_factors, r.seconds_solving, r.iterations,
              r.residual, usage.ru_maxrss / 1024.0, r.form_factor_bytes / (1024.0 * 1024.0));
  std::fflush(stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::size_t> sizes;
  for (int i = 1; i < argc; ++i) sizes.push_back(std::strtoul(argv[i], nullptr, 10));
  if (sizes.empty()) sizes = {4000};
  const struct {
    radiosity::SolverMethod method;
    const char* name;
  } methods[] = {{radiosity::SolverMethod::jacobi, "jacobi"},
                 {radiosity::SolverMethod::gauss_seidel, "gauss-seidel"},
                 {radiosity::SolverMethod::progressive, "progressive"}};
  std::printf("bench_solvers: radiosity %s, obstructed Cornell box, tolerance 1e-3, 2 threads\n",
              radiosity::version());
  for (std::size_t n : sizes)
    for (const auto& m : methods) {
      std::fflush(stdout);  // the child must not inherit (and print again) buffered output
      const pid_t pid = fork();
      if (pid == 0) {
        try {
          _exit(run(n, m.method, m.name));
        } catch (const std::exception& e) {
          std::printf("%7zu patches  %-13s error: %s\n", n, m.name, e.what());
          std::fflush(stdout);
          _exit(1);
        }
      }
      int status = 0;
      waitpid(pid, &status, 0);
    }
  return 0;
}
