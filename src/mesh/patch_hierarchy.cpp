// Meshing of scene polygons into patches and element quadtrees, with shared vertices and
// crack-free per-vertex interpolation.
// Based on:
//   M. F. Cohen, D. P. Greenberg, D. S. Immel & P. J. Brock, "An efficient radiosity approach for
//     realistic image synthesis", IEEE Computer Graphics and Applications 6(3), 1986
//     (patches shoot/receive, elements subdivide them: patch/element substructuring).
//   D. R. Baum, S. Mann, K. P. Smith & J. M. Winget, "Making radiosity usable: automatic
//     preprocessing and meshing techniques for the generation of accurate radiosity solutions",
//     SIGGRAPH 1991 (shared vertices, T-vertices and their interpolation).
//   M. F. Cohen & J. R. Wallace, "Radiosity and Realistic Image Synthesis", Academic Press 1993,
//     ch. 8 (quadtree element meshes, vertex radiosities by area-weighted averaging).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "radiosity/mesh.hpp"

#include "core/sampling.hpp"

namespace radiosity {
inline namespace v1 {

namespace {

// Areas are computed in double and stored as float, so a cell that is mathematically exactly at
// the limit may round a few ulps above it; this slack keeps such a cell from being split again
// (which would quadruple its element count for nothing).
constexpr double kAreaSlack = 1e-6;

// Refuse meshes whose estimated element count could not be indexed by 32-bit ids anyway,
// before any memory is spent on them.
constexpr double kMaxEstimatedElements = 1u << 28;

bool fits(double area, float limit) { return area <= static_cast<double>(limit) * (1.0 + kAreaSlack); }

struct AreaCentroid {
  double area = 0.0;
  glm::dvec3 centroid{0.0};
};

double triangle_area(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

// Exact area and centroid of a planar convex triangle or quad; a quad is the two triangles
// c0c1c2 + c0c2c3, their centroids weighted by area.
AreaCentroid cell_geometry(const std::vector<glm::vec3>& vertices, const std::array<std::uint32_t, 4>& corners) {
  const glm::dvec3 c0(vertices[corners[0]]), c1(vertices[corners[1]]), c2(vertices[corners[2]]);
  AreaCentroid out;
  const double a1 = triangle_area(c0, c1, c2);
  const glm::dvec3 g1 = (c0 + c1 + c2) / 3.0;
  if (corners[3] == kNone) {
    out.area = a1;
    out.centroid = g1;
    return out;
  }
  const glm::dvec3 c3(vertices[corners[3]]);
  const double a2 = triangle_area(c0, c2, c3);
  const glm::dvec3 g2 = (c0 + c2 + c3) / 3.0;
  out.area = a1 + a2;
  out.centroid = out.area > 0.0 ? (a1 * g1 + a2 * g2) / out.area : (g1 + g2) * 0.5;
  return out;
}

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  const std::uint32_t lo = std::min(a, b), hi = std::max(a, b);
  return (static_cast<std::uint64_t>(lo) << 32) | hi;
}

// Checks one area option: 0 (derive) or a positive number; +inf is allowed and means "never split".
void check_area_option(float value, const char* field) {
  if (!(value >= 0.0f))
    throw Error(ErrorCode::invalid_argument,
                std::string("MeshOptions::") + field + " must be >= 0 (0 derives it), got " + std::to_string(value));
}

}  // namespace

struct PatchHierarchy::Edges {
  /// Edge (min vertex, max vertex) -> its midpoint vertex, for sharing and T-vertex handling.
  std::unordered_map<std::uint64_t, std::uint32_t> midpoints;
  /// For a midpoint vertex, the edge it splits (kNone for lattice and centre vertices).
  std::vector<std::array<std::uint32_t, 2>> vertex_edge;
};

PatchHierarchy::PatchHierarchy() : edges_(std::make_unique<Edges>()) {}
PatchHierarchy::~PatchHierarchy() = default;
PatchHierarchy::PatchHierarchy(PatchHierarchy&&) noexcept = default;
PatchHierarchy& PatchHierarchy::operator=(PatchHierarchy&&) noexcept = default;

PatchHierarchy::PatchHierarchy(const PatchHierarchy& other)
    : options_(other.options_),
      patches_(other.patches_),
      elements_(other.elements_),
      leaves_(other.leaves_),
      leaf_slot_(other.leaf_slot_),
      vertices_(other.vertices_),
      edges_(std::make_unique<Edges>(*other.edges_)) {}

PatchHierarchy& PatchHierarchy::operator=(const PatchHierarchy& other) {
  if (this != &other) *this = PatchHierarchy(other);
  return *this;
}

PatchHierarchy::PatchHierarchy(const Scene& scene, const MeshOptions& options) : PatchHierarchy() {
  check_area_option(options.max_patch_area, "max_patch_area");
  check_area_option(options.max_element_area, "max_element_area");
  const double total_area = scene.total_area();

  // Derive what was left at 0. A derived patch limit never undercuts an explicit element limit:
  // asking only for coarser elements should not be an error.
  options_ = options;
  if (options_.max_patch_area == 0.0f) {
    options_.max_patch_area = static_cast<float>(total_area / 512.0);
    options_.max_patch_area = std::max(options_.max_patch_area, options_.max_element_area);
  } else if (options_.max_element_area > options_.max_patch_area) {
    throw Error(ErrorCode::invalid_argument, "MeshOptions::max_element_area (" + std::to_string(options.max_element_area) +
                                                 ") must not exceed MeshOptions::max_patch_area (" +
                                                 std::to_string(options.max_patch_area) + ")");
  }
  if (options_.max_element_area == 0.0f) options_.max_element_area = options_.max_patch_area / 4.0f;

  if (scene.polygons().empty()) return;
  if (!(options_.max_element_area > 0.0f))
    throw Error(ErrorCode::invalid_argument,
                "MeshOptions::max_element_area is 0 after derivation (the scene's polygons have no area)");
  // Leaves cover the scene at <= max_element_area each, and a full quadtree has ~4/3 nodes per leaf.
  const double estimate = total_area / static_cast<double>(options_.max_element_area) * (4.0 / 3.0);
  if (estimate > kMaxEstimatedElements)
    throw Error(ErrorCode::invalid_argument,
                "MeshOptions::max_element_area (" + std::to_string(options_.max_element_area) +
                    ") is too small for this scene: about " + std::to_string(static_cast<double>(estimate)) +
                    " elements would be created");

  const std::vector<Polygon>& polygons = scene.polygons();
  for (PolygonId id = 0; id < polygons.size(); ++id) {
    const Polygon& polygon = polygons[id];
    const PolygonVertices& p = polygon.vertices;
    if (p.size() == 4) {
      mesh_quad(id, polygon);
    } else if (p.size() == 3) {
      mesh_triangle(id, polygon, p[0], p[1], p[2]);
    } else {
      // A convex polygon with more vertices is a fan of triangles around vertex 0. Each triangle
      // gets its own lattice, so vertices are not shared across the fan diagonals: vertex values
      // may be discontinuous there (the same as at a polygon border).
      for (std::size_t i = 1; i + 1 < p.size(); ++i) mesh_triangle(id, polygon, p[0], p[i], p[i + 1]);
    }
  }

  // Split each patch's root until every leaf fits max_element_area. Roots are visited in order
  // and their subtrees depth-first, so element ids and leaves() do not depend on anything else.
  std::vector<std::uint32_t> stack;
  for (const Patch& patch : patches_) {
    stack.push_back(patch.root);
    while (!stack.empty()) {
      const std::uint32_t e = stack.back();
      stack.pop_back();
      if (fits(elements_[e].area, options_.max_element_area)) continue;
      const std::uint32_t first = subdivide(e);
      for (std::uint32_t k = 4; k-- > 0;) stack.push_back(first + k);
    }
  }
}

std::uint32_t PatchHierarchy::add_vertex(const glm::vec3& position, std::uint32_t edge_a, std::uint32_t edge_b) {
  if (vertices_.size() >= kNone - 1)
    throw Error(ErrorCode::memory_budget, "PatchHierarchy: more vertices than 32-bit ids can index");
  vertices_.push_back(position);
  edges_->vertex_edge.push_back({edge_a, edge_b});
  return static_cast<std::uint32_t>(vertices_.size() - 1);
}

std::uint32_t PatchHierarchy::add_element(const Element& e) {
  if (elements_.size() >= kNone - 1)
    throw Error(ErrorCode::memory_budget, "PatchHierarchy: more elements than 32-bit ids can index");
  elements_.push_back(e);
  leaf_slot_.push_back(kNone);  // the caller registers it in leaves_
  return static_cast<std::uint32_t>(elements_.size() - 1);
}

std::uint32_t PatchHierarchy::midpoint(std::uint32_t a, std::uint32_t b) {
  // One midpoint per undirected edge: the neighbour on the other side of (a, b) finds the same
  // vertex, which keeps the mesh conforming where both sides are split and lets vertex_values()
  // recognise it as a T-vertex where only one side is.
  const std::uint64_t key = edge_key(a, b);
  const auto found = edges_->midpoints.find(key);
  if (found != edges_->midpoints.end()) return found->second;
  const std::uint32_t m = add_vertex(0.5f * (vertices_[a] + vertices_[b]), std::min(a, b), std::max(a, b));
  edges_->midpoints.emplace(key, m);
  return m;
}

void PatchHierarchy::add_patch(PolygonId polygon_id, const Polygon& polygon,
                               const std::array<std::uint32_t, 4>& corners) {
  const AreaCentroid g = cell_geometry(vertices_, corners);
  Element root;
  root.corners = corners;
  root.patch = static_cast<std::uint32_t>(patches_.size());
  root.centroid = glm::vec3(g.centroid);
  root.area = static_cast<float>(g.area);
  const std::uint32_t id = add_element(root);
  leaf_slot_[id] = static_cast<std::uint32_t>(leaves_.size());
  leaves_.push_back(id);

  Patch patch;
  patch.polygon = polygon_id;
  patch.material = polygon.material;
  patch.group = polygon.group;
  patch.normal = polygon.normal;
  patch.centroid = root.centroid;
  patch.area = root.area;
  patch.root = id;
  patches_.push_back(patch);
}

void PatchHierarchy::mesh_quad(PolygonId polygon_id, const Polygon& polygon) {
  const PolygonVertices& p = polygon.vertices;
  const glm::dvec3 p0(p[0]), p1(p[1]), p2(p[2]), p3(p[3]);
  // Bilinear map P(s,t) = (1-s)(1-t)p0 + s(1-t)p1 + st p2 + (1-s)t p3; for a planar convex quad
  // its iso-lines are straight, so the grid cells are planar convex quads.
  auto at = [&](double s, double t) {
    return (1.0 - s) * (1.0 - t) * p0 + s * (1.0 - t) * p1 + s * t * p2 + (1.0 - s) * t * p3;
  };
  auto cell_area = [&](std::size_t i, std::size_t j, std::size_t nu, std::size_t nv) {
    const double s0 = double(i) / double(nu), s1 = double(i + 1) / double(nu);
    const double t0 = double(j) / double(nv), t1 = double(j + 1) / double(nv);
    const glm::dvec3 a = at(s0, t0), b = at(s1, t0), c = at(s1, t1), d = at(s0, t1);
    return triangle_area(a, b, c) + triangle_area(a, c, d);
  };

  // Near-square cells: divide each direction by the mean length of its two opposite edges.
  const double len_u = 0.5 * (glm::length(p1 - p0) + glm::length(p2 - p3));
  const double len_v = 0.5 * (glm::length(p3 - p0) + glm::length(p2 - p1));
  const double side = std::sqrt(static_cast<double>(options_.max_patch_area));
  std::size_t nu = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(len_u / side)));
  std::size_t nv = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(len_v / side)));
  // The area density |P_s x P_t| of a planar bilinear map is affine in (s,t) (the st term is
  // d x d = 0), so the largest cell is one of the four corner cells. Refine the direction with
  // the longer cells until that one fits.
  for (;;) {
    const double largest = std::max({cell_area(0, 0, nu, nv), cell_area(nu - 1, 0, nu, nv),
                                     cell_area(nu - 1, nv - 1, nu, nv), cell_area(0, nv - 1, nu, nv)});
    if (fits(largest, options_.max_patch_area)) break;
    if (len_u / double(nu) >= len_v / double(nv)) {
      ++nu;
    } else {
      ++nv;
    }
  }

  // Grid vertices, created once and shared by the patches around them.
  const std::uint32_t base = static_cast<std::uint32_t>(vertices_.size());
  for (std::size_t j = 0; j <= nv; ++j)
    for (std::size_t i = 0; i <= nu; ++i) {
      // Use the input corners exactly so that patch borders on the polygon border are not moved.
      glm::vec3 q;
      if (i == 0 && j == 0) q = p[0];
      else if (i == nu && j == 0) q = p[1];
      else if (i == nu && j == nv) q = p[2];
      else if (i == 0 && j == nv) q = p[3];
      else q = glm::vec3(at(double(i) / double(nu), double(j) / double(nv)));
      add_vertex(q, kNone, kNone);
    }
  auto vid = [&](std::size_t i, std::size_t j) { return base + static_cast<std::uint32_t>(j * (nu + 1) + i); };
  for (std::size_t j = 0; j < nv; ++j)
    for (std::size_t i = 0; i < nu; ++i)
      add_patch(polygon_id, polygon, {vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)});
}

void PatchHierarchy::mesh_triangle(PolygonId polygon_id, const Polygon& polygon, const glm::vec3& p0,
                                   const glm::vec3& p1, const glm::vec3& p2) {
  const glm::dvec3 a(p0), b(p1), c(p2);
  const double area = triangle_area(a, b, c);
  // k x k similar sub-triangles, each of area area / k^2.
  const double limit = static_cast<double>(options_.max_patch_area);
  std::size_t k = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(std::sqrt(area / limit))));
  while (!fits(area / double(k * k), options_.max_patch_area)) ++k;

  // Lattice vertex (i, j), i + j <= k, at p0 + i/k (p1 - p0) + j/k (p2 - p0); row j holds k+1-j vertices.
  const std::uint32_t base = static_cast<std::uint32_t>(vertices_.size());
  std::vector<std::uint32_t> row_start(k + 2);
  std::uint32_t next = base;
  for (std::size_t j = 0; j <= k; ++j) {
    row_start[j] = next;
    for (std::size_t i = 0; i + j <= k; ++i) {
      glm::vec3 q;
      if (i == 0 && j == 0) q = p0;
      else if (i == k) q = p1;
      else if (j == k) q = p2;
      else q = glm::vec3(a + (double(i) / double(k)) * (b - a) + (double(j) / double(k)) * (c - a));
      next = add_vertex(q, kNone, kNone) + 1;
    }
  }
  auto vid = [&](std::size_t i, std::size_t j) { return row_start[j] + static_cast<std::uint32_t>(i); };
  // "Up" triangles are translates of (p0, p1, p2), "down" ones are point reflections of it; both
  // keep the polygon's counter-clockwise orientation.
  for (std::size_t j = 0; j < k; ++j)
    for (std::size_t i = 0; i + j < k; ++i) {
      add_patch(polygon_id, polygon, {vid(i, j), vid(i + 1, j), vid(i, j + 1), kNone});
      if (i + j + 1 < k) add_patch(polygon_id, polygon, {vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1), kNone});
    }
}

std::uint32_t PatchHierarchy::subdivide(std::uint32_t element) {
  if (element >= elements_.size())
    throw Error(ErrorCode::invalid_argument, "PatchHierarchy::subdivide: element " + std::to_string(element) +
                                                 " is out of range (" + std::to_string(elements_.size()) +
                                                 " elements)");
  if (!elements_[element].is_leaf())
    throw Error(ErrorCode::invalid_argument,
                "PatchHierarchy::subdivide: element " + std::to_string(element) + " is not a leaf");
  if (elements_[element].depth == std::numeric_limits<std::uint8_t>::max())
    throw Error(ErrorCode::invalid_argument,
                "PatchHierarchy::subdivide: element " + std::to_string(element) + " is at the maximum depth");

  // Copy: add_element() below may reallocate elements_.
  const Element parent = elements_[element];
  const std::array<std::uint32_t, 4>& c = parent.corners;
  std::array<std::array<std::uint32_t, 4>, 4> kids;
  if (parent.corner_count() == 4) {
    const std::uint32_t m01 = midpoint(c[0], c[1]), m12 = midpoint(c[1], c[2]);
    const std::uint32_t m23 = midpoint(c[2], c[3]), m30 = midpoint(c[3], c[0]);
    // The mean of the corners is the bilinear centre, so children are the bilinear sub-cells.
    const glm::vec3 centre = 0.25f * (vertices_[c[0]] + vertices_[c[1]] + vertices_[c[2]] + vertices_[c[3]]);
    const std::uint32_t ctr = add_vertex(centre, kNone, kNone);
    kids = {{{c[0], m01, ctr, m30}, {m01, c[1], m12, ctr}, {ctr, m12, c[2], m23}, {m30, ctr, m23, c[3]}}};
  } else {
    const std::uint32_t m01 = midpoint(c[0], c[1]), m12 = midpoint(c[1], c[2]), m20 = midpoint(c[2], c[0]);
    kids = {{{c[0], m01, m20, kNone}, {m01, c[1], m12, kNone}, {m20, m12, c[2], kNone}, {m01, m12, m20, kNone}}};
  }

  const std::uint32_t first = static_cast<std::uint32_t>(elements_.size());
  for (const auto& corners : kids) {
    const AreaCentroid g = cell_geometry(vertices_, corners);
    Element child;
    child.corners = corners;
    child.patch = parent.patch;
    child.parent = element;
    child.depth = static_cast<std::uint8_t>(parent.depth + 1);
    child.centroid = glm::vec3(g.centroid);
    child.area = static_cast<float>(g.area);
    add_element(child);
  }
  elements_[element].first_child = first;

  // The first child takes the parent's slot in leaves_, the others go to the end, so the order
  // depends only on the sequence of subdivide() calls.
  const std::uint32_t slot = leaf_slot_[element];
  leaves_[slot] = first;
  leaf_slot_[first] = slot;
  leaf_slot_[element] = kNone;
  for (std::uint32_t k = 1; k < 4; ++k) {
    leaf_slot_[first + k] = static_cast<std::uint32_t>(leaves_.size());
    leaves_.push_back(first + k);
  }
  return first;
}

glm::vec3 PatchHierarchy::sample_point(std::uint32_t element, glm::vec2 uv) const {
  // The estimators' warp (core/sampling.hpp): area-uniform, and (u,v) strata stay compact cells
  // of equal area on quads too.
  const Element& e = elements_[element];
  std::array<glm::vec3, 4> corners{};
  for (int k = 0; k < e.corner_count(); ++k)
    corners[static_cast<std::size_t>(k)] = vertices_[e.corners[static_cast<std::size_t>(k)]];
  return detail::CellSampler(corners.data(), e.corner_count())(uv);
}

std::vector<Rgb> PatchHierarchy::vertex_values(const std::vector<Rgb>& element_values) const {
  if (element_values.size() != elements_.size())
    throw Error(ErrorCode::invalid_argument, "PatchHierarchy::vertex_values: element_values has " +
                                                 std::to_string(element_values.size()) + " entries, expected " +
                                                 std::to_string(elements_.size()) + " (one per element)");
  // Area-weighted mean of the leaves around each vertex. Accumulating in double makes a constant
  // field come back exactly after rounding to float.
  std::vector<glm::dvec3> sum(vertices_.size(), glm::dvec3(0.0));
  std::vector<double> weight(vertices_.size(), 0.0);
  for (const std::uint32_t id : leaves_) {
    const Element& e = elements_[id];
    const glm::dvec3 value(element_values[id]);
    for (int k = 0; k < e.corner_count(); ++k) {
      sum[e.corners[k]] += static_cast<double>(e.area) * value;
      weight[e.corners[k]] += static_cast<double>(e.area);
    }
  }
  std::vector<Rgb> out(vertices_.size(), Rgb(0.0f));
  for (std::size_t v = 0; v < vertices_.size(); ++v)
    if (weight[v] > 0.0) out[v] = Rgb(sum[v] / weight[v]);

  // T-vertices (Baum et al. 1991): a midpoint of a leaf's edge, and recursively any midpoint of
  // the halves of such an edge, lies on a coarse edge that interpolates only its two endpoints.
  // Setting each to the mean of the endpoints of the edge it splits makes both sides agree.
  std::vector<bool> hanging(vertices_.size(), false);
  std::vector<std::array<std::uint32_t, 2>> edges;
  for (const std::uint32_t id : leaves_) {
    const Element& e = elements_[id];
    const int n = e.corner_count();
    for (int k = 0; k < n; ++k) {
      edges.push_back({e.corners[k], e.corners[(k + 1) % n]});
      while (!edges.empty()) {
        const std::array<std::uint32_t, 2> ab = edges.back();
        edges.pop_back();
        const auto found = edges_->midpoints.find(edge_key(ab[0], ab[1]));
        if (found == edges_->midpoints.end() || hanging[found->second]) continue;
        const std::uint32_t m = found->second;
        hanging[m] = true;
        edges.push_back({ab[0], m});
        edges.push_back({m, ab[1]});
      }
    }
  }
  // midpoint(a, b) creates m after a and b exist, so m > a, b: in increasing id order the
  // endpoints of every hanging vertex, hanging or not, already hold their final values.
  for (std::size_t m = 0; m < vertices_.size(); ++m) {
    if (!hanging[m]) continue;
    const std::array<std::uint32_t, 2>& ab = edges_->vertex_edge[m];
    out[m] = 0.5f * (out[ab[0]] + out[ab[1]]);
  }
  return out;
}

void PatchHierarchy::aggregate(std::vector<Rgb>& element_values) const {
  if (element_values.size() != elements_.size())
    throw Error(ErrorCode::invalid_argument, "PatchHierarchy::aggregate: element_values has " +
                                                 std::to_string(element_values.size()) + " entries, expected " +
                                                 std::to_string(elements_.size()) + " (one per element)");
  // Children always have larger ids than their parent, so a reverse sweep sees every child's
  // final value before the parent's.
  for (std::size_t id = elements_.size(); id-- > 0;) {
    const Element& e = elements_[id];
    if (e.is_leaf()) continue;
    glm::dvec3 sum(0.0);
    double area = 0.0;
    for (std::uint32_t k = 0; k < 4; ++k) {
      const Element& child = elements_[e.first_child + k];
      sum += static_cast<double>(child.area) * glm::dvec3(element_values[e.first_child + k]);
      area += static_cast<double>(child.area);
    }
    element_values[id] = area > 0.0 ? Rgb(sum / area) : Rgb(0.0f);
  }
}

}  // namespace v1
}  // namespace radiosity
