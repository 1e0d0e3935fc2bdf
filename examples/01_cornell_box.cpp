// The quick start of the README: solve the built-in Cornell box and write an EXR and a PNG.
#include <cstdio>

#include <radiosity/radiosity.hpp>

int main() {
  radiosity::Scene scene = radiosity::cornell_box();           // or radiosity::load_scene("room.obj")
  radiosity::SolveOptions opt;                                  // every field has a default
  opt.method = radiosity::SolverMethod::progressive;            // jacobi, gauss_seidel, progressive
  opt.tolerance = 1e-3;                                         // unshot / emitted power
  radiosity::Solution sol = radiosity::solve(scene, opt);
  radiosity::Rgb floor = sol.group_radiosity("floor");         // area-weighted mean B, W/m^2
  std::printf("floor B = (%.3f, %.3f, %.3f)\n", floor.x, floor.y, floor.z);
  radiosity::Image image = radiosity::render(scene, sol);       // the scene's camera, 512x512
  radiosity::write_exr(image, "cornell.exr");
  radiosity::write_png(image, "cornell.png");
}
