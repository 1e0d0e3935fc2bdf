// `radiosity factors`: the view-factor matrix of a scene between its groups (CSV or JSON), its
// polygons or its elements (sparse: CSV triplets, JSON CSR, Matrix Market).
#include "factors.hpp"

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include <glm/geometric.hpp>

#include "cli_mpi.hpp"
#include "factors_format.hpp"
#include "npz_format.hpp"
#include "view3d_format.hpp"

#if RADIOSITY_HAS_MPI
#include "radiosity/mpi.hpp"
#endif

namespace cli {

namespace {

struct FactorsArgs {
  std::string scene;
  std::string method = "auto";
  std::string format = "csv";
  std::string level = "group";
  std::string correction = "none";
  std::string row_sums;
  std::string blocks;  ///< --blocks DIR
  bool sparse = false;
  bool level_given = false, correction_given = false;  // set from the options' counts
  std::string output;
  std::string groups;
  // The library's defaults; an explicit 0 is passed on and rejected with the field named.
  unsigned samples = rad::FormFactorOptions{}.source_samples, rays = rad::FormFactorOptions{}.visibility_rays,
           resolution = rad::FormFactorOptions{}.hemicube_resolution,
           hemisphere_rays = rad::FormFactorOptions{}.hemisphere_rays;
  std::uint64_t seed = 1;
  unsigned threads = 0;
  unsigned memory_budget_mib = 0;  ///< --memory-budget, MiB; 0 = the library's default
  float max_patch_area = 0.0f, max_element_area = 0.0f;
  bool strict = false;
  bool photometric = false;
  std::string reverse_winding;
  float epsilon = rad::ViewFactorOptions{}.epsilon;
};

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(s);
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

/// Writes `text` to `path`, or to stdout for "" or "-".
void write_text(const std::string& path, const std::string& text) {
  if (path.empty() || path == "-") {
    std::fwrite(text.data(), 1, text.size(), stdout);
    return;
  }
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw rad::Error(rad::ErrorCode::io_error, "cannot write '" + path + "'");
}

/// --blocks DIR: each process's rows (one block without mpirun) as DIR/block-K.mtx (Matrix
/// Market, the whole matrix's numbering) and DIR/block-K.rows.csv (row_sums_csv() of its rows),
/// and DIR/manifest.json from rank 0: what a matrix larger than one node's memory is written as
/// (docs/MPI.md). Uncorrected. Returns the exit code.
int write_blocks(const rad::Scene& scene, const rad::ViewFactorOptions& o, const FactorsArgs& a,
                 const std::string& level, ProgressBar& bar) {
  struct Range {
    std::size_t first = 0, last = 0;
    std::uint64_t non_zeros = 0;
    std::size_t source_elements = 0;
  };
  rad::ViewFactorMatrix rows;
  std::size_t first_row = 0, total_rows = 0;
  std::vector<Range> ranges;
#if RADIOSITY_HAS_MPI
  if (process_count() > 1) {
    rad::mpi::ViewFactorBlock block = rad::mpi::view_factor_block(scene, o, MPI_COMM_WORLD);
    rows = std::move(block.rows);
    first_row = block.first_row;
    total_rows = block.total_rows;
    for (const rad::mpi::RowBlock& b : block.blocks)
      ranges.push_back(Range{b.first_row, b.last_row, b.non_zeros, b.source_elements});
  }
#endif
  if (process_count() == 1) {  // without mpirun: one block, the whole matrix
    rows = rad::view_factor_matrix(scene, o);
    total_rows = rows.rows();
    ranges.push_back(Range{0, rows.rows(), rows.non_zeros(), rows.element_count});
  }
  bar.finish();
  if (process_rank() == 0)
    for (const std::string& w : rows.warnings) std::fprintf(stderr, "warning: factors: %s\n", w.c_str());
  const int rank = process_rank();
  const std::filesystem::path folder(a.blocks);
  const std::string matrix_file = "block-" + std::to_string(rank) + ".mtx",
                    rows_file = "block-" + std::to_string(rank) + ".rows.csv";
  std::string error;
  try {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);  // every process: the folder may be its own disk's
    if (!std::filesystem::is_directory(folder))
      throw rad::Error(rad::ErrorCode::io_error, "cannot create the output folder '" + a.blocks + "'");
    write_text((folder / matrix_file).string(),
               matrix_market_block(rows, first_row, total_rows, static_cast<std::size_t>(rank), ranges.size()));
    write_text((folder / rows_file).string(), row_sums_csv(rows, first_row));
  } catch (const std::exception& e) {
    error = e.what();
  }
  error = agree_on_error(error);  // a process that cannot write stops them all, and rank 0 says why
  if (!error.empty()) throw rad::Error(rad::ErrorCode::io_error, error);
  if (rank != 0) return 0;

  nlohmann::ordered_json manifest;
  manifest["format"] = "radiosity view-factor blocks";
  manifest["level"] = level;
  manifest["method"] = rows.method;
  manifest["correction"] = "none";
  manifest["seed"] = a.seed;
  manifest["rows"] = total_rows;
  manifest["columns"] = total_rows;
  std::uint64_t non_zeros = 0;
  std::size_t elements = 0;
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (std::size_t r = 0; r < ranges.size(); ++r) {
    non_zeros += ranges[r].non_zeros;
    elements += ranges[r].source_elements;
    list.push_back({{"rank", r},
                    {"first_row", ranges[r].first},
                    {"last_row", ranges[r].last},
                    {"non_zeros", ranges[r].non_zeros},
                    {"source_elements", ranges[r].source_elements},
                    {"matrix", "block-" + std::to_string(r) + ".mtx"},
                    {"rows", "block-" + std::to_string(r) + ".rows.csv"}});
  }
  manifest["non_zeros"] = non_zeros;
  manifest["source_elements"] = elements;
  manifest["blocks"] = std::move(list);
  write_text((folder / "manifest.json").string(), manifest.dump(2) + "\n");
  std::fprintf(stderr, "factors: %zu %ss, %llu factors, %zu source elements, %s, %zu block%s (one per process), "
               "%.3f s, wrote %s\n",
               total_rows, level.c_str(), static_cast<unsigned long long>(non_zeros), elements, rows.method.c_str(),
               ranges.size(), ranges.size() == 1 ? "" : "s", rows.seconds, (folder / "manifest.json").c_str());
  if (!rows.method_reason.empty())
    std::fprintf(stderr, "factors: %s (%s; --method overrides)\n", rows.method.c_str(), rows.method_reason.c_str());
  return 0;
}

int run_factors(const FactorsArgs& a) {
  return run_guarded([&] {
    // A View3D file brings its control line: encl=1 asks for the enclosure correction, and its
    // factors are per surface (a polygon each).
    const bool vs3 = lower_extension(a.scene) == ".vs3";
    rad::View3DControl control;
    std::string title;
    rad::Scene scene;
    if (vs3) {
      rad::LoadOptions load_options;
      load_options.strict = a.strict;
      rad::View3DFile file = rad::load_view3d(a.scene, load_options);
      scene = std::move(file.scene);
      control = file.control;
      title = file.title;
      reverse_winding(scene, a.reverse_winding);
    } else {
      scene = load(a.scene, a.strict, a.photometric, {false, a.reverse_winding});
    }
    print_load_notes(scene);
    std::string method = a.method;  // "auto" at the group level becomes "ray-cast" (below)
    rad::ViewFactorOptions o;
    if (a.method == "hierarchical") {
      o.method = rad::ViewFactorMethod::hierarchical;
      o.epsilon = a.epsilon;
    } else {
      o.form_factors.method = form_factor_method(a.method);
    }
    o.form_factors.hemisphere_rays = a.hemisphere_rays;
    o.form_factors.source_samples = a.samples;
    o.form_factors.visibility_rays = a.rays;
    o.form_factors.hemicube_resolution = a.resolution;
    o.form_factors.seed = a.seed;
    o.form_factors.threads = a.threads;
    o.memory_budget_bytes = std::size_t{a.memory_budget_mib} << 20;
    o.mesh.max_patch_area = a.max_patch_area;
    o.mesh.max_element_area = a.max_element_area;
    o.groups = split_list(a.groups);
    std::string level = a.level, correction = a.correction;
    std::string chosen;  // what the defaults chose, and why
    if (!a.level_given && (vs3 || a.format == "view3d")) {
      level = "polygon";
      chosen += vs3 ? "level polygon (a View3D file's surfaces)" : "level polygon (--format view3d)";
    }
    if (!a.correction_given && vs3 && control.enclosure) {
      correction = "enclosure";
      chosen += std::string(chosen.empty() ? "" : ", ") + "correction enclosure (the file's control line says encl=1)";
    }
    if (!chosen.empty()) std::fprintf(stderr, "factors: %s\n", chosen.c_str());
    // The group level's estimators have no automatic choice of their own: "auto" is ray-cast
    // there (element rows, occlusion by rays), named so in the summary and the JSON.
    if (method == "auto" && level == "group") {
      method = "ray-cast";
      o.form_factors.method = rad::FormFactorMethod::ray_cast;
    }
    o.level = level == "polygon" ? rad::ViewFactorLevel::polygon
              : level == "element" ? rad::ViewFactorLevel::element
                                     : rad::ViewFactorLevel::group;
    o.correction = correction == "reciprocity" ? rad::ViewFactorCorrection::reciprocity
                   : correction == "enclosure" ? rad::ViewFactorCorrection::enclosure
                                                 : rad::ViewFactorCorrection::none;
    if (a.format == "view3d" && o.level == rad::ViewFactorLevel::element)
      throw rad::Error(rad::ErrorCode::invalid_argument, "--format view3d is for --level polygon or group");
    if (o.level == rad::ViewFactorLevel::group && a.format == "mtx")
      throw rad::Error(rad::ErrorCode::invalid_argument, "--format mtx is for --level polygon or element");
    ProgressBar bar;
    o.on_progress = [&bar](const rad::Progress& p) { return bar.update(p); };
    if (!a.blocks.empty()) {
      if (o.level == rad::ViewFactorLevel::group)
        throw rad::Error(rad::ErrorCode::invalid_argument, "--blocks is for --level polygon or element");
      if (o.method == rad::ViewFactorMethod::hierarchical)
        throw rad::Error(rad::ErrorCode::invalid_argument,
                         "--blocks writes uncorrected rows: the hierarchical links' factors are made reciprocal over the "
                         "whole matrix");
      if (o.correction != rad::ViewFactorCorrection::none)
        throw rad::Error(rad::ErrorCode::invalid_argument,
                         "--blocks writes uncorrected rows: the " + correction + " correction needs the whole matrix");
      if (!a.output.empty() || !a.row_sums.empty())
        throw rad::Error(rad::ErrorCode::invalid_argument,
                         "--blocks writes its own files (Matrix Market and row sums per block): leave out -o and --row-sums");
      return write_blocks(scene, o, a, level, bar);
    }
    // Under mpirun the rows are split among the processes and rank 0 writes the result; the group
    // level is not split (each group's sums run over all its elements in turn): rank 0 alone.
    const int processes = process_count();
    if (processes > 1 && o.level == rad::ViewFactorLevel::group) {
      if (process_rank() != 0) return 0;
      std::fprintf(stderr, "factors: the group level is not split among MPI processes: rank 0 computes it alone\n");
    }
    const bool split = processes > 1 && o.level != rad::ViewFactorLevel::group;
    // The group level without a correction is view_factors() itself, as before the levels.
    const bool matrix = o.level != rad::ViewFactorLevel::group || o.correction != rad::ViewFactorCorrection::none ||
                        a.format == "view3d" || a.format == "npz";
    rad::ViewFactorMatrix m;
    rad::GroupViewFactors v;
    if (split) {
#if RADIOSITY_HAS_MPI
      m = rad::mpi::view_factor_matrix(scene, o, MPI_COMM_WORLD);
#endif
      bar.finish();
      if (process_rank() != 0) return 0;  // its block only: rank 0 has the whole matrix and writes it
    } else if (matrix) {
      m = rad::view_factor_matrix(scene, o);
    } else {
      v = rad::view_factors(scene, o);
    }
    bar.finish();
    if (matrix && o.level == rad::ViewFactorLevel::group) v = group_factors(m, 0);

    std::string text;
    if (a.format == "npz") {
      if (a.output.empty() || a.output == "-")
        throw rad::Error(rad::ErrorCode::invalid_argument, "--format npz writes a zip archive: give a file with -o");
      write_npz(m, a.output);
    } else if (a.format == "view3d") {
      // View3D's output is dense: n^2 numbers of about 9 characters each.
      constexpr std::size_t kMaxDenseRows = 10000;
      if (m.rows() > kMaxDenseRows)
        throw rad::Error(rad::ErrorCode::invalid_argument,
                         "--format view3d writes every factor, zeros included: " + std::to_string(m.rows()) +
                             " rows would make " + std::to_string(m.rows() * m.rows() / 100000000 + 1) +
                             "00 million numbers; above " + std::to_string(kMaxDenseRows) +
                             " rows use the sparse --format mtx or json");
      // View3D's output file: its header records encl as the run had it.
      control.enclosure = o.correction == rad::ViewFactorCorrection::enclosure;
      text = view3d_output(m, view3d_emissivities(scene, m), control);
    } else if (o.level == rad::ViewFactorLevel::group)
      text = a.format == "json" ? factors_json(v, a.sparse, method) : factors_csv(v, a.sparse);
    else
      text = a.format == "json" ? matrix_json(m, o.correction) : a.format == "mtx" ? matrix_market(m) : matrix_csv(m);
    if (a.format == "view3d" && control.output_format == 1 && (a.output.empty() || a.output == "-"))
      throw rad::Error(rad::ErrorCode::invalid_argument,
                       "the control line asks for View3D's binary output (out=1): give a file with -o");
    if (a.format != "npz") write_text(a.output, text);
    if (!a.row_sums.empty()) {
      if (!matrix) m = rad::view_factor_matrix(scene, o);  // the group rows as a matrix
      write_text(a.row_sums, row_sums_csv(m));
    }
    // The summary goes to stderr, so that stdout stays a clean CSV/JSON stream.
    const std::string links = v.link_count > 0 ? " (" + std::to_string(v.link_count) + " links)" : "";
    if (o.level == rad::ViewFactorLevel::group && !matrix) {
      std::fprintf(stderr, "factors: %zu groups, %zu patches, %zu source elements, %s%s, %.3f s%s%s\n",
                   v.groups.size(), v.patch_count, v.element_count, method.c_str(), links.c_str(), v.seconds,
                   a.output.empty() ? "" : ", wrote ", a.output.c_str());
    } else {
      const std::string processes_text =
          split ? ", split among " + std::to_string(processes) + " MPI processes" : std::string();
      std::fprintf(stderr, "factors: %zu %ss, %zu factors, %zu source elements, %s%s, %.3f s%s%s\n", m.rows(),
                   level.c_str(), m.non_zeros(), m.element_count, m.method.c_str(), processes_text.c_str(), m.seconds,
                   a.output.empty() ? "" : ", wrote ", a.output.c_str());
      if (!m.method_reason.empty())
        std::fprintf(stderr, "factors: %s (%s; --method overrides)\n", m.method.c_str(), m.method_reason.c_str());
      // The library's warnings (z-fighting, polygons wound against their neighbours, a model
      // wound outward) and notes (rows in contact, rows that see only the sky, covered rows).
      for (const std::string& w : m.warnings) std::fprintf(stderr, "warning: factors: %s\n", w.c_str());
      for (const std::string& n : m.notes) std::fprintf(stderr, "factors: %s\n", n.c_str());
      const rad::ViewFactorCorrectionReport& c = m.correction;
      std::fprintf(stderr,
                   "factors: before correction: reciprocity error up to %.3g, row sums off by up to %.3g (rms %.3g)\n",
                   c.reciprocity_before, c.row_sum_error_before, c.row_sum_rms_before);
      if (o.correction != rad::ViewFactorCorrection::none)
        std::fprintf(stderr, "factors: %s correction changed factors by up to %.3g (rms %.3g)%s\n",
                     correction.c_str(), c.largest_change, c.rms_change,
                     o.correction == rad::ViewFactorCorrection::enclosure
                         ? (", " + std::to_string(c.iterations) + " iterations, " + std::to_string(c.clamped) +
                            " factors clamped to 0, " + std::to_string(c.empty_rows) + " rows see nothing")
                               .c_str()
                         : "");
    }
    return 0;
  });
}

}  // namespace

Command add_factors_command(CLI::App& app) {
  auto args = std::make_shared<FactorsArgs>();
  FactorsArgs& a = *args;
  CLI::App* cmd = app.add_subcommand(
      "factors",
      "View factors F(i -> k) between the scene's groups (area-weighted over each source group), polygons or "
      "elements, as CSV, JSON or Matrix Market");
  cmd->add_option("scene", a.scene, kSceneHelp);
  std::vector<std::string> methods = form_factor_names();
  methods.push_back("hierarchical");
  cmd->add_option("--method", a.method,
                  "Form-factor estimator, or hierarchical: hierarchical radiosity's links (reciprocal factors, "
                  "cost close to linear in the scene)")
      ->check(CLI::IsMember(methods))
      ->capture_default_str();
  cmd->add_option("--epsilon", a.epsilon,
                  "Hierarchical: refine a link while its view factor may vary over its ends by more than this, "
                  "(0, 1]")
      ->check(in_range<float>(1e-6f, 1.0f))
      ->capture_default_str();
  cmd->add_option("--level", a.level,
                  "Rows and columns: group, polygon (every polygon, in scene order; sparse) or element (every "
                  "element of the mesh; sparse)")
      ->check(CLI::IsMember({"group", "polygon", "element"}))
      ->capture_default_str();
  cmd->add_option("--correction", a.correction,
                  "reciprocity: A_i F_ij = A_j F_ji exactly; enclosure: also rows that sum to 1 (closed scenes), by "
                  "a least-squares change that keeps the sparsity")
      ->check(CLI::IsMember({"none", "reciprocity", "enclosure"}))
      ->capture_default_str();
  cmd->add_option("--format", a.format,
                  "Output format: csv, json; mtx (Matrix Market, 1-based) for --level polygon or element; view3d "
                  "(View3D's output file: areas, dense rows, emissivities; implies --level polygon); npz (scipy.sparse's "
                  "CSR archive with ids, area and sky per row; needs -o)")
      ->check(CLI::IsMember({"csv", "json", "mtx", "view3d", "npz"}))
      ->capture_default_str();
  cmd->add_option("--row-sums", a.row_sums,
                  "Also write each row's area, sum, sky view factor and standard errors as CSV here");
  cmd->add_flag("--sparse", a.sparse, "Only the non-zero factors (CSV: from,to,factor rows)");
  cmd->add_option("--blocks", a.blocks,
                  "Write the rows as blocks into this folder, one per MPI process (one without mpirun): "
                  "block-K.mtx (Matrix Market, the whole matrix's numbering), block-K.rows.csv and manifest.json; "
                  "for matrices larger than one node's memory; uncorrected (docs/MPI.md)");
  cmd->add_option("-o,--output", a.output, "Write here instead of stdout");
  cmd->add_option("--groups", a.groups, "Comma-separated groups to report, in this order (default: all)");
  cmd->add_option("--samples", a.samples,
                  "Points per source element, 1..64 (hemicube: a square count is a Gauss rule)")
      ->check(in_range<unsigned>(1u, 64u))
      ->capture_default_str();
  cmd->add_option("--rays", a.rays, "Ray cast: occlusion rays per source point, 1..64")
      ->check(in_range<unsigned>(1u, 64u))
      ->capture_default_str();
  cmd->add_option("--hemisphere-rays", a.hemisphere_rays, "Monte Carlo: rays per element, 16..1048576")
      ->check(in_range<unsigned>(16u, 1u << 20))
      ->capture_default_str();
  cmd->add_option("--resolution", a.resolution, "Hemicube: top-face resolution in pixels, 2..8192")
      ->check(in_range<unsigned>(2u, 8192u))
      ->capture_default_str();
  cmd->add_option("--seed", a.seed, "Random seed (results are identical for a seed at any thread count)")
      ->check(any_number<std::uint64_t>())
      ->capture_default_str();
  cmd->add_option("--threads", a.threads, "Worker threads (0 = all cores)")->check(any_number<unsigned>());
  cmd->add_option("--memory-budget", a.memory_budget_mib,
                  "The most memory the factors may take, MiB (0 = 4096): a matrix estimated over it (from a sample "
                  "of its rows) is refused with the figure before its rows are computed")
      ->check(in_range<unsigned>(0u, 1u << 24));
  cmd->add_option("--max-patch-area", a.max_patch_area, "Largest patch, scene units^2 (0 = derive)")
      ->check(non_negative<float>());
  cmd->add_option("--max-element-area", a.max_element_area, "Largest element, scene units^2 (0 = derive)")
      ->check(non_negative<float>());
  add_strict_flag(*cmd, a.strict);
  add_photometric_flag(*cmd, a.photometric);
  add_reverse_winding_option(*cmd, a.reverse_winding);
  CLI::Option* level = cmd->get_option("--level");
  CLI::Option* correction = cmd->get_option("--correction");
  return Command{cmd, [args, level, correction] {
                   args->level_given = level->count() > 0;
                   args->correction_given = correction->count() > 0;
                   return run_factors(*args);
                 }};
}

}  // namespace cli
