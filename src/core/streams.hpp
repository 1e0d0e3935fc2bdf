// The random streams of the library, one name each. A stream is the third key of
// detail::Rng(seed, key_a, key_b): key_a says whose samples (an element, a pixel, a photon
// block), key_b which use of them, so no two uses of the same key_a ever draw the same numbers.
// Some streams take an offset (a target, a light, a chunk, a sample index) below the span
// stated here; the static_assert below keeps every stream's range apart from the others'. The
// values are the ones the code has always used, so results for a seed are unchanged.
#pragma once

#include <cstdint>

namespace radiosity::detail {

enum class Stream : std::uint64_t {
  // Form factors.
  ray_cast_front = 0x100000000ull,       ///< + target: ray_cast source and visibility samples
  ray_cast_back = 0x180000000ull,        ///< + target: the same from an element's back
  monte_carlo_row = 0x300000000ull,      ///< hemisphere rays of an element's front row
  monte_carlo_column = 0x400000000ull,   ///< + chunk: rays shot from a target for its column
  monte_carlo_light = 0x500000000ull,    ///< + light: shadow rays to an emitting polygon
  monte_carlo_back_row = 0x600000000ull, ///< hemisphere rays of an element's back row
  monte_carlo_back_light = 0x700000000ull,  ///< + light: shadow rays from an element's back
  hemicube_front = 0x4e3cc0beull,        ///< + sample: a hemicube's random rotation
  hemicube_back = 0x5e3cc0beull,         ///< + sample: the same over an element's back
  // Images (key_a: the pixel, or the element / photon block named).
  pixel_jitter = 0x7e11ull,              ///< sub-pixel positions (render() and the two-pass view alike)
  path = 0x9a7b0001ull,                  ///< the reference path tracer's paths
  two_pass_path = 0x2a550001ull,         ///< the two-pass view's specular and glossy paths
  two_pass_direct = 0xd1ec7000ull,       ///< per element: the direct part of pass 1
  photon = 0xca057100ull,                ///< per photon block: caustic photons
  // Lightmaps (key_a: the texel).
  lightmap_gather = 0x1a9e0000ull,       ///< a texel's hemisphere rays (final gather)
  lightmap_light = 0xb0000000000ull,     ///< + emitter: a texel's shadow rays to an emitting polygon
  // Lights that are not polygons (key_a: the element, or the pixel / element named).
  light_front = 0xc0000000000ull,        ///< + light: the first shot's rays from an element's front
  light_back = 0xc0100000000ull,         ///< + light: the same from an element's back
  two_pass_sky = 0xd1ec7001ull,          ///< per element: sky rays of the direct part of pass 1
  // Hierarchical radiosity (key_a: the link's receiver and source handles, 32 bits each).
  hierarchical_link = 0xe0000000000ull,  ///< a link's visibility rays
  hierarchical_enclosure = 0xe1000000000ull,  ///< key_a 2 x element + back: a side's enclosure rays
  hierarchical_leaf_visibility = 0xe2000000000ull,  ///< the final gather's rays to a link's leaves
  // View factors (key_a: the element).
  view_factor_sky = 0xf0000000000ull,    ///< an element's rays for its sky view factor
  view_factor_cost = 0xf1000000000ull,   ///< key_a 0: the pairs the automatic choice integrates to estimate
};

/// The key of `stream`, `offset` into its range.
constexpr std::uint64_t stream_key(Stream stream, std::uint64_t offset = 0) {
  return static_cast<std::uint64_t>(stream) + offset;
}

namespace streams {

/// How far each stream's offsets reach: targets, emitters and lights below 2^31, chunks below 2^32,
/// hemicube samples below 2^16; the rest take none.
struct Range {
  std::uint64_t first, span;
};
constexpr Range kRanges[] = {
    {stream_key(Stream::ray_cast_front), 1ull << 31},       {stream_key(Stream::ray_cast_back), 1ull << 31},
    {stream_key(Stream::monte_carlo_row), 1},               {stream_key(Stream::monte_carlo_column), 1ull << 32},
    {stream_key(Stream::monte_carlo_light), 1ull << 31},    {stream_key(Stream::monte_carlo_back_row), 1},
    {stream_key(Stream::monte_carlo_back_light), 1ull << 31}, {stream_key(Stream::hemicube_front), 1ull << 16},
    {stream_key(Stream::hemicube_back), 1ull << 16},        {stream_key(Stream::pixel_jitter), 1},
    {stream_key(Stream::path), 1},                          {stream_key(Stream::two_pass_path), 1},
    {stream_key(Stream::two_pass_direct), 1},               {stream_key(Stream::photon), 1},
    {stream_key(Stream::lightmap_gather), 1},               {stream_key(Stream::lightmap_light), 1ull << 31},
    {stream_key(Stream::light_front), 1ull << 31},          {stream_key(Stream::light_back), 1ull << 31},
    {stream_key(Stream::two_pass_sky), 1},                  {stream_key(Stream::hierarchical_link), 1},
    {stream_key(Stream::view_factor_sky), 1},               {stream_key(Stream::hierarchical_enclosure), 1},
    {stream_key(Stream::hierarchical_leaf_visibility), 1},
};

constexpr bool disjoint() {
  constexpr std::size_t n = sizeof(kRanges) / sizeof(kRanges[0]);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = i + 1; k < n; ++k) {
      const Range a = kRanges[i], b = kRanges[k];
      if (a.first < b.first + b.span && b.first < a.first + a.span) return false;
    }
  return true;
}
static_assert(disjoint(), "two random streams overlap: give one a key of its own");

}  // namespace streams

}  // namespace radiosity::detail
