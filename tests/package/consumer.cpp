// Links the installed library, checks header/binary versions agree and runs a coarse Cornell box.
#include <cmath>
#include <cstdio>
#include <cstring>

#include <radiosity/radiosity.hpp>

int main() {
  if (std::strcmp(radiosity::version(), RADIOSITY_VERSION_STRING) != 0) {
    std::printf("header %s, library %s\n", RADIOSITY_VERSION_STRING, radiosity::version());
    return 1;
  }
  radiosity::Scene scene = radiosity::cornell_box();
  radiosity::SolveOptions opt;
  opt.mesh.max_patch_area = 20000.0f;
  opt.mesh.max_element_area = 20000.0f;
  radiosity::Solution sol = radiosity::solve(scene, opt);
  radiosity::Rgb floor = sol.group_radiosity("floor");
  std::printf("consumer: radiosity %s, floor B = (%.4g, %.4g, %.4g)\n", radiosity::version(),
              floor.x, floor.y, floor.z);
  return (floor.x > 0.0f && std::isfinite(floor.x)) ? 0 : 1;
}
