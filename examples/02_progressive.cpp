// Progressive refinement of the Cornell box after a few steps, with and without the ambient
// term, as in Cohen, Chen, Wallace & Greenberg 1988 (figure of the "progressive" sequence).
// Writes progressive_<steps>.png and progressive_<steps>_ambient.png into the current folder
// (or the folder given as the first argument).
#include <cstdio>
#include <filesystem>
#include <string>

#include <radiosity/radiosity.hpp>

int main(int argc, char** argv) {
  const std::filesystem::path folder = argc > 1 ? argv[1] : ".";
  std::filesystem::create_directories(folder);
  const radiosity::Scene scene = radiosity::cornell_box();
  // The default mesh has about 600 patches: 1 step shows the light alone, 20 the first
  // bounces, 250 a rough solution and 5000 a converged one.
  for (int steps : {1, 20, 250, 5000}) {
    radiosity::SolveOptions opt;
    opt.method = radiosity::SolverMethod::progressive;
    opt.tolerance = 1e-6;  // stop on the step count, not the residual
    opt.max_iterations = steps;
    const radiosity::Solution sol = radiosity::solve(scene, opt);
    for (bool ambient : {false, true}) {
      radiosity::RenderOptions ro;
      ro.width = ro.height = 256;
      ro.ambient = ambient;
      const radiosity::Image image = radiosity::render(scene, sol, ro);
      const std::string name = "progressive_" + std::to_string(steps) + (ambient ? "_ambient" : "") + ".png";
      radiosity::write_png(image, folder / name);
      std::printf("%-32s %5d steps, residual %.3g, ambient (%.3g, %.3g, %.3g)\n", name.c_str(),
                  sol.report().iterations, sol.report().residual, sol.ambient().x, sol.ambient().y, sol.ambient().z);
    }
  }
}
