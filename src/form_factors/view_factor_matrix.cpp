// The sparse view-factor matrix between polygons, elements or groups (form_factors.hpp,
// docs/VIEW_FACTORS.md), for thermal and urban-climate users.
// Based on:
//   M. Cohen, D. Greenberg, D. Immel & P. Brock, "An efficient radiosity approach for realistic
//     image synthesis", IEEE CG&A 6(3), 1986 (substructuring: a surface's factor is the
//     area-weighted sum over its elements: F(p -> j) = sum_e A_e F(e -> j) / A_p).
//   J. R. Howell, M. P. Menguc & R. Siegel, "Thermal Radiation Heat Transfer", 6th ed., 2016,
//     ch. 4 (view-factor algebra; the reciprocity and closure that view_factor_correction.cpp
//     enforces).
//
// Rows are made a chunk of whole polygons at a time from the estimator's sparse element rows,
// so memory is the result plus one chunk; the element level is the polygon level of a scene
// whose polygons are the mesh's leaf elements. The rows of any block come from
// detail::ViewFactorRows (view_factor_rows.hpp), which the MPI module (src/mpi/) calls for each
// process's block; the correction is the end, on the whole matrix.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "core/frame.hpp"
#include "core/halton.hpp"
#include "core/memory_budget.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "core/rng.hpp"
#include "core/sampling.hpp"
#include "core/streams.hpp"
#include "geometry/burial.hpp"
#include "geometry/ray_scene.hpp"
#include "form_factors/estimators.hpp"
#include "form_factors/exact_view_factors.hpp"
#include "form_factors/view_factor_correction.hpp"
#include "form_factors/view_factor_rows.hpp"
#include "scene/overlap.hpp"
#include "scene/winding_check.hpp"
#include "solver/hierarchical/link_view_factors.hpp"
#include "radiosity/form_factors.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

/// Source elements per chunk of rows (whole polygons are kept together, so a chunk may hold
/// more): the first chunk's, then BlockSizer's choice (about 15 ms a chunk, so a cancel is
/// seen soon) within these; an element's row does not depend on its chunk.
constexpr std::size_t kFirstChunk = 32, kSmallestChunk = 8, kLargestChunk = 16384;
/// Bytes of one entry of the matrix: its column and its value.
constexpr double kEntryBytes = sizeof(std::uint32_t) + sizeof(float);

/// Throws Error{memory_budget} when the matrix's `bytes` after `done` of `rows` rows pass `budget`.
void check_matrix_memory(double bytes, std::size_t done, std::size_t rows, std::size_t budget) {
  if (bytes <= static_cast<double>(budget)) return;
  detail::refuse_memory("the view-factor matrix (after " + std::to_string(done) + " of " + std::to_string(rows) + " rows)",
                        bytes, budget, "ViewFactorOptions::memory_budget_bytes",
                        "; choose fewer rows (ViewFactorOptions::groups), a coarser level or mesh, or raise the budget");
}

/// Rows whose entries are counted before the element rows are computed (evenly spread over a
/// block of at least four times as many): the matrix's size is estimated from them, and a matrix
/// estimated over the budget is refused then, not after most of its rows (minutes at a million
/// rows). A row's entry count varies with what it sees (a roof few, a street many), so the
/// estimate is a mean, within about a tenth at these counts; the check as the rows are made stays.
constexpr std::size_t kSizeSampleRows = 256;

/// The enclosure correction refuses a scene with a row farther than this from 1 (check_enclosure()).
constexpr double kMaxClosureGap = 0.25;

/// Which polygons get a row: not obstruction-only, and in `groups` when it is not empty.
/// Throws for an unknown or repeated group name.
std::vector<std::uint32_t> selected_polygons(const Scene& scene, const std::vector<std::string>& groups,
                                             const char* caller) {
  std::vector<char> keep_group(scene.groups().size(), groups.empty() ? 1 : 0);
  for (const std::string& name : groups) {
    const std::optional<GroupId> id = scene.find_group(name);
    if (!id) throw Error(ErrorCode::invalid_argument, std::string(caller) + ": groups: the scene has no group '" + name + "'");
    if (keep_group[*id]) throw Error(ErrorCode::invalid_argument, std::string(caller) + ": groups: '" + name + "' is listed twice");
    keep_group[*id] = 1;
  }
  std::vector<std::uint32_t> row_of(scene.polygons().size(), kNone);
  std::uint32_t rows = 0;
  for (std::size_t p = 0; p < scene.polygons().size(); ++p) {
    const Polygon& polygon = scene.polygons()[p];
    if (!polygon.obstruction_only && keep_group[polygon.group]) row_of[p] = rows++;
  }
  return row_of;
}

/// Points pressed against the ground: a polygon lying on another face to face (find_overlaps():
/// coincident, facing apart; a building's bottom on the ground it stands on) at a point with
/// nothing at all on its side (no ray of the burial test meets a polygon: the void under a
/// terrain, which the model leaves open). Its rays start just past the other polygon and meet
/// nothing, so they would count as sky: a bottom on the ground would see the whole sky. Such a
/// point sees nothing instead, as the ground under it does (its rays meet the building's inside).
/// Where something does lie on its side, the point keeps its rays: two rooms modelled as separate
/// boxes share a wall as two coincident polygons facing apart, and each side sees its own room
/// (and the sky through that room's windows).
class PressedPoints {
 public:
  /// `overlaps`: find_overlaps(scene).
  PressedPoints(const Scene& scene, const std::vector<PolygonOverlap>& overlaps, const detail::RayScene& occluders,
                float lift)
      : scene_(scene), occluders_(occluders), lift_(lift), first_(scene.polygons().size() + 1, 0) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    for (const PolygonOverlap& o : overlaps) {
      if (!o.lying_against()) continue;
      pairs.emplace_back(o.first, o.second);
      pairs.emplace_back(o.second, o.first);
    }
    std::sort(pairs.begin(), pairs.end());
    for (const auto& pair : pairs) ++first_[pair.first + 1];
    for (std::size_t p = 0; p + 1 < first_.size(); ++p) first_[p + 1] += first_[p];
    partners_.reserve(pairs.size());
    for (const auto& pair : pairs) partners_.push_back(pair.second);
  }
  /// Whether polygon `polygon` lies against any other.
  bool lies_against(std::uint32_t polygon) const { return first_[polygon + 1] > first_[polygon]; }
  /// Whether point `x` of polygon `polygon` (on its surface) is pressed against another.
  bool pressed(std::uint32_t polygon, const glm::vec3& x) const {
    const glm::vec3 n = scene_.polygons()[polygon].normal;
    bool covered = false;
    for (std::size_t k = first_[polygon]; k < first_[polygon + 1] && !covered; ++k)
      covered = inside(scene_.polygons()[partners_[k]], x);
    if (!covered) return false;
    const glm::vec3 origin = x + lift_ * n;
    for (const glm::vec3& d : detail::burial_directions(n))
      if (occluders_.occluded(origin, d, 0.0f, std::numeric_limits<float>::infinity())) return false;
    return true;
  }

 private:
  /// Whether `x`, taken into convex polygon q's plane, lies within it (its edges included, to
  /// the touching tolerance's share of an edge's length).
  bool inside(const Polygon& q, const glm::vec3& x) const {
    const std::size_t n = q.vertices.size();
    for (std::size_t i = 0; i < n; ++i) {
      const glm::vec3 a = q.vertices[i], edge = q.vertices[(i + 1) % n] - a;
      if (glm::dot(glm::cross(edge, x - a), q.normal) < -lift_ * glm::length(edge)) return false;
    }
    return true;
  }
  const Scene& scene_;
  const detail::RayScene& occluders_;
  float lift_;
  std::vector<std::size_t> first_;       ///< per polygon: its partners are partners_[first_[p], first_[p + 1])
  std::vector<std::uint32_t> partners_;  ///< the polygons each lies against
};

/// Per row, the sky view factor: the cosine-weighted fraction of the hemisphere above the row's
/// elements (sources[first[r] .. first[r + 1]), area-weighted) in which no polygon lies, from
/// `rays` stratified rays per element (points and directions each stratified, paired by a
/// random permutation), each drawn from the element's own stream. Fills out.sky and
/// out.sky_standard_error (binomial over the row's rays).
/// Reports progress through `gate` between blocks of elements, from `done` (a fraction of
/// Phase::form_factors already reported) to 1; returns false when cancelled (out.sky is then
/// left empty).
/// Rows [row_begin, row_end) of `first` only, into out.sky[r - row_begin]. `overlaps`:
/// find_overlaps(scene).
bool row_sky(const Scene& scene, const std::vector<PolygonOverlap>& overlaps, const PatchHierarchy& hierarchy,
             const std::vector<std::uint32_t>& sources, const std::vector<std::uint64_t>& first, std::size_t row_begin,
             std::size_t row_end, const FormFactorOptions& ff, detail::ProgressGate& gate, double done,
             ViewFactorMatrix& out) {
  const std::size_t rows = row_end - row_begin;
  const std::size_t element_begin = first[row_begin], element_end = first[row_end];
  const detail::RayScene occluders = detail::RayScene::from_polygons(scene);
  const float epsilon = 1e-5f * std::max(scene.bounds().diagonal(), 1e-6f);
  const PressedPoints pressed(scene, overlaps, occluders, epsilon);
  const std::uint32_t n = ff.hemisphere_rays;
  std::vector<double> escaped(element_end - element_begin, 0.0);  // per source of the rows
  // Elements [begin, end) of `sources`: their fractions of rays that meet nothing.
  auto trace = [&](std::size_t begin, std::size_t end) {
    std::vector<glm::vec2> points(n), directions(n);
    std::vector<glm::vec3> origin(n), direction(n);
    std::vector<std::uint8_t> blocked(n);
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t e = sources[k];
      const glm::vec3 normal = hierarchy.normal(e);
      const detail::Frame frame(normal);
      detail::Rng rng(ff.seed, e, detail::stream_key(detail::Stream::view_factor_sky));
      // Points and directions from one randomised 4D Halton set (core/halton.hpp), as the
      // Monte Carlo rows and the lights' first shot draw theirs.
      const detail::ShiftedHalton4 halton(rng);
      for (std::uint32_t i = 0; i < n; ++i) halton.point(i, directions[i], points[i]);
      for (std::uint32_t i = 0; i < n; ++i) {
        origin[i] = hierarchy.sample_point(e, points[i]) + epsilon * normal;
        direction[i] = frame.to_world(detail::cosine_hemisphere(directions[i]));
      }
      occluders.occluded_incoherent(n, origin.data(), direction.data(), 0.0f, std::numeric_limits<float>::infinity(),
                                    blocked.data());
      const std::uint32_t polygon = hierarchy.patches()[hierarchy.element(e).patch].polygon;
      if (pressed.lies_against(polygon))
        for (std::uint32_t i = 0; i < n; ++i)
          if (!blocked[i] && pressed.pressed(polygon, origin[i] - epsilon * normal)) blocked[i] = 1;
      std::uint32_t open = 0;
      for (const std::uint8_t x : blocked) open += x ? 0 : 1;
      escaped[k - element_begin] = static_cast<double>(open) / static_cast<double>(n);
    }
  };
  detail::BlockSizer blocks(kFirstChunk, kSmallestChunk, kLargestChunk);
  for (std::size_t block = element_begin, block_end = 0; block < element_end; block = block_end) {
    block_end = std::min<std::size_t>(element_end, block + blocks.size());
    detail::parallel_for(ff.threads, block_end - block, 16,
                         [&](std::size_t begin, std::size_t end) { trace(block + begin, block + end); });
    blocks.done(block_end - block);
    Progress p;
    p.phase = Phase::form_factors;
    p.fraction = done + (1.0 - done) * static_cast<double>(block_end - element_begin) /
                            static_cast<double>(element_end - element_begin);
    if (!gate.report(p, block_end == element_end)) return false;
  }
  out.sky.assign(rows, 0.0);
  out.sky_standard_error.assign(rows, 0.0);
  for (std::size_t r = row_begin; r < row_end; ++r) {
    double area = 0.0, sky = 0.0;
    for (std::uint64_t k = first[r]; k < first[r + 1]; ++k) {
      const double a = hierarchy.element(sources[k]).area;
      area += a;
      sky += a * escaped[k - element_begin];
    }
    if (!(area > 0.0)) continue;
    const double v = sky / area;
    const double total = static_cast<double>(n) * static_cast<double>(first[r + 1] - first[r]);
    out.sky[r - row_begin] = v;
    out.sky_standard_error[r - row_begin] = std::sqrt(v * (1.0 - v) / total);
  }
  return true;
}

/// A scene whose polygons are the leaf elements of `hierarchy` (in leaves() order), with their
/// polygons' materials, groups and obstruction flags.
Scene element_scene(const Scene& scene, const PatchHierarchy& hierarchy) {
  Scene out;
  for (const Material& m : scene.materials()) out.add_material(m);
  std::vector<glm::vec3> corners;
  for (const std::uint32_t e : hierarchy.leaves()) {
    const Element& el = hierarchy.element(e);
    const Polygon& polygon = scene.polygons()[hierarchy.patches()[el.patch].polygon];
    corners.clear();
    for (int k = 0; k < el.corner_count(); ++k) corners.push_back(hierarchy.vertices()[el.corners[k]]);
    const PolygonRange range = out.add_polygon(corners, polygon.material, scene.groups()[polygon.group]);
    if (range.count != 1)
      throw Error(ErrorCode::internal, "view_factor_matrix: element " + std::to_string(e) + " is not one polygon");
    if (polygon.obstruction_only) out.set_obstruction_only(range.first);
  }
  return out;
}

/// The enclosure correction closes rows that noise and small gaps leave a little off 1; rows
/// far from 1 mean the scene is no enclosure as seen from the polygons' fronts, and closing
/// them would invent factors. Rows that see nothing at all (covered: a floor facet under a
/// block that stands on it) are left as they are. Throws Error{invalid_argument} naming the
/// worst row.
void check_enclosure(const ViewFactorMatrix& m, const Scene& scene) {
  std::size_t off = 0, worst = 0, empty = 0;
  double worst_gap = 0.0;
  for (std::size_t i = 0; i < m.rows(); ++i) {
    double s = 0.0;
    for (std::uint64_t k = m.row_offsets[i]; k < m.row_offsets[i + 1]; ++k) s += static_cast<double>(m.values[k]);
    // A row that sees nothing (a floor facet under a block standing on it) stays as it is.
    if (s == 0.0) {
      ++empty;
      continue;
    }
    const double gap = std::fabs(1.0 - s);
    if (gap > kMaxClosureGap) ++off;
    if (gap > worst_gap) {
      worst_gap = gap;
      worst = i;
    }
  }
  if (off == 0) return;
  std::string what = m.level == ViewFactorLevel::group     ? "group '" + m.names[worst] + "'"
                     : m.level == ViewFactorLevel::polygon ? "polygon " + std::to_string(m.ids[worst])
                                                           : "element " + std::to_string(m.ids[worst]);
  if (m.level == ViewFactorLevel::polygon) what += " (group '" + scene.groups()[scene.polygons()[m.ids[worst]].group] + "')";
  char numbers[160];
  std::snprintf(numbers, sizeof numbers, " rows sum to less than %g or more than %g (and %zu see nothing at all; the worst, ",
                1.0 - kMaxClosureGap, 1.0 + kMaxClosureGap, empty);
  char gap[48];
  std::snprintf(gap, sizeof gap, ", is off by %.3g)", worst_gap);
  throw Error(ErrorCode::invalid_argument,
              "view_factor_matrix: enclosure correction: the scene is no closed enclosure seen from the fronts of its "
              "polygons: " + std::to_string(off) + " of " + std::to_string(m.rows()) + numbers + what + gap +
                  ". An open scene takes the reciprocity correction; polygons that face outward (an exporter's "
                  "winding) see nothing in front of them");
}

/// The automatic choice at the polygon and element levels (FormFactorMethod::automatic): the
/// exact mode while its thread time is estimated at most this, Monte Carlo rows beyond. The
/// exact mode integrates every pair of rows, with a cost per pair from a microsecond (far apart,
/// nothing between) to a millisecond (partly hidden behind several occluders): the benchmark room
/// of 3 708 facets takes about 9 s of thread time, a city block of 3 744 triangles (16 buildings)
/// about 115 s. 60 s is half a minute on two threads.
constexpr double kAutomaticExactSeconds = 60.0;
/// Thread time per unit of ExactPolygonTransport::Workspace::work (a pair, a point of the adaptive
/// rules, an occluder clipped at a point). Measured (session 37, quiet machine, 2 threads): the
/// room estimated at 11 s, 4.2 s wall for its rows; the city block estimated at 77 s, 58 s wall;
/// the benchmark city of 5 832 facets estimated at 14 s, 19 s of thread time on a loaded one.
/// Within about a third either way, enough to tell seconds from minutes.
constexpr double kExactWorkSeconds = 0.2e-6;
/// Pairs the estimate integrates (all of them when there are fewer).
constexpr std::size_t kCostSample = 4096;

/// What the exact mode would cost on the rows `ids` (polygons of `transport`'s scene): each
/// unordered pair once, a sample of them integrated (`seed`'s stream, so the same choice on every
/// run and every MPI process).
struct ExactCost {
  double pairs = 0.0;       ///< unordered pairs of rows
  std::size_t sampled = 0;  ///< pairs integrated to estimate
  double seconds = 0.0;     ///< thread time, estimated
  double seen = 0.0;        ///< the share of the sampled pairs that see each other (a factor > 0)
};
ExactCost exact_cost(const detail::ExactPolygonTransport& transport, const std::vector<std::uint32_t>& ids,
                     std::uint64_t seed, unsigned threads) {
  ExactCost cost;
  const std::size_t n = ids.size();
  cost.pairs = 0.5 * static_cast<double>(n) * static_cast<double>(n > 0 ? n - 1 : 0);
  if (n < 2) return cost;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> sample;
  if (cost.pairs <= static_cast<double>(kCostSample)) {
    for (std::uint32_t r = 0; r < n; ++r)
      for (std::uint32_t c = r + 1; c < n; ++c) sample.emplace_back(ids[r], ids[c]);
  } else {
    detail::Rng rng(seed, 0, detail::stream_key(detail::Stream::view_factor_cost));
    for (std::size_t k = 0; k < kCostSample; ++k) {
      const auto r = static_cast<std::uint32_t>(std::min<double>(rng.uniform() * static_cast<double>(n), n - 1));
      auto c = static_cast<std::uint32_t>(std::min<double>(rng.uniform() * static_cast<double>(n - 1), n - 2));
      if (c >= r) ++c;
      sample.emplace_back(ids[r], ids[c]);
    }
  }
  std::vector<std::uint64_t> work(sample.size(), 0);
  std::vector<std::uint8_t> seen(sample.size(), 0);
  detail::parallel_for(threads, sample.size(), 64, [&](std::size_t begin, std::size_t end) {
    const auto w = transport.workspace();
    for (std::size_t k = begin; k < end; ++k) {
      w->work = 0;
      seen[k] = transport.transport(sample[k].first, sample[k].second, *w) > 0.0 ? 1 : 0;
      work[k] = w->work;
    }
  });
  std::uint64_t total = 0, seeing = 0;
  for (const std::uint64_t x : work) total += x;
  for (const std::uint8_t x : seen) seeing += x;
  cost.sampled = sample.size();
  cost.seen = static_cast<double>(seeing) / static_cast<double>(sample.size());
  cost.seconds = cost.pairs * static_cast<double>(total) / static_cast<double>(sample.size()) * kExactWorkSeconds;
  return cost;
}

/// Rows [begin, end) of the exact mode (exact_view_factors.hpp) between the polygons `ids` of
/// `transport`'s scene (row and column r: polygon ids[r]), into out.row_offsets, columns and
/// values: each unordered pair once, F(r -> c) = G_rc / A_r. A pair with both rows in the block is
/// integrated by its lower row; a pair with one outside by this block (and by the other's, to
/// the same bits). Rows are integrated in parallel, a chunk at a time between progress reports;
/// returns false when `gate` cancels (every row of the block is then left empty).
bool exact_rows(const detail::ExactPolygonTransport& transport, const std::vector<std::uint32_t>& ids,
                const std::vector<double>& area, std::size_t begin, std::size_t end, unsigned threads,
                std::size_t memory_budget, detail::ProgressGate& gate, double share, ViewFactorMatrix& out) {
  const std::size_t n = ids.size(), rows = end - begin;
  std::vector<std::vector<std::uint32_t>> columns(rows);
  std::vector<std::vector<float>> transports(rows);
  // Chunks of rows of about equal work (row r integrates n - r pairs in a whole matrix), each
  // of about as many pairs as BlockSizer asks for.
  detail::BlockSizer chunk_pairs(std::max<std::size_t>(n, 1) * 4, 64, std::max<std::size_t>(n, 1) * 64);
  constexpr std::size_t kPieceColumns = 256;
  struct Piece {
    std::size_t row, first, last;  // row `row`, columns [first, last)
  };
  std::vector<Piece> pieces;
  std::vector<std::vector<std::uint32_t>> piece_columns;
  std::vector<std::vector<float>> piece_transports;
  std::size_t row = begin, pairs_held = 0;
  while (row < end) {
    std::size_t last = row, pairs = 0;
    while (last < end && (last == row || pairs < chunk_pairs.size())) pairs += n - (last++ - begin);
    // The chunk's rows cut into pieces of kPieceColumns columns, integrated in parallel and then
    // joined per row in column order: one row's pairs can take far longer than the others'
    // (a floor facet beside a block, every pair partly hidden: 0.1 s), and whole rows as the
    // parallel items left one thread waiting for it at the end of each chunk (the closed
    // Cornell box of 4 142 facets ran on 1.2 of 2 cores).
    pieces.clear();
    for (std::size_t r = row; r < last; ++r)
      for (std::size_t c = 0; c < n; c += kPieceColumns) {
        const std::size_t c_end = std::min(n, c + kPieceColumns);
        // Columns [begin, r] of the block are the lower rows' (or the row's own): none here.
        if (c >= begin && c_end <= r + 1) continue;
        pieces.push_back({r, c, c_end});
      }
    piece_columns.resize(pieces.size());
    piece_transports.resize(pieces.size());
    detail::parallel_for(threads, pieces.size(), 1, [&](std::size_t b, std::size_t e) {
      const auto w = transport.workspace();
      for (std::size_t k = b; k < e; ++k) {
        const Piece& piece = pieces[k];
        std::vector<std::uint32_t>& c_out = piece_columns[k];
        std::vector<float>& g_out = piece_transports[k];
        c_out.clear();
        g_out.clear();
        for (std::size_t c = piece.first; c < piece.last; ++c) {
          if (c == piece.row || (c >= begin && c < piece.row)) continue;  // the lower row of the block has it
          const double g = transport.transport(ids[piece.row], ids[c], *w);
          if (!(g > 0.0)) continue;
          c_out.push_back(static_cast<std::uint32_t>(c));
          g_out.push_back(static_cast<float>(g));
        }
      }
    });
    for (std::size_t k = 0; k < pieces.size(); ++k) {
      const std::size_t r = pieces[k].row - begin;
      columns[r].insert(columns[r].end(), piece_columns[k].begin(), piece_columns[k].end());
      transports[r].insert(transports[r].end(), piece_transports[k].begin(), piece_transports[k].end());
    }
    chunk_pairs.done(pairs);
    // Each pair is held once now and twice in the result (both directions), 8 bytes per entry:
    // refuse before the result is made, or the next chunk, if that passes the budget.
    for (std::size_t q = row; q < last; ++q) pairs_held += columns[q - begin].size();
    row = last;
    check_matrix_memory(3.0 * static_cast<double>(pairs_held) * kEntryBytes, row - begin, rows, memory_budget);
    Progress p;
    p.phase = Phase::form_factors;
    p.fraction = share * static_cast<double>(row - begin) / static_cast<double>(rows);
    if (!gate.report(p, false)) {
      out.row_offsets.assign(rows + 1, 0);
      return false;
    }
  }
  // Row r: its own pairs with columns below the block, then those the block's lower rows
  // integrated (columns [begin, r)), then its own above r; each part in column order.
  std::vector<std::uint64_t> count(rows, 0);
  for (std::size_t q = 0; q < rows; ++q) {
    count[q] += columns[q].size();
    for (const std::uint32_t c : columns[q])
      if (c >= begin && c < end) ++count[c - begin];
  }
  out.row_offsets.assign(rows + 1, 0);
  for (std::size_t r = 0; r < rows; ++r) out.row_offsets[r + 1] = out.row_offsets[r] + count[r];
  out.columns.assign(out.row_offsets[rows], 0);
  out.values.assign(out.row_offsets[rows], 0.0f);
  // F(r -> c) = G_rc / A_r.
  std::vector<double> inverse_area(rows, 0.0);
  for (std::size_t r = 0; r < rows; ++r) inverse_area[r] = area[begin + r] > 0.0 ? 1.0 / area[begin + r] : 0.0;
  std::vector<std::uint64_t> lower(rows), upper(rows);  // next slot of the transposed, own-above parts
  for (std::size_t r = 0; r < rows; ++r) {
    const std::vector<std::uint32_t>& own = columns[r];
    const auto below = static_cast<std::size_t>(
        std::lower_bound(own.begin(), own.end(), static_cast<std::uint32_t>(begin)) - own.begin());
    std::uint64_t at = out.row_offsets[r];
    for (std::size_t k = 0; k < below; ++k, ++at) {
      out.columns[at] = own[k];
      out.values[at] = static_cast<float>(static_cast<double>(transports[r][k]) * inverse_area[r]);
    }
    lower[r] = at;
    upper[r] = out.row_offsets[r + 1] - (own.size() - below);
    for (std::size_t k = below, u = upper[r]; k < own.size(); ++k, ++u) {
      out.columns[u] = own[k];
      out.values[u] = static_cast<float>(static_cast<double>(transports[r][k]) * inverse_area[r]);
    }
  }
  for (std::size_t q = 0; q < rows; ++q)
    for (std::size_t k = 0; k < columns[q].size(); ++k) {
      const std::uint32_t c = columns[q][k];
      if (c < begin || c >= end || c < begin + q) continue;
      const std::uint64_t at = lower[c - begin]++;
      out.columns[at] = static_cast<std::uint32_t>(begin + q);
      out.values[at] = static_cast<float>(static_cast<double>(transports[q][k]) * inverse_area[c - begin]);
    }
  return true;
}

}  // namespace

double ViewFactorMatrix::at(std::size_t row, std::uint32_t column) const {
  const auto first = columns.begin() + static_cast<std::ptrdiff_t>(row_offsets[row]);
  const auto last = columns.begin() + static_cast<std::ptrdiff_t>(row_offsets[row + 1]);
  const auto it = std::lower_bound(first, last, column);
  return it != last && *it == column ? static_cast<double>(values[static_cast<std::size_t>(it - columns.begin())]) : 0.0;
}

const char* to_string(ViewFactorLevel level) {
  switch (level) {
    case ViewFactorLevel::group: return "group";
    case ViewFactorLevel::polygon: return "polygon";
    case ViewFactorLevel::element: return "element";
  }
  return "unknown";
}

const char* to_string(ViewFactorCorrection correction) {
  switch (correction) {
    case ViewFactorCorrection::none: return "none";
    case ViewFactorCorrection::reciprocity: return "reciprocity";
    case ViewFactorCorrection::enclosure: return "enclosure";
  }
  return "unknown";
}

ViewFactorMatrix view_factor_matrix(const Scene& scene, const ViewFactorOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  if (scene.polygons().empty()) throw Error(ErrorCode::invalid_scene, "view_factor_matrix: the scene has no polygons");
  const FormFactorOptions ff = detail::view_factor_estimator_options(options);
  const bool links = options.method == ViewFactorMethod::hierarchical;
  if (links && !(options.epsilon > 0.0f && options.epsilon <= 1.0f))
    throw Error(ErrorCode::invalid_argument,
                "view_factor_matrix: epsilon must be in (0, 1], got " + std::to_string(options.epsilon));

  ViewFactorMatrix out;
  out.level = options.level;
  out.row_offsets.assign(1, 0);
  // find_overlaps(scene) once (0.5 s at 246k polygons), for the sky, the warnings and the notes;
  // left empty at the element level, where the rows are a scene of their own.
  std::vector<PolygonOverlap> overlaps;
  if (options.level == ViewFactorLevel::group) {
    const GroupViewFactors g = view_factors(scene, options);
    const std::size_t n = g.groups.size();
    out.names = g.groups;
    out.area = g.area;
    for (const std::string& name : g.groups) out.ids.push_back(*scene.find_group(name));
    out.row_offsets.assign(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t k = 0; k < n; ++k) {
        const float v = static_cast<float>(g.at(i, k));
        if (!(v > 0.0f)) continue;
        out.columns.push_back(static_cast<std::uint32_t>(k));
        out.values.push_back(v);
      }
      out.row_offsets[i + 1] = out.columns.size();
    }
    out.method = links ? "hierarchical" : to_string(ff.method);
    out.element_count = g.element_count;
    out.cancelled = g.cancelled;
    if (!out.cancelled) {
      // The groups' sky view factors, from the elements of their polygons (not obstruction-only).
      const PatchHierarchy hierarchy(scene, options.mesh);
      std::vector<std::uint32_t> row_of_group(scene.groups().size(), kNone);
      for (std::size_t i = 0; i < n; ++i) row_of_group[out.ids[i]] = static_cast<std::uint32_t>(i);
      std::vector<std::uint64_t> first(n + 1, 0);
      auto row_of = [&](std::uint32_t e) {
        const Polygon& p = scene.polygons()[hierarchy.patches()[hierarchy.element(e).patch].polygon];
        return p.obstruction_only ? kNone : row_of_group[p.group];
      };
      for (const std::uint32_t e : hierarchy.leaves())
        if (row_of(e) != kNone) ++first[row_of(e) + 1];
      for (std::size_t r = 0; r < n; ++r) first[r + 1] += first[r];
      std::vector<std::uint32_t> sources(first[n]);
      std::vector<std::uint64_t> at(first.begin(), first.end() - 1);
      for (const std::uint32_t e : hierarchy.leaves())
        if (row_of(e) != kNone) sources[at[row_of(e)]++] = e;
      // view_factors() reported its rows; the sky's rays report at the end, and may cancel.
      detail::ProgressGate gate(options.on_progress);
      overlaps = find_overlaps(scene);
      out.cancelled = !row_sky(scene, overlaps, hierarchy, sources, first, 0, n, ff, gate, 1.0, out);
    }
  } else {
    detail::ProgressGate gate(options.on_progress);
    Progress start;
    start.phase = Phase::form_factors;
    out.cancelled = !gate.report(start, true);
    out.method = links ? "hierarchical" : to_string(ff.method);
    if (!out.cancelled) {
      const detail::ViewFactorRows rows(scene, options, &options.on_progress);
      out.cancelled = rows.cancelled();
      if (!out.cancelled) rows.compute(0, rows.rows(), gate, out);
      if (options.level == ViewFactorLevel::polygon) overlaps = rows.overlaps();
    }
  }
  detail::finish_view_factor_matrix(scene, options,
                                    options.level == ViewFactorLevel::element ? nullptr : &overlaps, out);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace v1
}  // namespace radiosity

namespace radiosity::detail {

FormFactorOptions view_factor_estimator_options(const ViewFactorOptions& options) {
  FormFactorOptions ff = resolve(options.form_factors);
  if (ff.method == FormFactorMethod::automatic) ff.method = FormFactorMethod::ray_cast;
  // The view factors of surfaces that send and receive on their fronts (as View3D's).
  ff.diffuse_transmission = false;
  ff.specular_depth = 0;
  return ff;
}

struct ViewFactorRows::Impl {
  ViewFactorLevel level = ViewFactorLevel::polygon;
  std::size_t memory_budget = detail::kDefaultMemoryBudget;  ///< ViewFactorOptions::memory_budget_bytes, resolved
  FormFactorOptions ff;
  /// ViewFactorMethod::hierarchical: the links' rows (refined against `epsilon`) instead of the
  /// estimator's.
  bool links = false;
  float epsilon = 0.0f;
  /// Element level: the given scene's mesh (its leaves name the rows) and the scene whose
  /// polygons are its leaf elements, on which the rows are computed.
  std::optional<PatchHierarchy> element_mesh;
  std::optional<Scene> elements;
  const Scene* scene = nullptr;  ///< the scene the rows are computed on
  PatchHierarchy hierarchy;      ///< its mesh
  std::vector<std::uint32_t> ids;             ///< per row: its polygon of *scene
  std::vector<double> area;                   ///< per row
  std::vector<std::uint32_t> column_of_patch;  ///< per patch: the row (and column) of its polygon, or kNone
  /// Source elements grouped by row (in element order within a row): row r's are
  /// sources[first[r] .. first[r + 1]).
  std::vector<std::uint32_t> sources;
  std::vector<std::uint64_t> first;
  bool cancelled = false;  ///< the meshing callback said stop
  std::string reason;      ///< why FormFactorMethod::automatic chose ff.method (empty when it was given)
  std::vector<PolygonOverlap> overlaps;  ///< find_overlaps(*scene)
  /// The exact mode's occluders and pairs, made once for the automatic choice's estimate and the
  /// rows (null unless the exact mode runs).
  std::unique_ptr<const ExactPolygonTransport> exact;
  /// The exact mode: the share of pairs that see each other, from exact_cost()'s sample (for the
  /// matrix's size before the pairs are integrated); negative when not sampled (few pairs).
  double exact_seen = -1.0;
};

ViewFactorRows::ViewFactorRows(const Scene& scene, const ViewFactorOptions& options, const ProgressFn* meshing)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  ProgressFn progress;
  if (meshing && *meshing)
    progress = [&](const Progress& p) {
      if ((*meshing)(p)) return true;
      m.cancelled = true;
      return false;
    };
  auto mesh_scene = [&](const Scene& s, const MeshOptions& o) {
    return progress ? PatchHierarchy(s, o, progress) : PatchHierarchy(s, o);
  };
  m.level = options.level;
  m.memory_budget = detail::resolve_memory_budget(options.memory_budget_bytes);
  m.ff = view_factor_estimator_options(options);
  const bool automatic = options.method == ViewFactorMethod::estimator &&
                         options.form_factors.method == FormFactorMethod::automatic;
  m.links = options.method == ViewFactorMethod::hierarchical;
  m.epsilon = options.epsilon;
  std::vector<std::uint32_t> row_of = selected_polygons(scene, options.groups, "view_factor_matrix");
  MeshOptions mesh = options.mesh;
  m.scene = &scene;
  if (options.level == ViewFactorLevel::element) {
    // Elements: the polygon level of a scene made of the leaf elements, meshed as they are.
    const PatchHierarchy& hierarchy = m.element_mesh.emplace(mesh_scene(scene, options.mesh));
    if (m.cancelled) return;
    m.scene = &m.elements.emplace(element_scene(scene, hierarchy));
    std::vector<std::uint32_t> element_row_of(m.elements->polygons().size(), kNone);
    for (std::size_t k = 0; k < hierarchy.leaves().size(); ++k)
      element_row_of[k] = row_of[hierarchy.patches()[hierarchy.element(hierarchy.leaves()[k]).patch].polygon];
    // Rows renumbered densely in leaf order.
    std::uint32_t rows = 0;
    for (std::uint32_t& r : element_row_of)
      if (r != kNone) r = rows++;
    row_of = std::move(element_row_of);
    mesh = MeshOptions{};
    mesh.max_patch_area = mesh.max_element_area = std::numeric_limits<float>::max();
  }

  const std::size_t polygons = m.scene->polygons().size();
  for (std::size_t p = 0; p < polygons; ++p)
    if (row_of[p] != kNone) m.ids.push_back(static_cast<std::uint32_t>(p));
  const std::size_t rows = m.ids.size();
  if (!m.links && m.ff.method == FormFactorMethod::ray_cast)
    m.exact = std::make_unique<const ExactPolygonTransport>(*m.scene);
  if (m.exact && !automatic && 0.5 * static_cast<double>(rows) * static_cast<double>(rows) > kCostSample) {
    // The exact mode asked for: its sample too, for the matrix's size (compute()).
    m.exact_seen = exact_cost(*m.exact, m.ids, m.ff.seed, m.ff.threads).seen;
  }
  if (automatic) {
    // The exact mode where it takes seconds, Monte Carlo rows where it would take minutes
    // (kAutomaticExactSeconds); the reason goes to ViewFactorMatrix::method_reason.
    const ExactCost cost = exact_cost(*m.exact, m.ids, m.ff.seed, m.ff.threads);
    if (cost.pairs > static_cast<double>(kCostSample)) m.exact_seen = cost.seen;
    char text[320];
    if (cost.seconds <= kAutomaticExactSeconds) {
      std::snprintf(text, sizeof text,
                    "automatic: the exact mode, about %.2g s of thread time for %.3g M pairs of %s (estimated from "
                    "%zu of them)",
                    cost.seconds, 1e-6 * cost.pairs, options.level == ViewFactorLevel::element ? "elements" : "polygons",
                    cost.sampled);
    } else {
      m.ff.method = FormFactorMethod::monte_carlo;
      m.exact.reset();
      std::snprintf(text, sizeof text,
                    "automatic: the exact mode would take about %.2g s of thread time for %.3g M pairs of %s (estimated "
                    "from %zu of them), over the %.0f s the automatic choice allows; Monte Carlo rows of %u rays per "
                    "element instead, each row with its standard error",
                    cost.seconds, 1e-6 * cost.pairs, options.level == ViewFactorLevel::element ? "elements" : "polygons",
                    cost.sampled, kAutomaticExactSeconds, m.ff.hemisphere_rays);
    }
    m.reason = text;
  }
  m.area.assign(rows, 0.0);
  m.hierarchy = mesh_scene(*m.scene, mesh);
  if (m.cancelled) {
    m.ids.clear();
    m.area.clear();
    m.first.assign(1, 0);
    return;
  }
  const PatchHierarchy& hierarchy = m.hierarchy;
  const std::vector<Patch>& patches = hierarchy.patches();
  m.column_of_patch.resize(patches.size());
  for (std::size_t j = 0; j < patches.size(); ++j) m.column_of_patch[j] = row_of[patches[j].polygon];

  m.first.assign(rows + 1, 0);
  for (const std::uint32_t e : hierarchy.leaves()) {
    const std::uint32_t r = row_of[patches[hierarchy.element(e).patch].polygon];
    if (r == kNone) continue;
    ++m.first[r + 1];
    m.area[r] += hierarchy.element(e).area;
  }
  for (std::size_t r = 0; r < rows; ++r) m.first[r + 1] += m.first[r];
  m.sources.resize(m.first[rows]);
  std::vector<std::uint64_t> at(m.first.begin(), m.first.end() - 1);
  for (const std::uint32_t e : hierarchy.leaves()) {
    const std::uint32_t r = row_of[patches[hierarchy.element(e).patch].polygon];
    if (r != kNone) m.sources[at[r]++] = e;
  }
  m.overlaps = find_overlaps(*m.scene);
}

ViewFactorRows::~ViewFactorRows() = default;

std::size_t ViewFactorRows::rows() const { return impl_->ids.size(); }
bool ViewFactorRows::cancelled() const { return impl_->cancelled; }

const std::vector<std::uint64_t>& ViewFactorRows::source_offsets() const { return impl_->first; }
const std::vector<PolygonOverlap>& ViewFactorRows::overlaps() const { return impl_->overlaps; }

void ViewFactorRows::compute(std::size_t begin, std::size_t end, ProgressGate& gate, ViewFactorMatrix& out) const {
  const Impl& m = *impl_;
  const PatchHierarchy& hierarchy = m.hierarchy;
  const std::vector<Patch>& patches = hierarchy.patches();
  const std::vector<std::uint64_t>& first = m.first;
  const std::vector<std::uint32_t>& sources = m.sources;
  const std::size_t rows = end - begin;
  out.level = m.level;
  out.method = m.links ? "hierarchical" : to_string(m.ff.method);
  out.method_reason = m.reason;
  out.ids.assign(m.ids.begin() + static_cast<std::ptrdiff_t>(begin), m.ids.begin() + static_cast<std::ptrdiff_t>(end));
  // Element level: leaf position -> element id.
  if (m.element_mesh)
    for (std::uint32_t& id : out.ids) id = m.element_mesh->leaves()[id];
  out.area.assign(m.area.begin() + static_cast<std::ptrdiff_t>(begin), m.area.begin() + static_cast<std::ptrdiff_t>(end));
  out.row_offsets.assign(rows + 1, 0);
  out.columns.clear();
  out.values.clear();
  out.element_count = first[end] - first[begin];
  out.cancelled = false;
  const bool monte_carlo = !m.links && m.ff.method == FormFactorMethod::monte_carlo;
  // The rows' share of the progress (the sky's rays come after them): about half of the rays
  // for Monte Carlo, most of the work for the other estimators; the links' refinement takes the
  // first half of theirs.
  const double rows_share = monte_carlo ? 0.5 : 0.9;
  const double rows_start = m.links ? 0.45 : 0.0;
  out.sky.clear();
  out.sky_standard_error.clear();
  out.row_standard_error.clear();
  if (monte_carlo) out.row_standard_error.assign(rows, 0.0);
  if (rows == 0) return;

  if (!m.links && m.ff.method == FormFactorMethod::ray_cast) {
    // The exact mode: polygon pairs integrated once, without rays (exact_view_factors.hpp). Its
    // size first, from the sample's share of pairs that see each other, counted as exact_rows()
    // counts it (each pair held once, then twice in the result).
    if (m.exact_seen >= 0.0) {
      const double n = static_cast<double>(m.ids.size()), block = static_cast<double>(rows);
      const double pairs = block * (n - 1.0) - 0.5 * block * (block - 1.0);
      const double estimate = 3.0 * pairs * m.exact_seen * kEntryBytes;
      if (estimate > static_cast<double>(m.memory_budget))
        detail::refuse_memory("the view-factor matrix (the exact mode, estimated from " +
                                  std::to_string(kCostSample) + " sampled pairs of its " +
                                  std::to_string(static_cast<std::uint64_t>(pairs)) + ", before integrating them)",
                              estimate, m.memory_budget, "ViewFactorOptions::memory_budget_bytes",
                              "; choose fewer rows (ViewFactorOptions::groups), a coarser level, Monte Carlo rows "
                              "(FormFactorMethod::monte_carlo), or raise the budget");
    }
    out.cancelled =
        !exact_rows(*m.exact, m.ids, m.area, begin, end, m.ff.threads, m.memory_budget, gate, rows_share, out);
    if (!out.cancelled)
      out.cancelled =
          !row_sky(*m.scene, m.overlaps, hierarchy, sources, first, begin, end, m.ff, gate, rows_share, out);
    return;
  }
  // The element rows: the estimator's, or the links' (refined over the whole scene, so every
  // block of rows refines the same links: a process of a split computation too). refine()
  // takes its mesh mutable though it splits nothing here, so the links get a copy.
  std::unique_ptr<FormFactorEstimator> estimator;
  std::optional<PatchHierarchy> linked_mesh;
  std::unique_ptr<LinkHierarchy> links;
  if (m.links) {
    // The refinement reports its own fraction, of [0, rows_start) here; a cancel goes through.
    const ProgressFn refining = [&](const Progress& p) {
      Progress q = p;
      q.fraction = rows_start * p.fraction;
      return gate.report(q);
    };
    ProgressGate refine_gate(refining);
    std::uint64_t rays = 0;
    links = view_factor_links(*m.scene, linked_mesh.emplace(hierarchy), m.epsilon, m.ff.seed, m.ff.threads,
                              m.memory_budget, refine_gate, rays, true);
    if (!links) {
      out.cancelled = true;
      return;
    }
  } else {
    estimator = make_form_factor_estimator(*m.scene, hierarchy, m.ff);
  }
  std::vector<double> sum(m.ids.size(), 0.0);  // the accumulator of one row, by column
  std::vector<std::uint32_t> touched;
  std::vector<std::uint32_t> batch;
  std::vector<SparseFactors> element_rows;
  // Row r's columns (its elements' rows, element_rows[base + (k - first[r])] for its sources k)
  // summed into sum[] by column, the columns in `touched`.
  auto accumulate = [&](std::size_t r, std::size_t base) {
    touched.clear();
    for (std::uint64_t k = first[r]; k < first[r + 1]; ++k) {
      const std::uint32_t e = sources[k];
      const double a = hierarchy.element(e).area;
      const SparseFactors& f = element_rows[base + static_cast<std::size_t>(k - first[r])];
      for (std::size_t n = 0; n < f.index.size(); ++n) {
        // Backs of two-sided patches (indices past the patches) are not surfaces here.
        if (f.index[n] >= patches.size()) continue;
        const std::uint32_t c = m.column_of_patch[f.index[n]];
        if (c == kNone) continue;
        if (sum[c] == 0.0) touched.push_back(c);
        sum[c] += a * static_cast<double>(f.value[n]);
      }
    }
  };
  // The rows the size estimate made (in increasing order), kept as their column sums so that the
  // loop below does not make them again.
  std::vector<std::size_t> sampled;
  std::vector<std::vector<std::pair<std::uint32_t, double>>> sampled_sums;
  if (rows >= 4 * kSizeSampleRows) {
    // The matrix's size, estimated from a sample of its rows before they are all made.
    double entries = 0.0;
    sampled.reserve(kSizeSampleRows);
    sampled_sums.reserve(kSizeSampleRows);
    for (std::size_t k = 0; k < kSizeSampleRows; ++k) {
      const std::size_t r = begin + (2 * k + 1) * rows / (2 * kSizeSampleRows);
      batch.assign(sources.begin() + static_cast<std::ptrdiff_t>(first[r]),
                   sources.begin() + static_cast<std::ptrdiff_t>(first[r + 1]));
      if (links)
        links->view_factor_rows(*linked_mesh, batch, element_rows);
      else
        estimator->sparse_element_rows(batch, element_rows);
      accumulate(r, 0);
      sampled.push_back(r);
      std::vector<std::pair<std::uint32_t, double>>& kept = sampled_sums.emplace_back();
      kept.reserve(touched.size());
      for (const std::uint32_t c : touched) {
        if (m.area[r] > 0.0 && static_cast<float>(sum[c] / m.area[r]) > 0.0f) entries += 1.0;
        kept.emplace_back(c, sum[c]);
        sum[c] = 0.0;
      }
    }
    entries *= static_cast<double>(rows) / static_cast<double>(kSizeSampleRows);
    const double estimate = entries * kEntryBytes;
    if (estimate > static_cast<double>(m.memory_budget))
      detail::refuse_memory("the view-factor matrix (estimated from " + std::to_string(kSizeSampleRows) + " of its " +
                                std::to_string(rows) + " rows, before computing them)",
                            estimate, m.memory_budget, "ViewFactorOptions::memory_budget_bytes",
                            "; choose fewer rows (ViewFactorOptions::groups), a coarser level or mesh, or raise the "
                            "budget");
    // Room for the estimate and a tenth more, so that the arrays' doubling does not take them
    // past the budget on the way (the check below counts their capacity).
    const auto reserved = static_cast<std::size_t>(1.1 * entries);
    out.columns.reserve(reserved);
    out.values.reserve(reserved);
  }
  std::size_t row = begin;
  std::size_t next_sampled = 0;  // the first of `sampled` not yet written
  std::vector<std::size_t> base;  // a chunk's rows' first element row in element_rows
  detail::BlockSizer chunk(kFirstChunk, kSmallestChunk, kLargestChunk);
  while (row < end) {
    // The chunk: whole rows until it holds the elements BlockSizer asks for; its sampled rows'
    // elements are left out of the batch.
    std::size_t last = row;
    while (last < end && (last == row || first[last] - first[row] < chunk.size())) ++last;
    batch.clear();
    base.clear();
    for (std::size_t r = row, s = next_sampled; r < last; ++r) {
      base.push_back(batch.size());
      if (s < sampled.size() && sampled[s] == r) {
        ++s;
        continue;
      }
      batch.insert(batch.end(), sources.begin() + static_cast<std::ptrdiff_t>(first[r]),
                   sources.begin() + static_cast<std::ptrdiff_t>(first[r + 1]));
    }
    if (batch.empty())
      element_rows.clear();
    else if (links)
      links->view_factor_rows(*linked_mesh, batch, element_rows);
    else
      estimator->sparse_element_rows(batch, element_rows);
    chunk.done(batch.size());
    for (std::size_t r = row; r < last; ++r) {
      if (next_sampled < sampled.size() && sampled[next_sampled] == r) {
        touched.clear();
        for (const auto& [c, value] : sampled_sums[next_sampled]) {
          touched.push_back(c);
          sum[c] = value;
        }
        ++next_sampled;
      } else {
        accumulate(r, base[r - row]);
      }
      std::sort(touched.begin(), touched.end());
      const double inverse_area = m.area[r] > 0.0 ? 1.0 / m.area[r] : 0.0;
      double row_sum = 0.0;
      for (const std::uint32_t c : touched) {
        const float v = static_cast<float>(sum[c] * inverse_area);
        sum[c] = 0.0;
        if (!(v > 0.0f)) continue;
        out.columns.push_back(c);
        out.values.push_back(v);
        row_sum += static_cast<double>(v);
      }
      out.row_offsets[r - begin + 1] = out.columns.size();
      if (monte_carlo) {
        // Binomial: the row's rays each reach a surface of the matrix or not.
        const double s = std::clamp(row_sum, 0.0, 1.0);
        const double n = static_cast<double>(m.ff.hemisphere_rays) * static_cast<double>(first[r + 1] - first[r]);
        out.row_standard_error[r - begin] = std::sqrt(s * (1.0 - s) / n);
      }
    }
    row = last;
    check_matrix_memory(static_cast<double>(out.columns.capacity() * sizeof(std::uint32_t) +
                                            out.values.capacity() * sizeof(float)),
                        row - begin, rows, m.memory_budget);
    Progress p;
    p.phase = Phase::form_factors;
    p.fraction = rows_start + (rows_share - rows_start) * static_cast<double>(row - begin) / static_cast<double>(rows);
    if (!gate.report(p, false)) {
      out.cancelled = true;
      for (std::size_t r = row; r < end; ++r) out.row_offsets[r - begin + 1] = out.columns.size();
      break;
    }
  }
  if (!out.cancelled)
    out.cancelled =
        !row_sky(*m.scene, m.overlaps, hierarchy, sources, first, begin, end, m.ff, gate, rows_share, out);
}

void fill_missing_sky(ViewFactorMatrix& m) {
  if (m.sky.size() == m.rows() && m.sky_standard_error.size() == m.rows()) return;
  m.sky.assign(m.rows(), 0.0);
  m.sky_standard_error.assign(m.rows(), 0.0);
}

namespace {

/// The rows of `m` that see no surface, told apart, into m.warnings and m.notes: at the polygon
/// level, polygons lying against others in contact (a box's bottom on a floor: hidden, as they
/// should be); rows that see only the sky (a roof above everything else in an open scene, or,
/// when find_polygons_facing_outward() judges most of the model wound outward as `check` does,
/// a warning); and rows that see nothing at all (covered). `overlaps`: find_overlaps(scene).
void describe_empty_rows(const Scene& scene, const std::vector<PolygonOverlap>& overlaps, ViewFactorMatrix& m) {
  bool any_empty = false;
  for (std::size_t i = 0; i < m.rows() && !any_empty; ++i) any_empty = m.row_offsets[i + 1] == m.row_offsets[i];
  if (!any_empty) return;
  std::vector<bool> touching;
  if (m.level == ViewFactorLevel::polygon) {
    touching.assign(scene.polygons().size(), false);
    for (const PolygonOverlap& p : overlaps)
      if (p.lying_against()) touching[p.first] = touching[p.second] = true;
  }
  std::size_t blind = 0, in_contact = 0, sky_only = 0;
  double empty_area = 0.0, total_area = 0.0;  // of the rows that see no surface, and of all
  for (std::size_t i = 0; i < m.rows(); ++i) {
    total_area += m.area[i];
    if (m.row_offsets[i + 1] != m.row_offsets[i]) continue;
    if (!touching.empty() && touching[m.ids[i]]) {
      ++in_contact;
      continue;
    }
    empty_area += m.area[i];
    if (i < m.sky.size() && m.sky[i] > 0.0)
      ++sky_only;
    else
      ++blind;
  }
  // Judged (32 rays per polygon) only when the rows that see no surface are a large part of the
  // area: a model wound outward leaves most of it so (a room's walls, however many facets its
  // furniture has), an open scene a few roofs above the rest.
  const bool outward = sky_only > 0 && 4.0 * empty_area >= total_area &&
                       find_polygons_facing_outward(scene, overlaps).looks_wound_outward();
  const std::string rows = std::to_string(m.rows());
  if (outward)
    m.warnings.push_back(std::to_string(sky_only + blind) + " of " + rows +
                         " rows see no surface in front of them, only the sky, and most of the model looks wound "
                         "outward (polygons send and receive on their fronts only: --reverse-winding outward turns "
                         "them over; in code, Scene::reverse_winding() of find_polygons_facing_outward())");
  else if (sky_only > 0)
    m.notes.push_back(std::to_string(sky_only) +
                      " rows see only the sky (no surface in front of them: a roof above the rest)");
  // What stands in front of such a row shows it only its back: most often it is covered (a floor
  // under a block without a bottom face, the ground under a building), hidden as it should be.
  if (blind > 0 && !outward)
    m.notes.push_back(std::to_string(blind) + " of " + rows +
                      " rows see nothing, neither a surface nor the sky: they are covered, what lies in front of "
                      "them shows them its back (the ground under a building, a floor under a block: hidden, as it "
                      "should be; if not, check the winding)");
  if (in_contact > 0)
    m.notes.push_back(std::to_string(in_contact) +
                      " rows see nothing because their polygons lie against others, in contact (a box's bottom on a "
                      "floor): hidden, as they should be");
}

}  // namespace

void finish_view_factor_matrix(const Scene& scene, const ViewFactorOptions& options,
                               const std::vector<PolygonOverlap>* overlaps, ViewFactorMatrix& out) {
  if (!out.cancelled && options.correction == ViewFactorCorrection::enclosure) check_enclosure(out, scene);
  if (!out.cancelled) {
    // The links' two directions of a pair were refined and sampled apart: their factors are
    // reciprocal by construction, each pair's transport the mean of the two (as at group level).
    const ViewFactorCorrection correction =
        options.method == ViewFactorMethod::hierarchical && options.correction == ViewFactorCorrection::none
            ? ViewFactorCorrection::reciprocity
            : options.correction;
    SparseRowsF F{std::move(out.row_offsets), std::move(out.columns), std::move(out.values)};
    out.correction = correct_view_factors(correction, out.area, F, view_factor_estimator_options(options).threads);
    out.row_offsets = std::move(F.offsets);
    out.columns = std::move(F.columns);
    out.values = std::move(F.values);
  }
  fill_missing_sky(out);
  if (out.cancelled) return;
  std::vector<PolygonOverlap> searched;
  if (!overlaps) overlaps = &(searched = find_overlaps(scene));
  // A polygon modelled twice (McGuire's Cornell box indexes a side of each box again as its
  // "bottom face") is two receivers to the view factors: the exact mode integrates each, so a
  // row that sees them counts that area twice (its sum 1.28 in that box), silently but for this.
  out.warnings = z_fighting_warnings(scene, *overlaps,
                                     "each is a surface of its own to the view factors: the exact mode (ray-cast, "
                                     "what the automatic choice takes for small scenes) counts that area twice in the "
                                     "rows that see it (sums above 1), the others split it between the two by "
                                     "rounding; remove one of them");
  // A polygon wound against the surface it belongs to looks the wrong way: its row is wrong,
  // silently but for this (solve() says the same of its light).
  for (std::string& w : inconsistent_winding_warnings(scene, inconsistent_winding(scene, {}), true))
    out.warnings.push_back(std::move(w));
  describe_empty_rows(scene, *overlaps, out);
}

}  // namespace radiosity::detail
