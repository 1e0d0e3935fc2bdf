// radiosity/mpi.hpp under mpirun with 1, 2 and 4 processes (tests/CMakeLists.txt runs this
// program once per count): every process also computes the single-process result of the same
// small scene, and the split results must be bit for bit the same. Every TEST_CASE is
// collective, so checks never skip a collective call (CHECK, not REQUIRE).
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>
#include <mpi.h>

#include <cstring>
#include <string>
#include <vector>

#include <radiosity/mpi.hpp>
#include <radiosity/radiosity.hpp>

#include "city.hpp"
#include "support/scenes.hpp"

namespace {

namespace rad = radiosity;

int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

int ranks() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

/// Bit for bit equal (NaN included).
template <typename T>
bool same(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

/// Rows [first, first + block.rows()) of `whole`, uncorrected, equal to `block` bit for bit.
bool same_rows(const rad::ViewFactorMatrix& whole, std::size_t first, const rad::ViewFactorMatrix& block) {
  if (first + block.rows() > whole.rows()) return false;
  const std::uint64_t base = whole.row_offsets[first];
  for (std::size_t i = 0; i < block.rows(); ++i) {
    if (whole.ids[first + i] != block.ids[i] || whole.area[first + i] != block.area[i]) return false;
    if (whole.row_offsets[first + i + 1] - base != block.row_offsets[i + 1]) return false;
    if (!whole.row_standard_error.empty() && whole.row_standard_error[first + i] != block.row_standard_error[i])
      return false;
    // The sky's rays are drawn per element: a block's are the whole matrix's.
    if (whole.sky[first + i] != block.sky[i] || whole.sky_standard_error[first + i] != block.sky_standard_error[i])
      return false;
  }
  for (std::uint64_t k = 0; k < block.non_zeros(); ++k)
    if (whole.columns[base + k] != block.columns[k] || whole.values[base + k] != block.values[k]) return false;
  return true;
}

/// Every figure of the whole matrix but the timing.
void check_same_matrix(const rad::ViewFactorMatrix& a, const rad::ViewFactorMatrix& b) {
  CHECK(a.level == b.level);
  CHECK(a.ids == b.ids);
  CHECK(a.names == b.names);
  CHECK(same(a.area, b.area));
  CHECK(a.row_offsets == b.row_offsets);
  CHECK(a.columns == b.columns);
  CHECK(same(a.values, b.values));
  CHECK(same(a.sky, b.sky));
  CHECK(same(a.sky_standard_error, b.sky_standard_error));
  CHECK(same(a.row_standard_error, b.row_standard_error));
  CHECK(a.method == b.method);
  CHECK(a.method_reason == b.method_reason);
  CHECK(a.element_count == b.element_count);
  CHECK(a.cancelled == b.cancelled);
  CHECK(a.correction.reciprocity_before == b.correction.reciprocity_before);
  CHECK(a.correction.largest_change == b.correction.largest_change);
  CHECK(a.correction.rms_change == b.correction.rms_change);
  CHECK(a.correction.iterations == b.correction.iterations);
}

/// The split view factors against one process's: rank 0 has the whole matrix, every other rank
/// its block (rows named by ids, uncorrected); view_factor_block() gives every rank its rows.
void check_view_factors(const rad::Scene& scene, const rad::ViewFactorOptions& options) {
  const rad::ViewFactorMatrix single = rad::view_factor_matrix(scene, options);
  const rad::ViewFactorMatrix split = rad::mpi::view_factor_matrix(scene, options, MPI_COMM_WORLD);
  if (rank() == 0) {
    check_same_matrix(split, single);
  } else if (options.level != rad::ViewFactorLevel::group) {
    // The block's rows are the uncorrected single-process rows.
    rad::ViewFactorOptions uncorrected = options;
    uncorrected.correction = rad::ViewFactorCorrection::none;
    const rad::ViewFactorMatrix raw = rad::view_factor_matrix(scene, uncorrected);
    std::size_t first = 0;
    while (first < raw.rows() && !split.ids.empty() && raw.ids[first] != split.ids[0]) ++first;
    CHECK(same_rows(raw, split.ids.empty() ? raw.rows() : first, split));
  } else {
    CHECK(split.rows() == 0);
  }
  if (options.level == rad::ViewFactorLevel::group) return;

  rad::ViewFactorOptions uncorrected = options;
  uncorrected.correction = rad::ViewFactorCorrection::none;
  const rad::ViewFactorMatrix raw =
      options.correction == rad::ViewFactorCorrection::none ? rad::ViewFactorMatrix{} : rad::view_factor_matrix(scene, uncorrected);
  const rad::ViewFactorMatrix& whole = options.correction == rad::ViewFactorCorrection::none ? single : raw;
  const rad::mpi::ViewFactorBlock block = rad::mpi::view_factor_block(scene, uncorrected, MPI_COMM_WORLD);
  CHECK(block.total_rows == whole.rows());
  CHECK(block.blocks.size() == static_cast<std::size_t>(ranks()));
  CHECK(block.first_row == block.blocks[static_cast<std::size_t>(rank())].first_row);
  CHECK(block.rows.rows() == block.blocks[static_cast<std::size_t>(rank())].last_row - block.first_row);
  CHECK(same_rows(whole, block.first_row, block.rows));
  // The blocks tile the rows in order and hold every factor.
  std::uint64_t non_zeros = 0;
  std::size_t next = 0, elements = 0;
  for (const rad::mpi::RowBlock& b : block.blocks) {
    CHECK(b.first_row == next);
    next = b.last_row;
    non_zeros += b.non_zeros;
    elements += b.source_elements;
  }
  CHECK(next == whole.rows());
  CHECK(non_zeros == whole.non_zeros());
  CHECK(elements == whole.element_count);
}

rad::ViewFactorOptions factor_options(rad::ViewFactorLevel level, rad::FormFactorMethod method,
                                      rad::ViewFactorCorrection correction = rad::ViewFactorCorrection::none) {
  rad::ViewFactorOptions o;
  o.level = level;
  o.correction = correction;
  o.form_factors.method = method;
  o.form_factors.hemisphere_rays = 256;
  o.form_factors.threads = 1;
  return o;
}

/// Every value of the solution and the report's figures but timings and memory.
void check_same_solution(const rad::Solution& a, const rad::Solution& b) {
  CHECK(a.status() == b.status());
  CHECK(same(a.radiosity(), b.radiosity()));
  CHECK(same(a.irradiance(), b.irradiance()));
  CHECK(same(a.direct_irradiance(), b.direct_irradiance()));
  CHECK(same(a.back_radiosity(), b.back_radiosity()));
  CHECK(a.hierarchy().leaves() == b.hierarchy().leaves());
  const rad::SolveReport &ra = a.report(), &rb = b.report();
  CHECK(ra.iterations == rb.iterations);
  CHECK(same(ra.residual_history, rb.residual_history));
  CHECK(ra.refined_elements == rb.refined_elements);
  CHECK(ra.light_rays == rb.light_rays);
  CHECK(ra.emitted_power == rb.emitted_power);
  CHECK(ra.absorbed_power == rb.absorbed_power);
  CHECK(ra.light_power == rb.light_power);
  CHECK(ra.warnings == rb.warnings);
  CHECK(a.light_groups().size() == b.light_groups().size());
  for (std::size_t k = 0; k < a.light_groups().size() && k < b.light_groups().size(); ++k) {
    CHECK(a.light_groups()[k].name == b.light_groups()[k].name);
    CHECK(same(a.light_groups()[k].radiosity, b.light_groups()[k].radiosity));
    CHECK(same(a.light_groups()[k].irradiance, b.light_groups()[k].irradiance));
    CHECK(same(a.light_groups()[k].direct_irradiance, b.light_groups()[k].direct_irradiance));
  }
}

/// The split solve against one process's; returns the split one.
rad::Solution check_solve(const rad::Scene& scene, const rad::SolveOptions& options) {
  const rad::Solution single = rad::solve(scene, options);
  rad::Solution split = rad::mpi::solve(scene, options, MPI_COMM_WORLD);
  CHECK(split.status() == rad::SolveStatus::converged);
  CHECK(split.report().iterations > 1);
  check_same_solution(split, single);
  return split;
}

rad::SolveOptions jacobi(rad::FormFactorMethod method) {
  rad::SolveOptions o;
  o.method = rad::SolverMethod::jacobi;
  o.form_factors.method = method;
  o.form_factors.hemisphere_rays = 256;
  o.mesh.max_patch_area = 40000.0f;
  o.mesh.max_element_area = 20000.0f;
  o.threads = 1;
  return o;
}

}  // namespace

TEST_SUITE("mpi") {
  TEST_CASE("mpi view factors of the Cornell box per polygon and per element are the single process's bit for bit") {
    const rad::Scene scene = rad::cornell_box();
    auto coarse = [](rad::ViewFactorOptions o) {
      o.mesh.max_patch_area = 40000.0f;
      o.mesh.max_element_area = 40000.0f;
      return o;
    };
    const rad::FormFactorMethod mc = rad::FormFactorMethod::monte_carlo;
    check_view_factors(scene, coarse(factor_options(rad::ViewFactorLevel::polygon, rad::FormFactorMethod::ray_cast)));
    check_view_factors(scene, coarse(factor_options(rad::ViewFactorLevel::polygon, mc)));
    check_view_factors(scene, coarse(factor_options(rad::ViewFactorLevel::polygon, mc, rad::ViewFactorCorrection::reciprocity)));
    check_view_factors(scene, coarse(factor_options(rad::ViewFactorLevel::element, mc)));
    // The group level is not split: rank 0 computes it.
    check_view_factors(scene, coarse(factor_options(rad::ViewFactorLevel::group, rad::FormFactorMethod::monte_carlo)));
  }

  TEST_CASE("mpi view factors, automatic: every process makes the single process's choice - the exact mode for the "
            "Cornell box, Monte Carlo rows for a city - and the rows are its bit for bit") {
    rad::ViewFactorOptions o = factor_options(rad::ViewFactorLevel::polygon, rad::FormFactorMethod::automatic);
    o.mesh.max_patch_area = o.mesh.max_element_area = 1e30f;
    check_view_factors(rad::cornell_box(), o);
    // The benchmark city of 3 x 3 blocks: the exact mode would take minutes (found under MPI:
    // the merged matrix was named ray-cast and lost its rows' standard errors).
    bench::CityOptions city;
    city.blocks = 3;
    city.facet_size = 2.25;
    o.form_factors.hemisphere_rays = 16;
    const rad::Scene scene = bench::city(city).scene;
    const rad::ViewFactorMatrix split = rad::mpi::view_factor_matrix(scene, o, MPI_COMM_WORLD);
    CHECK(split.method == "monte-carlo");  // every process's block too
    CHECK(split.method_reason.rfind("automatic: the exact mode would take about ", 0) == 0);
    CHECK(split.row_standard_error.size() == split.rows());
    // Rank 0 holds the merged matrix: the single process's (23 454 rows, so once, not per rank).
    if (rank() == 0) check_same_matrix(split, rad::view_factor_matrix(scene, o));
  }

  TEST_CASE("mpi view factors from the hierarchical links per polygon are the single process's bit for bit") {
    // Every process refines the same links; rank 0 gathers the rows and makes them reciprocal.
    const rad::Scene scene = rad::cornell_box();
    rad::ViewFactorOptions o;
    o.method = rad::ViewFactorMethod::hierarchical;
    o.level = rad::ViewFactorLevel::polygon;
    o.mesh.max_patch_area = 40000.0f;
    o.mesh.max_element_area = 40000.0f;
    const rad::ViewFactorMatrix single = rad::view_factor_matrix(scene, o);
    const rad::ViewFactorMatrix split = rad::mpi::view_factor_matrix(scene, o, MPI_COMM_WORLD);
    if (rank() == 0) check_same_matrix(split, single);
    CHECK(split.method == "hierarchical");
    CHECK_THROWS_WITH_AS(rad::mpi::view_factor_block(scene, o, MPI_COMM_WORLD), doctest::Contains("reciprocal"),
                         rad::Error);
  }

  TEST_CASE("mpi view factors with the enclosure correction of a meshed closed box are the single process's") {
    const rad::Scene scene = test::closed_box(rad::Material{}, glm::vec3(1.0f, 2.0f, 3.0f));
    rad::ViewFactorOptions o =
        factor_options(rad::ViewFactorLevel::element, rad::FormFactorMethod::monte_carlo, rad::ViewFactorCorrection::enclosure);
    o.mesh.max_patch_area = 0.5f;
    check_view_factors(scene, o);
  }

  TEST_CASE("mpi view factors: errors reach every process") {
    const rad::Scene scene = rad::cornell_box();  // open: no front wall
    rad::ViewFactorOptions o =
        factor_options(rad::ViewFactorLevel::polygon, rad::FormFactorMethod::monte_carlo, rad::ViewFactorCorrection::enclosure);
    // Rank 0 alone corrects; every process throws its error.
    CHECK_THROWS_WITH_AS(rad::mpi::view_factor_matrix(scene, o, MPI_COMM_WORLD),
                         doctest::Contains("no closed enclosure"), rad::Error);
    CHECK_THROWS_WITH_AS(rad::mpi::view_factor_block(scene, o, MPI_COMM_WORLD),
                         doctest::Contains("needs the whole matrix"), rad::Error);
    o.correction = rad::ViewFactorCorrection::none;
    o.groups = {"no_such_group"};
    CHECK_THROWS_WITH_AS(rad::mpi::view_factor_matrix(scene, o, MPI_COMM_WORLD),
                         doctest::Contains("no_such_group"), rad::Error);
  }

  TEST_CASE("mpi Jacobi solve of the Cornell box with ray_cast and monte_carlo rows is the single process's bit for bit") {
    const rad::Scene scene = rad::cornell_box();
    check_solve(scene, jacobi(rad::FormFactorMethod::ray_cast));
    check_solve(scene, jacobi(rad::FormFactorMethod::monte_carlo));
  }

  TEST_CASE("mpi Jacobi solve with lights - light groups - back sides and adaptive subdivision is the single process's") {
    // Lights (their first shot split too) and light groups.
    rad::Material wall;
    wall.reflectance = rad::Rgb(0.6f, 0.5f, 0.4f);
    rad::Scene lit = test::closed_box(wall, glm::vec3(2.0f, 1.0f, 1.5f));
    lit.add_light(test::point_light("lamp", 2.0f, glm::vec3(0.5f, 0.8f, 0.7f)));
    lit.add_light(test::point_light("other", 1.0f, glm::vec3(1.5f, 0.3f, 0.4f)));
    rad::SolveOptions o = jacobi(rad::FormFactorMethod::monte_carlo);
    o.mesh.max_patch_area = 0.25f;
    o.mesh.max_element_area = 0.1f;
    o.separate_light_groups = true;
    CHECK(check_solve(lit, o).light_groups().size() == 2);
    // Adaptive subdivision: the blocks move as the unknowns grow.
    o.separate_light_groups = false;
    o.adaptive.enabled = true;
    o.adaptive.max_passes = 2;
    CHECK(check_solve(lit, o).report().refined_elements > 0);

    // A two-sided partition: back sides are unknowns (and rows) of their own.
    rad::Scene sheet = test::closed_box(wall, glm::vec3(2.0f, 1.0f, 1.0f));
    rad::Material partition;
    partition.reflectance = rad::Rgb(0.5f);
    partition.diffuse_transmittance = rad::Rgb(0.3f);
    const rad::MaterialId p = sheet.add_material(partition);
    rad::add_quad(sheet, {1.0f, 0.05f, 0.05f}, {0.0f, 0.9f, 0.0f}, {0.0f, 0.0f, 0.9f}, p, "partition");
    sheet.add_light(test::point_light("lamp", 1.0f, glm::vec3(0.5f, 0.5f, 0.5f)));
    o.adaptive.enabled = false;
    CHECK(!check_solve(sheet, o).back_radiosity().empty());
  }

  TEST_CASE("mpi solve refuses methods other than Jacobi on every process") {
    rad::SolveOptions o = jacobi(rad::FormFactorMethod::ray_cast);
    o.method = rad::SolverMethod::gauss_seidel;
    CHECK_THROWS_WITH_AS(rad::mpi::solve(rad::cornell_box(), o, MPI_COMM_WORLD),
                         doctest::Contains("SolverMethod::jacobi"), rad::Error);
  }

  TEST_CASE("mpi solve: a cancel asked for on one process stops every process at the end of a sweep") {
    rad::SolveOptions o = jacobi(rad::FormFactorMethod::ray_cast);
    o.tolerance = 1e-12;
    const int me = rank();
    o.on_progress = [me](const rad::Progress& p) { return !(me == ranks() - 1 && p.phase == rad::Phase::solving); };
    const rad::Solution s = rad::mpi::solve(rad::cornell_box(), o, MPI_COMM_WORLD);
    CHECK(s.status() == rad::SolveStatus::cancelled);
    CHECK(s.report().iterations == 1);
  }
}

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  doctest::Context context(argc, argv);
  // One report: the other processes say only what fails.
  if (rank() != 0) {
    context.setOption("minimal", true);
    context.setOption("no-colors", true);
  }
  const int failed = context.run();
  // A failure on any process fails the run.
  int any = failed != 0 ? 1 : 0, result = 0;
  MPI_Allreduce(&any, &result, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return result;
}
