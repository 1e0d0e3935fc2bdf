// Embree-backed ray queries.
// Based on: Wald, Woop, Benthin, Johnson & Ernst, "Embree: A Kernel Framework for Efficient CPU
// Ray Tracing", ACM TOG 33(4), 2014.
#include "geometry/ray_scene.hpp"

#include <algorithm>
#include <cstring>
#include <utility>
#include <limits>
#include <string>

#include <embree3/rtcore.h>

#include "core/thread_sanitizer.hpp"
#include "scene/overlap.hpp"
#include "radiosity/mesh.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

namespace {

RTCDevice as_device(void* p) { return static_cast<RTCDevice>(p); }
RTCScene as_scene(void* p) { return static_cast<RTCScene>(p); }

/// One ray origin + t dir, t in (tnear, tfar), for the single-ray and stream calls.
RTCRay single_ray(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar, unsigned id) {
  RTCRay ray;
  ray.org_x = origin.x;
  ray.org_y = origin.y;
  ray.org_z = origin.z;
  ray.dir_x = dir.x;
  ray.dir_y = dir.y;
  ray.dir_z = dir.z;
  ray.tnear = tnear;
  ray.tfar = tfar;
  ray.time = 0.0f;
  ray.mask = 0xffffffffu;
  ray.id = id;
  ray.flags = 0;
  return ray;
}

// Keeps only hits on a triangle's front (the ray against its geometric normal): the second
// query of RayScene::prefer_front().
void front_only(const RTCFilterFunctionNArguments* args) {
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const float dot = RTCRayN_dir_x(args->ray, args->N, i) * RTCHitN_Ng_x(args->hit, args->N, i) +
                      RTCRayN_dir_y(args->ray, args->N, i) * RTCHitN_Ng_y(args->hit, args->N, i) +
                      RTCRayN_dir_z(args->ray, args->N, i) * RTCHitN_Ng_z(args->hit, args->N, i);
    if (dot > 0.0f) args->valid[i] = 0;
  }
}

}  // namespace

const char* embree_device_config() {
#if defined(RADIOSITY_THREAD_SANITIZER)
  return "threads=1";
#else
  return nullptr;
#endif
}

RayScene::RayScene(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& triangles,
                   std::vector<std::uint32_t> ids, std::vector<std::uint8_t> back_is_inside)
    : ids_(std::move(ids)), indices_(triangles), back_is_inside_(std::move(back_is_inside)) {
  // Embree must not start its own threads beyond what the caller's TBB arena allows; the
  // default configuration uses TBB, which composes with ours.
  RTCDevice device = rtcNewDevice(embree_device_config());
  if (!device)
    throw Error(ErrorCode::internal, "Embree: cannot create a device (error " +
                                         std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
  device_ = device;
  RTCScene scene = rtcNewScene(device);
  scene_ = scene;
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  // Context filters: prefer_front()'s second query, which only hits fronts.
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
  if (!positions.empty()) {
    glm::vec3 lo = positions[0], hi = positions[0];
    for (const glm::vec3& p : positions) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    coincidence_ = static_cast<float>(touching_tolerance(lo, hi));
  }

  if (!indices_.empty()) {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), positions.size()));
    for (std::size_t i = 0; i < positions.size(); ++i) std::memcpy(vb + 3 * i, &positions[i], 3 * sizeof(float));
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(unsigned), indices_.size() / 3));
    std::memcpy(ib, indices_.data(), indices_.size() * sizeof(unsigned));
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(scene);
  for (const auto& [property, width] : {std::pair{RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED, 16},
                                        std::pair{RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED, 8},
                                        std::pair{RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED, 4}}) {
    if (rtcGetDeviceProperty(device, property) == 0) continue;
    if (packet_width_ == 1)
      packet_width_ = width;
    else
      narrow_packets_ |= width;
  }
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE) {
    release();
    throw Error(ErrorCode::internal, "Embree: building the ray-query scene failed");
  }
}

RayScene::RayScene(RayScene&& other) noexcept
    : device_(other.device_),
      scene_(other.scene_),
      packet_width_(other.packet_width_),
      narrow_packets_(other.narrow_packets_),
      coincidence_(other.coincidence_),
      ids_(std::move(other.ids_)),
      indices_(std::move(other.indices_)),
      back_is_inside_(std::move(other.back_is_inside_)) {
  other.device_ = nullptr;
  other.scene_ = nullptr;
}

RayScene& RayScene::operator=(RayScene&& other) noexcept {
  if (this != &other) {
    release();
    device_ = other.device_;
    scene_ = other.scene_;
    packet_width_ = other.packet_width_;
    narrow_packets_ = other.narrow_packets_;
    coincidence_ = other.coincidence_;
    ids_ = std::move(other.ids_);
    indices_ = std::move(other.indices_);
    back_is_inside_ = std::move(other.back_is_inside_);
    other.device_ = nullptr;
    other.scene_ = nullptr;
  }
  return *this;
}

RayScene::~RayScene() { release(); }

void RayScene::release() noexcept {
  if (scene_) rtcReleaseScene(as_scene(scene_));
  if (device_) rtcReleaseDevice(as_device(device_));
  scene_ = nullptr;
  device_ = nullptr;
}

namespace {

// 1 when a material's back is no surface: one-sided, opaque, its own BRDF unset (which may
// transmit).
std::uint8_t back_is_inside(const Material& m) {
  const bool transmits = m.transmittance.x > 0.0f || m.transmittance.y > 0.0f || m.transmittance.z > 0.0f ||
                         m.diffuse_transmittance.x > 0.0f || m.diffuse_transmittance.y > 0.0f ||
                         m.diffuse_transmittance.z > 0.0f;
  return m.two_sided || transmits || m.brdf ? 0 : 1;
}

}  // namespace

RayScene RayScene::from_polygons(const Scene& scene) {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> triangles, ids;
  std::vector<std::uint8_t> inside;
  const auto& polygons = scene.polygons();
  for (std::size_t p = 0; p < polygons.size(); ++p) {
    const auto& v = polygons[p].vertices;
    auto base = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), v.begin(), v.end());
    const std::uint8_t flag = back_is_inside(scene.material(polygons[p].material));
    // Polygons are convex, so a fan covers them exactly.
    for (std::uint32_t k = 1; k + 1 < v.size(); ++k) {
      triangles.insert(triangles.end(), {base, base + k, base + k + 1});
      ids.push_back(static_cast<std::uint32_t>(p));
      inside.push_back(flag);
    }
  }
  return RayScene(positions, triangles, std::move(ids), std::move(inside));
}

std::vector<std::uint8_t> RayScene::backs_inside(const Scene& scene, const PatchHierarchy& hierarchy) {
  std::vector<std::uint8_t> out;
  out.reserve(hierarchy.patches().size());
  // A hierarchy from another scene (which the callers refuse after this) must not index past
  // the materials: such patches get 0.
  for (const Patch& p : hierarchy.patches())
    out.push_back(p.material < scene.materials().size() ? back_is_inside(scene.material(p.material)) : 0);
  return out;
}

RayScene RayScene::from_leaves(const PatchHierarchy& hierarchy, const std::vector<std::uint8_t>& back_is_inside) {
  std::vector<std::uint32_t> triangles, ids;
  std::vector<std::uint8_t> inside;
  const bool flags = !back_is_inside.empty();
  for (std::uint32_t e : hierarchy.leaves()) {
    const Element& el = hierarchy.element(e);
    const std::uint8_t flag = flags ? back_is_inside[el.patch] : 0;
    triangles.insert(triangles.end(), {el.corners[0], el.corners[1], el.corners[2]});
    ids.push_back(e);
    inside.push_back(flag);
    if (el.corner_count() == 4) {
      triangles.insert(triangles.end(), {el.corners[0], el.corners[2], el.corners[3]});
      ids.push_back(e);
      inside.push_back(flag);
    }
  }
  if (!flags) inside.clear();
  return RayScene(hierarchy.vertices(), triangles, std::move(ids), std::move(inside));
}

bool RayScene::occluded(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray = single_ray(origin, dir, tnear, tfar, 0);
  rtcOccluded1(as_scene(scene_), &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

void RayScene::occluded_incoherent(std::size_t count, const glm::vec3* origin, const glm::vec3* dir, float tnear,
                                   float tfar, std::uint8_t* blocked) const {
  // Embree's stream mode (rtcOccluded1M, incoherent) sorts a batch of rays into packets that
  // travel the BVH together; below a few dozen rays its set-up costs more than it saves.
  // Measured on the 22k city: the sky's first shot (batches of 256 and 1024 rays) 1.25 s -> 0.93 s;
  // the hierarchical links (4 to 64 rays) slower in stream mode at 16 rays, unchanged at 64.
  constexpr std::size_t kStreamMinimum = 64;
  if (count < kStreamMinimum) {
    for (std::size_t i = 0; i < count; ++i) blocked[i] = occluded(origin[i], dir[i], tnear, tfar) ? 1 : 0;
    return;
  }
  thread_local std::vector<RTCRay> rays;
  rays.resize(count);
  for (std::size_t i = 0; i < count; ++i) rays[i] = single_ray(origin[i], dir[i], tnear, tfar, static_cast<unsigned>(i));
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  rtcOccluded1M(as_scene(scene_), &context, rays.data(), static_cast<unsigned>(count), sizeof(RTCRay));
  for (std::size_t i = 0; i < count; ++i) blocked[i] = rays[i].tfar < 0.0f ? 1 : 0;
}

namespace {

/// Lane k of a packet of rays (RTCRay4/8/16): the ray origin + t dir, t in (tnear, tfar).
template <typename RayK>
void set_lane(RayK& ray, std::size_t k, const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar) {
  ray.org_x[k] = origin.x;
  ray.org_y[k] = origin.y;
  ray.org_z[k] = origin.z;
  ray.dir_x[k] = dir.x;
  ray.dir_y[k] = dir.y;
  ray.dir_z[k] = dir.z;
  ray.tnear[k] = tnear;
  ray.tfar[k] = tfar;
  ray.time[k] = 0.0f;
  ray.mask[k] = 0xffffffffu;
  ray.id[k] = 0;
  ray.flags[k] = 0;
}

// Segments [i, i + K) of the batch as one packet of K rays; lanes past `count` are switched off.
template <int K, typename RayK, typename Occluded>
void occluded_packets(RTCScene scene, std::size_t count, const glm::vec3* origin, const glm::vec3* dir, float tnear,
                      float tfar, std::uint8_t* blocked, Occluded occluded) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  // The rays of a batch run between two nearby surfaces: Embree may trace them as a bundle.
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  RayK ray;
  alignas(64) int valid[K];
  for (std::size_t i = 0; i < count; i += K) {
    const std::size_t n = std::min<std::size_t>(K, count - i);
    for (std::size_t k = 0; k < static_cast<std::size_t>(K); ++k) {
      valid[k] = k < n ? -1 : 0;
      set_lane(ray, k, origin[k < n ? i + k : i], dir[k < n ? i + k : i], tnear, tfar);
    }
    occluded(valid, scene, &context, &ray);
    for (std::size_t k = 0; k < n; ++k) blocked[i + k] = ray.tfar[k] < 0.0f ? 1 : 0;
  }
}

}  // namespace

void RayScene::occluded(std::size_t count, const glm::vec3* origin, const glm::vec3* dir, float tnear, float tfar,
                        std::uint8_t* blocked) const {
  RTCScene scene = as_scene(scene_);
  int width = packet_width_;
  if (count <= 4 && (narrow_packets_ & 4) != 0)
    width = 4;
  else if (count <= 8 && (narrow_packets_ & 8) != 0)
    width = 8;
  switch (width) {
    case 16: occluded_packets<16, RTCRay16>(scene, count, origin, dir, tnear, tfar, blocked, rtcOccluded16); return;
    case 8: occluded_packets<8, RTCRay8>(scene, count, origin, dir, tnear, tfar, blocked, rtcOccluded8); return;
    case 4: occluded_packets<4, RTCRay4>(scene, count, origin, dir, tnear, tfar, blocked, rtcOccluded4); return;
    default:
      for (std::size_t i = 0; i < count; ++i) blocked[i] = occluded(origin[i], dir[i], tnear, tfar) ? 1 : 0;
  }
}

namespace {

template <int K, typename RayHitK, typename Intersect>
void intersect_packets(RTCScene scene, const std::vector<std::uint32_t>& ids, std::size_t count,
                       const glm::vec3* origin, const glm::vec3* dir, float tnear, float tfar, RayScene::Hit* hits,
                       std::uint8_t* found, Intersect intersect) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RayHitK rh;
  alignas(64) int valid[K];
  for (std::size_t i = 0; i < count; i += K) {
    const std::size_t n = std::min<std::size_t>(K, count - i);
    for (std::size_t k = 0; k < static_cast<std::size_t>(K); ++k) {
      valid[k] = k < n ? -1 : 0;
      set_lane(rh.ray, k, origin[k < n ? i + k : i], dir[k < n ? i + k : i], tnear, tfar);
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    intersect(valid, scene, &context, &rh);
    for (std::size_t k = 0; k < n; ++k) {
      found[i + k] = rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
      if (!found[i + k]) continue;
      RayScene::Hit& h = hits[i + k];
      h.t = rh.ray.tfar[k];
      h.triangle = rh.hit.primID[k];
      h.id = ids[rh.hit.primID[k]];
      h.u = rh.hit.u[k];
      h.v = rh.hit.v[k];
      h.geometric_normal = glm::vec3(rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k]);
    }
  }
}

}  // namespace

void RayScene::intersect(std::size_t count, const glm::vec3* origin, const glm::vec3* dir, float tnear, float tfar,
                         Hit* hits, std::uint8_t* found) const {
  RTCScene scene = as_scene(scene_);
  switch (packet_width_) {
    case 16:
      intersect_packets<16, RTCRayHit16>(scene, ids_, count, origin, dir, tnear, tfar, hits, found, rtcIntersect16);
      break;
    case 8:
      intersect_packets<8, RTCRayHit8>(scene, ids_, count, origin, dir, tnear, tfar, hits, found, rtcIntersect8);
      break;
    case 4:
      intersect_packets<4, RTCRayHit4>(scene, ids_, count, origin, dir, tnear, tfar, hits, found, rtcIntersect4);
      break;
    default:
      for (std::size_t i = 0; i < count; ++i) {
        const std::optional<Hit> h = intersect(origin[i], dir[i], tnear, tfar);
        found[i] = h ? 1 : 0;
        if (h) hits[i] = *h;
      }
      return;
  }
  for (std::size_t i = 0; i < count; ++i)
    if (found[i]) prefer_front(origin[i], dir[i], tnear, hits[i]);
}

namespace {

/// The nearest hit within (tnear, tfar) of one ray, through `filter` when not null (a context
/// filter: the scene has RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION).
std::optional<RayScene::Hit> nearest_hit(RTCScene scene, const std::vector<std::uint32_t>& ids,
                                         const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar,
                                         RTCFilterFunctionN filter) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.filter = filter;
  RTCRayHit rh;
  rh.ray = single_ray(origin, dir, tnear, tfar, 0);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  RayScene::Hit h;
  h.t = rh.ray.tfar;
  h.triangle = rh.hit.primID;
  h.id = ids[rh.hit.primID];
  h.u = rh.hit.u;
  h.v = rh.hit.v;
  h.geometric_normal = glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  return h;
}

}  // namespace

std::optional<RayScene::Hit> RayScene::intersect(const glm::vec3& origin, const glm::vec3& dir, float tnear,
                                                 float tfar) const {
  std::optional<Hit> h = nearest_hit(as_scene(scene_), ids_, origin, dir, tnear, tfar, nullptr);
  if (h) prefer_front(origin, dir, tnear, *h);
  return h;
}

void RayScene::prefer_front(const glm::vec3& origin, const glm::vec3& dir, float tnear, Hit& h) const {
  if (back_is_inside_.empty() || back_is_inside_[h.triangle] == 0) return;
  const float facing = glm::dot(dir, h.geometric_normal);
  if (!(facing > 0.0f)) return;  // a front (or edge-on): nothing to prefer
  // The ray's parameter changes by `window` while crossing a slab 2 x coincidence_ thick
  // around the plane hit.
  const float rate = facing / glm::length(h.geometric_normal);
  const float window = coincidence_ / rate;
  const std::optional<Hit> front =
      nearest_hit(as_scene(scene_), ids_, origin, dir, std::max(tnear, h.t - window), h.t + window, front_only);
  if (front) h = *front;
}

}  // namespace radiosity::detail
