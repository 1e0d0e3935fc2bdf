// Hemicube element-to-patch form factors.
// Based on: M. F. Cohen & D. P. Greenberg, "The hemi-cube: a radiosity solution for complex
// environments", Computer Graphics 19(3) (SIGGRAPH 1985), 31-40 (five faces, delta form factors,
// item buffer); I. E. Sutherland & G. W. Hodgman, "Reentrant polygon clipping", CACM 17(1), 1974
// (clipping to the view pyramid and near plane); D. R. Baum, H. E. Rushmeier & J. M. Winget,
// "Improving radiosity solutions through the use of analytically determined form-factors",
// SIGGRAPH 1989 (the hemicube's aliasing and proximity errors); M. F. Cohen & J. R. Wallace,
// "Radiosity and Realistic Image Synthesis", 1993, sec. 4.9 (delta form factors, error analysis).
//
// From a point x on the source, every patch is projected onto the five faces of a cube around x
// (the top face res x res pixels, the four sides res x res/2), clipped to each face's view
// pyramid above the horizon, and z-buffered; each pixel then belongs to the nearest patch, and
// F(dx -> j) is the sum of the delta form factors of j's pixels. Delta form factors are the exact
// cosine-weighted solid angle of each pixel (Lambert's contour integral over the pixel square),
// so the pixels of a face sum exactly to the face's share of the hemisphere. The element factor
// averages F(dx -> j) over Gauss-Legendre points x of the element (weights from the product
// rule), each hemicube turned about the normal by its own random angle so that the pixel grid's
// aliasing does not line up with the scene's edges.
//
// Diffuse transmission (FormFactorOptions::diffuse_transmission): a translucent patch seen from
// behind writes its back target into the item buffer instead of nothing, and an element's back
// row is the hemicube over its back side (the frame's normal flipped).
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "core/parallel.hpp"
#include "core/rng.hpp"
#include "form_factors/estimators.hpp"
#include "form_factors/sampling.hpp"
#include "form_factors/shaft.hpp"
#include "core/quadrature.hpp"
#include "core/streams.hpp"

namespace radiosity::detail {

namespace {

constexpr std::uint32_t kNoItem = 0xffffffffu;
constexpr double kTwoPi = 6.283185307179586;

// A point in a face's view coordinates: x right, y up, z forward.
struct V3 {
  float x, y, z;
};
struct V2 {
  float x, y;
};

// One face of the hemicube: screen x in [-1, 1], screen y in [y_min, 1] at forward distance 1.
struct FaceGeometry {
  int width = 0, height = 0;
  float y_min = -1.0f;
  float scale_x = 0.0f, scale_y = 0.0f;  // pixels per screen unit
};

// A receiver or occluder as the rasteriser needs it, in the hemicube's frame (T1, T2, N).
struct Projected {
  std::array<glm::vec3, 4> q{};  // corners relative to the eye
  int count = 0;
  glm::vec3 normal{0.0f};        // the patch's normal in the frame
  float plane = 0.0f;            // dot(normal, q[0]): < 0 when the eye is in front
  std::uint32_t item = kNoItem;  // the patch id when the eye sees its front, its back target
                                 // when it sees a translucent patch's back, else kNoItem
};

// Face k's view of a frame vector (a, b, c) = components along (T1, T2, N).
inline V3 face_view(int face, const glm::vec3& p) {
  switch (face) {
    case 0: return {p.x, p.y, p.z};    // top: looking along N
    case 1: return {p.y, p.z, p.x};    // looking along +T1
    case 2: return {-p.y, p.z, -p.x};  // along -T1
    case 3: return {-p.x, p.z, p.y};   // along +T2
    default: return {p.x, p.z, -p.y};  // along -T2
  }
}

// Signed distance-like value of a view point to clip plane k (>= 0 inside). Planes: near, the
// four sides of the pyramid; the bottom side is the horizon (y >= 0) for the side faces.
inline float clip_value(int plane, const V3& v, bool top, float near) {
  switch (plane) {
    case 0: return v.z - near;
    case 1: return v.z - v.x;
    case 2: return v.z + v.x;
    case 3: return v.z - v.y;
    default: return top ? v.z + v.y : v.y;
  }
}

// A pixel rectangle [x0, x1) x [y0, y1).
struct Scissor {
  int x0, y0, x1, y1;
};

// Per-thread rasteriser state: one face at a time, rows face.width apart.
struct Raster {
  std::vector<float> depth;         // inverse depth 1/z; 0 = nothing
  std::vector<std::uint32_t> item;  // the nearest patch's id, or kNoItem
  Scissor touched{0, 0, 0, 0};      // bounds of the pixels drawn since it was reset
};

class HemicubeEstimator final : public TargetEstimator {
 public:
  HemicubeEstimator(const Scene& scene, const PatchHierarchy& hierarchy, const FormFactorOptions& options)
      : TargetEstimator(hierarchy), hierarchy_(hierarchy), options_(options) {
    const float diagonal = std::max(scene.bounds().diagonal(), 1e-6f);
    offset_ = 1e-5f * diagonal;
    near_ = 1e-7f * diagonal;
    edge_on_ = 1e-7f * diagonal;

    const int res = static_cast<int>(options.hemicube_resolution);
    faces_[0] = FaceGeometry{res, res, -1.0f, 0.5f * static_cast<float>(res), 0.5f * static_cast<float>(res)};
    const int side = (res + 1) / 2;
    for (int f = 1; f < 5; ++f)
      faces_[f] = FaceGeometry{res, side, 0.0f, 0.5f * static_cast<float>(res), static_cast<float>(side)};
    delta_forms();

    const auto& patches = hierarchy.patches();
    if (options.diffuse_transmission) set_translucent_patches(find_back_patches(scene, hierarchy));
    back_item_ = back_targets(patches.size(), translucent_patches());  // kNone == kNoItem
    std::vector<std::vector<glm::vec3>> polygons;
    std::vector<glm::vec3> normals;
    corners_.resize(patches.size());
    counts_.resize(patches.size());
    for (std::size_t j = 0; j < patches.size(); ++j) {
      const Element& root = hierarchy.element(patches[j].root);
      counts_[j] = root.corner_count();
      std::vector<glm::vec3> poly;
      for (int k = 0; k < counts_[j]; ++k) {
        corners_[j][static_cast<std::size_t>(k)] = hierarchy.vertices()[root.corners[static_cast<std::size_t>(k)]];
        poly.push_back(corners_[j][static_cast<std::size_t>(k)]);
      }
      polygons.push_back(std::move(poly));
      normals.push_back(patches[j].normal);
    }
    patch_culler_ = ShaftCuller(polygons, normals);

    // Source points: a g x g Gauss-Legendre product rule when source_samples is a square g^2,
    // otherwise source_samples midpoints of strata along u at v = 1/2, equally weighted.
    const std::uint32_t ns = options.source_samples;
    const auto g = static_cast<std::uint32_t>(std::lround(std::sqrt(static_cast<double>(ns))));
    if (g * g == ns) {
      std::vector<float> node;
      std::vector<double> weight;
      gauss_legendre(static_cast<int>(g), node, weight);
      for (std::uint32_t i = 0; i < g; ++i)
        for (std::uint32_t k = 0; k < g; ++k) {
          uv_.emplace_back(node[i], node[k]);
          weight_.push_back(weight[i] * weight[k]);
        }
    } else {
      for (std::uint32_t i = 0; i < ns; ++i) {
        uv_.emplace_back((static_cast<float>(i) + 0.5f) / static_cast<float>(ns), 0.5f);
        weight_.push_back(1.0 / ns);
      }
    }
  }

  // Dense rows keep to the fronts of patches (FormFactorOptions::diffuse_transmission).
  void element_rows(const std::vector<std::uint32_t>& elements, float* out) const override {
    const std::size_t n = hierarchy_.patches().size();
    rows(elements, false, [&](std::size_t k, const std::vector<double>& row) {
      for (std::size_t j = 0; j < n; ++j) out[k * n + j] = static_cast<float>(std::min(row[j], 1.0));
    });
  }

  // Only the pixels that patch j covers matter, and only patches inside the pyramid from the
  // eye to j can cover them: those are found by a shaft query, rasterised within j's screen
  // rectangle, so a column costs about (sources x samples x 5 faces) small rasterisations
  // instead of full hemicubes. Same pixels, same depth order: the values equal the rows'.
  void patch_column(std::uint32_t patch, const std::vector<std::uint32_t>& elements, float* out) const override {
    parallel_for(options_.threads, elements.size(), 16, [&](std::size_t begin, std::size_t end) {
      Raster raster;
      std::vector<std::uint32_t> candidates;
      std::vector<Projected> projected;
      for (std::size_t k = begin; k < end; ++k)
        out[k] = static_cast<float>(column_entry(elements[k], patch, false, raster, candidates, projected));
    });
  }

 private:
  // Calls emit(k, row) with the full hemicube row (every target) of each element's front, or
  // back when `back`, from parallel workers.
  template <typename Emit>
  void rows(const std::vector<std::uint32_t>& elements, bool back, const Emit& emit) const {
    parallel_for(options_.threads, elements.size(), 4, [&](std::size_t begin, std::size_t end) {
      Raster raster;
      const std::size_t pixels = static_cast<std::size_t>(faces_[0].width) * static_cast<std::size_t>(faces_[0].height);
      raster.depth.assign(pixels, 0.0f);
      raster.item.assign(pixels, kNoItem);
      std::vector<Projected> projected;
      std::vector<double> row(target_count());
      for (std::size_t k = begin; k < end; ++k) {
        std::fill(row.begin(), row.end(), 0.0);
        for (std::size_t s = 0; s < uv_.size(); ++s) {
          const Frame frame = sample_frame(elements[k], s, back);
          project_all(frame, projected);
          for (int f = 0; f < 5; ++f) {
            const FaceGeometry& face = faces_[f];
            const Scissor all{0, 0, face.width, face.height};
            raster.touched = Scissor{face.width, face.height, 0, 0};
            for (const Projected& p : projected) draw(f, p, all, raster);
            gather(f, raster.touched, frame.weight, raster, row);
          }
        }
        emit(k, row);
      }
    });
  }

  // With diffuse transmission, rows and columns run over every target (backs after the patches).
  void target_rows(const std::vector<std::uint32_t>& elements, bool back,
                   std::vector<SparseFactors>& out) const override {
    out.assign(elements.size(), SparseFactors{});
    rows(elements, back, [&](std::size_t k, const std::vector<double>& row) {
      for (std::size_t t = 0; t < row.size(); ++t)
        if (row[t] > 0.0) {
          out[k].index.push_back(static_cast<std::uint32_t>(t));
          out[k].value.push_back(static_cast<float>(std::min(row[t], 1.0)));
        }
    });
  }

  void target_column(std::uint32_t target, const std::vector<std::uint32_t>& elements, float* column) const override {
    const std::size_t m = elements.size();
    parallel_for(options_.threads, m, 16, [&](std::size_t begin, std::size_t end) {
      Raster raster;
      std::vector<std::uint32_t> candidates;
      std::vector<Projected> projected;
      for (std::size_t k = begin; k < end; ++k) {
        column[k] = static_cast<float>(column_entry(elements[k], target, false, raster, candidates, projected));
        if (back_item_[hierarchy_.element(elements[k]).patch] != kNoItem)
          column[m + k] = static_cast<float>(column_entry(elements[k], target, true, raster, candidates, projected));
      }
    });
  }

  struct Frame {
    glm::vec3 eye{0.0f}, t1{0.0f}, t2{0.0f}, n{0.0f};
    PolygonId polygon = 0;
    double weight = 0.0;  ///< quadrature weight of the point (rule weight x area density)
  };

  // Exact delta form factors: the unoccluded factor from the eye to each pixel's square, stored
  // as prefix sums along each row (width + 1 entries per row), so that a run of pixels of one
  // patch costs one subtraction. A row sums to at most ~1/height, so float prefixes keep an
  // absolute error near 1e-10.
  void delta_forms() {
    for (int f = 0; f < 2; ++f) {
      const FaceGeometry& face = faces_[f];
      const auto width = static_cast<std::size_t>(face.width);
      std::vector<double> delta(width * static_cast<std::size_t>(face.height), -1.0);
      for (int r = 0; r < face.height; ++r)
        for (int c = 0; c < face.width; ++c) {
          const std::size_t i = static_cast<std::size_t>(r) * width + static_cast<std::size_t>(c);
          if (delta[i] >= 0.0) continue;  // known by symmetry
          const float x0 = -1.0f + static_cast<float>(c) / face.scale_x,
                      x1 = -1.0f + static_cast<float>(c + 1) / face.scale_x;
          const float y0 = face.y_min + static_cast<float>(r) / face.scale_y;
          const float y1 = face.y_min + static_cast<float>(r + 1) / face.scale_y;
          // Frame coordinates (T1, T2, N) of the pixel's corners; the top face lies at N = 1,
          // the side face (looking along +T1) at T1 = 1.
          std::array<glm::vec3, 4> sq;
          if (f == 0)
            sq = {glm::vec3(x0, y0, 1), glm::vec3(x1, y0, 1), glm::vec3(x1, y1, 1), glm::vec3(x0, y1, 1)};
          else
            sq = {glm::vec3(1, x0, y0), glm::vec3(1, x1, y0), glm::vec3(1, x1, y1), glm::vec3(1, x0, y1)};
          const double d = point_to_polygon_factor(glm::vec3(0.0f), glm::vec3(0, 0, 1), sq.data(), 4);
          // The faces are symmetric about their vertical centre line, and the top face also
          // about its horizontal one: mirrored pixels have the same delta form factor.
          const std::size_t mc = width - 1 - static_cast<std::size_t>(c);
          const std::size_t mr = static_cast<std::size_t>(face.height - 1 - r);
          delta[i] = d;
          delta[static_cast<std::size_t>(r) * width + mc] = d;
          if (f == 0) {
            delta[mr * width + static_cast<std::size_t>(c)] = d;
            delta[mr * width + mc] = d;
          }
        }
      const std::size_t stride = width + 1;
      std::vector<float>& prefix = prefix_[static_cast<std::size_t>(f)];
      prefix.assign(stride * static_cast<std::size_t>(face.height), 0.0f);
      for (std::size_t r = 0; r < static_cast<std::size_t>(face.height); ++r) {
        double sum = 0.0;
        for (std::size_t c = 0; c < width; ++c) {
          sum += delta[r * width + c];
          prefix[r * stride + c + 1] = static_cast<float>(sum);
        }
      }
    }
  }

  // Adds w x (the delta form factors of each patch's pixels) within `t` to row[patch] and clears
  // those pixels. Consecutive pixels of one patch form runs, summed from the prefix sums.
  void gather(int f, const Scissor& t, double w, Raster& raster, std::vector<double>& row) const {
    const FaceGeometry& face = faces_[f];
    const float* prefix = prefix_[f == 0 ? 0 : 1].data();
    const auto stride = static_cast<std::size_t>(face.width) + 1;
    for (int r = t.y0; r < t.y1; ++r) {
      const std::size_t base = static_cast<std::size_t>(r) * static_cast<std::size_t>(face.width);
      const float* p = prefix + static_cast<std::size_t>(r) * stride;
      const std::uint32_t* items = raster.item.data() + base;
      int c = t.x0;
      while (c < t.x1) {
        const std::uint32_t id = items[c];
        const int start = c;
        while (c < t.x1 && items[c] == id) ++c;
        if (id != kNoItem) row[id] += w * static_cast<double>(p[c] - p[start]);
      }
      std::fill(raster.item.begin() + static_cast<std::ptrdiff_t>(base) + t.x0,
                raster.item.begin() + static_cast<std::ptrdiff_t>(base) + t.x1, kNoItem);
      std::fill(raster.depth.begin() + static_cast<std::ptrdiff_t>(base) + t.x0,
                raster.depth.begin() + static_cast<std::ptrdiff_t>(base) + t.x1, 0.0f);
    }
  }

  // The hemicube at sample s of element e: its eye (lifted off the surface by offset_ so that
  // the source's own plane is strictly below the horizon) and its frame, turned about the
  // normal by an angle from the element's own stream.
  // `back`: the hemicube over the element's back side.
  Frame sample_frame(std::uint32_t e, std::size_t s, bool back = false) const {
    const Element& el = hierarchy_.element(e);
    const Patch& patch = hierarchy_.patches()[el.patch];
    std::array<glm::vec3, 4> c;
    for (int k = 0; k < el.corner_count(); ++k)
      c[static_cast<std::size_t>(k)] = hierarchy_.vertices()[el.corners[static_cast<std::size_t>(k)]];
    const CellMap map(c.data(), el.corner_count());
    Frame f;
    f.n = back ? -patch.normal : patch.normal;
    f.eye = map.point(uv_[s]) + offset_ * f.n;
    f.weight = weight_[s] * static_cast<double>(map.density(uv_[s]));
    f.polygon = patch.polygon;
    const glm::vec3 helper = std::fabs(f.n.x) < 0.6f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    const glm::vec3 u = glm::normalize(glm::cross(helper, f.n)), v = glm::cross(f.n, u);
    Rng rng(options_.seed, e, stream_key(back ? Stream::hemicube_back : Stream::hemicube_front, s));
    const float phi = static_cast<float>(kTwoPi) * rng.uniform();
    f.t1 = std::cos(phi) * u + std::sin(phi) * v;
    f.t2 = glm::cross(f.n, f.t1);
    return f;
  }

  bool project(const Frame& frame, std::uint32_t j, Projected& p) const {
    const Patch& patch = hierarchy_.patches()[j];
    if (patch.polygon == frame.polygon) return false;
    p.count = counts_[j];
    bool above = false;
    for (int k = 0; k < p.count; ++k) {
      const glm::vec3 d = corners_[j][static_cast<std::size_t>(k)] - frame.eye;
      p.q[static_cast<std::size_t>(k)] = glm::vec3(glm::dot(d, frame.t1), glm::dot(d, frame.t2), glm::dot(d, frame.n));
      above |= p.q[static_cast<std::size_t>(k)].z > 0.0f;
    }
    if (!above) return false;
    p.normal =
        glm::vec3(glm::dot(patch.normal, frame.t1), glm::dot(patch.normal, frame.t2), glm::dot(patch.normal, frame.n));
    p.plane = glm::dot(p.normal, p.q[0]);
    if (std::fabs(p.plane) <= edge_on_) return false;  // seen edge-on: covers no pixel
    p.item = p.plane < 0.0f ? j : back_item_[j];
    return true;
  }

  void project_all(const Frame& frame, std::vector<Projected>& out) const {
    out.clear();
    Projected p;
    for (std::uint32_t j = 0; j < corners_.size(); ++j)
      if (project(frame, j, p)) out.push_back(p);
  }

  // Clips patch p to face f's view pyramid (near plane included) and returns its corners in
  // pixel coordinates; 0 when nothing is left. Intersections are computed from the inside
  // corner, so two patches sharing an edge get bit-identical clipped corners.
  int clip(int f, const Projected& p, std::array<V2, 12>& screen) const {
    std::array<V3, 12> a, b;
    int m = p.count;
    unsigned all_out = 0x1f;
    for (int k = 0; k < m; ++k) {
      a[static_cast<std::size_t>(k)] = face_view(f, p.q[static_cast<std::size_t>(k)]);
      unsigned out = 0;
      for (int plane = 0; plane < 5; ++plane)
        if (clip_value(plane, a[static_cast<std::size_t>(k)], f == 0, near_) < 0.0f) out |= 1u << plane;
      all_out &= out;
    }
    if (all_out != 0) return 0;  // entirely outside one plane
    for (int plane = 0; plane < 5 && m >= 3; ++plane) {
      int o = 0;
      for (int k = 0; k < m; ++k) {
        const V3& u = a[static_cast<std::size_t>(k)];
        const V3& v = a[static_cast<std::size_t>((k + 1) % m)];
        const float du = clip_value(plane, u, f == 0, near_), dv = clip_value(plane, v, f == 0, near_);
        if (du >= 0.0f) b[static_cast<std::size_t>(o++)] = u;
        if ((du >= 0.0f) != (dv >= 0.0f)) {
          const V3& in = du >= 0.0f ? u : v;
          const V3& out = du >= 0.0f ? v : u;
          const float din = du >= 0.0f ? du : dv, dout = du >= 0.0f ? dv : du;
          const float t = din / (din - dout);
          b[static_cast<std::size_t>(o++)] = {in.x + t * (out.x - in.x), in.y + t * (out.y - in.y),
                                              in.z + t * (out.z - in.z)};
        }
      }
      m = o;
      std::swap(a, b);
    }
    if (m < 3) return 0;
    const FaceGeometry& face = faces_[f];
    for (int k = 0; k < m; ++k) {
      const V3& v = a[static_cast<std::size_t>(k)];
      screen[static_cast<std::size_t>(k)] = {(v.x / v.z + 1.0f) * face.scale_x,
                                             (v.y / v.z - face.y_min) * face.scale_y};
    }
    return m;
  }

  // Scan-converts patch p onto face f inside the scissor: a pixel is covered when its centre is
  // inside the projected polygon (left and top edges inclusive, so neighbours sharing an edge
  // never both cover a pixel nor leave a gap), and taken when p is nearer than what is there.
  void draw(int f, const Projected& p, const Scissor& box, Raster& raster) const {
    std::array<V2, 12> v;
    const int m = clip(f, p, v);
    if (m < 3) return;
    const FaceGeometry& face = faces_[f];
    // Inverse depth is affine in screen coordinates: with the plane dot(n, x) = plane and the
    // view direction (X, Y, 1), 1/z = (n.x X + n.y Y + n.z) / plane.
    const V3 nf = face_view(f, p.normal);
    const float inv = 1.0f / p.plane;
    const float ax = nf.x * inv / face.scale_x, ay = nf.y * inv / face.scale_y;
    const float a0 = (nf.x * -1.0f + nf.y * face.y_min + nf.z) * inv;
    // Edges with their lower end first (so a shared edge gives both neighbours the same
    // crossings) and their slope dx/dy; horizontal edges cross no pixel centre row.
    struct Edge {
      float y0, y1, x0, slope;
    };
    std::array<Edge, 12> edges;
    int edge_count = 0;
    float ymin = v[0].y, ymax = v[0].y;
    for (int k = 0; k < m; ++k) {
      V2 e0 = v[static_cast<std::size_t>(k)], e1 = v[static_cast<std::size_t>((k + 1) % m)];
      ymin = std::min(ymin, e0.y);
      ymax = std::max(ymax, e0.y);
      if (e0.y == e1.y) continue;
      if (e1.y < e0.y) std::swap(e0, e1);
      edges[static_cast<std::size_t>(edge_count++)] = Edge{e0.y, e1.y, e0.x, (e1.x - e0.x) / (e1.y - e0.y)};
    }
    const int r0 = std::max(box.y0, static_cast<int>(std::ceil(ymin - 0.5f)));
    const int r1 = std::min(box.y1, static_cast<int>(std::ceil(ymax - 0.5f)));
    const std::uint32_t id = p.item;
    for (int r = r0; r < r1; ++r) {
      const float yc = static_cast<float>(r) + 0.5f;
      float xl = 1e30f, xr = -1e30f;
      for (int k = 0; k < edge_count; ++k) {
        const Edge& e = edges[static_cast<std::size_t>(k)];
        if (yc < e.y0 || yc >= e.y1) continue;
        const float x = e.x0 + (yc - e.y0) * e.slope;
        xl = std::min(xl, x);
        xr = std::max(xr, x);
      }
      if (!(xl < xr)) continue;
      const int c0 = std::max(box.x0, static_cast<int>(std::ceil(xl - 0.5f)));
      const int c1 = std::min(box.x1, static_cast<int>(std::ceil(xr - 0.5f)));
      if (c0 >= c1) continue;
      raster.touched = Scissor{std::min(raster.touched.x0, c0), std::min(raster.touched.y0, r),
                               std::max(raster.touched.x1, c1), std::max(raster.touched.y1, r + 1)};
      // Unconditional loads and stores of selected values, so the depth test vectorises.
      float* depth = raster.depth.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(face.width);
      std::uint32_t* items = raster.item.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(face.width);
      const float row0 = a0 + ay * yc + 0.5f * ax;
      for (int c = c0; c < c1; ++c) {
        const float w = row0 + ax * static_cast<float>(c);
        const float d = depth[c];
        const std::uint32_t old = items[c];
        const std::uint32_t nearer = 0u - static_cast<std::uint32_t>(w > d);  // all ones when nearer
        depth[c] = std::max(w, d);
        items[c] = (id & nearer) | (old & ~nearer);
      }
    }
  }

  // F(e -> target) (from e's back when `back`); `target` is a patch or a translucent patch's back.
  double column_entry(std::uint32_t e, std::uint32_t t, bool back, Raster& raster,
                      std::vector<std::uint32_t>& candidates, std::vector<Projected>& projected) const {
    const std::size_t n = hierarchy_.patches().size();
    const std::uint32_t j = t < n ? t : translucent_patches()[t - n];
    const glm::vec3 receiver_normal = t < n ? hierarchy_.patches()[j].normal : -hierarchy_.patches()[j].normal;
    double sum = 0.0;
    for (std::size_t s = 0; s < uv_.size(); ++s) {
      const Frame frame = sample_frame(e, s, back);
      Projected target;
      if (!project(frame, j, target) || target.item != t) continue;
      // The patches that can hide part of j from the eye are inside the pyramid eye -> j.
      Shaft shaft;
      if (!shaft.build(&frame.eye, 1, frame.n, corners_[j].data(), counts_[j], receiver_normal, offset_))
        continue;
      candidates.clear();
      patch_culler_.collect(shaft, j, candidates);
      candidates.insert(std::upper_bound(candidates.begin(), candidates.end(), j), j);
      projected.clear();
      Projected p;
      for (const std::uint32_t c : candidates)
        if (project(frame, c, p)) projected.push_back(p);
      for (int f = 0; f < 5; ++f) {
        std::array<V2, 12> v;
        const int m = clip(f, target, v);
        if (m < 3) continue;
        const FaceGeometry& face = faces_[f];
        float x0 = v[0].x, x1 = v[0].x, y0 = v[0].y, y1 = v[0].y;
        for (int k = 1; k < m; ++k) {
          x0 = std::min(x0, v[static_cast<std::size_t>(k)].x);
          x1 = std::max(x1, v[static_cast<std::size_t>(k)].x);
          y0 = std::min(y0, v[static_cast<std::size_t>(k)].y);
          y1 = std::max(y1, v[static_cast<std::size_t>(k)].y);
        }
        const Scissor box{std::max(0, static_cast<int>(std::floor(x0))), std::max(0, static_cast<int>(std::floor(y0))),
                          std::min(face.width, static_cast<int>(std::ceil(x1)) + 1),
                          std::min(face.height, static_cast<int>(std::ceil(y1)) + 1)};
        if (box.x0 >= box.x1 || box.y0 >= box.y1) continue;
        raster.depth.resize(static_cast<std::size_t>(face.width) * static_cast<std::size_t>(face.height));
        raster.item.resize(raster.depth.size());
        for (int r = box.y0; r < box.y1; ++r) {
          const std::size_t base = static_cast<std::size_t>(r) * static_cast<std::size_t>(face.width);
          std::fill(raster.depth.begin() + static_cast<std::ptrdiff_t>(base + static_cast<std::size_t>(box.x0)),
                    raster.depth.begin() + static_cast<std::ptrdiff_t>(base + static_cast<std::size_t>(box.x1)), 0.0f);
          std::fill(raster.item.begin() + static_cast<std::ptrdiff_t>(base + static_cast<std::size_t>(box.x0)),
                    raster.item.begin() + static_cast<std::ptrdiff_t>(base + static_cast<std::size_t>(box.x1)),
                    kNoItem);
        }
        for (const Projected& q : projected) draw(f, q, box, raster);
        const float* prefix = prefix_[f == 0 ? 0 : 1].data();
        const auto stride = static_cast<std::size_t>(face.width) + 1;
        double face_sum = 0.0;
        for (int r = box.y0; r < box.y1; ++r) {
          const std::uint32_t* items =
              raster.item.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(face.width);
          const float* sums = prefix + static_cast<std::size_t>(r) * stride;
          for (int c = box.x0; c < box.x1;) {
            const int start = c;
            const bool mine = items[c] == t;
            while (c < box.x1 && (items[c] == t) == mine) ++c;
            if (mine) face_sum += static_cast<double>(sums[c] - sums[start]);
          }
        }
        sum += frame.weight * face_sum;
      }
    }
    return std::min(sum, 1.0);
  }

  const PatchHierarchy& hierarchy_;
  FormFactorOptions options_;
  float offset_ = 0.0f, near_ = 0.0f, edge_on_ = 0.0f;
  std::array<FaceGeometry, 5> faces_{};
  std::array<std::vector<float>, 2> prefix_;  // top face, side face (the four sides are alike)
  std::vector<std::array<glm::vec3, 4>> corners_;
  std::vector<int> counts_;
  ShaftCuller patch_culler_;
  std::vector<glm::vec2> uv_;
  std::vector<double> weight_;
  std::vector<std::uint32_t> back_item_;  // per patch: its back target when translucent, else kNoItem
};

}  // namespace

std::unique_ptr<FormFactorEstimator> make_hemicube_estimator(const Scene& scene, const PatchHierarchy& hierarchy,
                                                             const FormFactorOptions& options) {
  return std::make_unique<HemicubeEstimator>(scene, hierarchy, options);
}

}  // namespace radiosity::detail
