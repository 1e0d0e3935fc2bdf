// Ray queries against a set of triangles, backed by an Embree BVH. Private to the library: no
// public header mentions Embree.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

namespace radiosity {
inline namespace v1 {
class Scene;
class PatchHierarchy;
}  // namespace v1
}  // namespace radiosity

namespace radiosity::detail {

/// The configuration every Embree device of the library is made with (rtcNewDevice): the
/// default (nullptr: Embree builds on oneTBB, which composes with our loops), except under
/// ThreadSanitizer, where it is "threads=1": Debian's Embree and oneTBB are not instrumented,
/// so a BVH built on oneTBB's workers, calling back into our code, would be reported as racing
/// with the thread that waited for it (tests/tsan.supp, src/core/parallel.hpp).
const char* embree_device_config();

/// A triangle mesh with a user id per triangle, committed once and then queried from any
/// number of threads. Move-only.
/// Thread safety: occluded() and intersect() may be called concurrently.
class RayScene {
 public:
  struct Hit {
    float t = 0.0f;
    std::uint32_t id = 0;        ///< the user id of the triangle hit
    std::uint32_t triangle = 0;  ///< index of the triangle hit
    float u = 0.0f, v = 0.0f;    ///< barycentric coordinates of vertices 1 and 2
    glm::vec3 geometric_normal{0.0f};  ///< unnormalised, right-hand rule of the triangle
  };

  /// `triangles` indexes `positions`; `ids` has one entry per triangle. `back_is_inside` (empty,
  /// or one flag per triangle): 1 where the triangle's back is no surface (one-sided, opaque),
  /// so that intersect() may take a coincident front instead of it. Throws Error{internal}
  /// if Embree cannot create a device.
  RayScene(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& triangles,
           std::vector<std::uint32_t> ids, std::vector<std::uint8_t> back_is_inside = {});
  RayScene(RayScene&& other) noexcept;
  RayScene& operator=(RayScene&& other) noexcept;
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;
  ~RayScene();

  /// The scene's polygons, fan-triangulated; ids are polygon ids.
  static RayScene from_polygons(const Scene& scene);
  /// The hierarchy's leaf elements (quads as two triangles); ids are element ids. With
  /// `back_is_inside` (per patch, from backs_inside()), intersect() prefers coincident fronts
  /// as from_polygons()'s does; without, it returns the nearest hit as it is (point location).
  static RayScene from_leaves(const PatchHierarchy& hierarchy, const std::vector<std::uint8_t>& back_is_inside = {});
  /// Per patch of `hierarchy` (meshed from `scene`): 1 when its material's back is no surface
  /// (one-sided, opaque, no BRDF of its own), for from_leaves().
  static std::vector<std::uint8_t> backs_inside(const Scene& scene, const PatchHierarchy& hierarchy);

  /// True when something lies on the segment origin + t*dir, t in (tnear, tfar).
  bool occluded(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar) const;
  /// occluded() for `count` segments origin[i] + t*dir[i], t in (tnear, tfar): blocked[i] = 1
  /// when something lies on segment i, else 0. Traced as coherent packets, with the same
  /// answers as occluded(): for bundles of rays between two nearby surfaces this is 2-3x faster
  /// than one ray at a time. The packets are the narrowest native size (4, 8 or 16 rays) that
  /// holds the batch, the widest for larger batches: a batch of 4 in a packet of 16 pays for 16
  /// lanes (the hierarchical links' pilots and most of their estimates are 4 rays: the 246k
  /// city's link refinement took 0.85-0.95 times the time with the narrowest packet, each run
  /// measured against its sky's rays, five pairs alternated; docs/HIERARCHICAL.md).
  void occluded(std::size_t count, const glm::vec3* origin, const glm::vec3* dir, float tnear, float tfar,
                std::uint8_t* blocked) const;
  /// The same answers as occluded() for `count` segments that go their own ways (sky
  /// directions from one element: packets were 1.3x slower on the benchmark city): Embree's
  /// stream mode for batches of 64 rays or more (1.3x faster than one at a time there), one ray
  /// at a time for fewer.
  void occluded_incoherent(std::size_t count, const glm::vec3* origin, const glm::vec3* dir, float tnear, float tfar,
                           std::uint8_t* blocked) const;
  /// The nearest hit on the ray within (tnear, tfar); where a back and a front are one surface
  /// (coincident within 2e-5 of the scene's diagonal, facing apart), the front.
  std::optional<Hit> intersect(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar) const;
  /// intersect() for `count` rays as packets of Embree's widest native size: found[i] = 1 and
  /// hits[i] filled when ray i hits something, else found[i] = 0. Same answers as intersect().
  void intersect(std::size_t count, const glm::vec3* origin, const glm::vec3* dir, float tnear, float tfar, Hit* hits,
                 std::uint8_t* found) const;

  const std::vector<std::uint32_t>& triangle_ids() const { return ids_; }
  /// Vertex indices of a triangle (three entries).
  const std::uint32_t* triangle(std::uint32_t index) const { return &indices_[3 * index]; }

 private:
  void release() noexcept;

  void* device_ = nullptr;  // RTCDevice
  void* scene_ = nullptr;   // RTCScene
  /// A hit on the back of a one-sided opaque triangle (back_is_inside_) with a front within
  /// coincidence_ of it (a wall modelled as two coincident faces, one per room) becomes that
  /// front's hit: from either side the ray meets the face toward it, as if the two were one
  /// wall, instead of whichever rounding picks (a back, which absorbs everything). A two-sided
  /// or transmitting back is a surface of its own and stays the hit.
  void prefer_front(const glm::vec3& origin, const glm::vec3& dir, float tnear, Hit& h) const;

  int packet_width_ = 1;    // widest ray packet the CPU runs natively (16, 8, 4, or 1)
  int narrow_packets_ = 0;  // native packet widths below packet_width_: 4 and/or 8, as bits
  float coincidence_ = 0.0f;  // distance below which two surfaces are one (kOverlapRelativeTolerance x diagonal)
  std::vector<std::uint32_t> ids_;
  std::vector<std::uint32_t> indices_;
  std::vector<std::uint8_t> back_is_inside_;  // per triangle, or empty
};

}  // namespace radiosity::detail
