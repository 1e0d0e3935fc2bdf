// choose_camera() on a ray scene a renderer already has (render.hpp declares the public one).
#pragma once

#include <cstdint>
#include <functional>

#include "radiosity/render.hpp"
#include "geometry/ray_scene.hpp"

namespace radiosity::detail {

/// choose_camera(scene) judged on `rays`, a ray scene of `scene`'s surfaces whose ids
/// `polygon_of` maps to polygons (RayScene::from_polygons(): the identity; from_leaves(): the
/// element's polygon), so that a renderer does not build a second one (about 1 s a million
/// polygons, before its first progress report).
CameraChoice choose_camera(const Scene& scene, const RayScene& rays,
                           const std::function<PolygonId(std::uint32_t)>& polygon_of);

}  // namespace radiosity::detail
