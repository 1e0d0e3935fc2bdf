// The pixel loop of the three renderers (render(), render_path_traced(), render_two_pass()):
// bands of rows, each band's pixels in parallel, and between bands the progress report and the
// cancel check on the calling thread, as ImageOptions::on_progress promises. A renderer brings
// only its per-pixel work.
#pragma once

#include <cstddef>
#include <functional>

#include "radiosity/render.hpp"

namespace radiosity::detail {

/// How for_each_pixel() cuts the image. A band is the unit of progress and cancel: a long one
/// delays both, so each renderer sizes its bands by its cost per pixel.
struct ImageBands {
  int rows = 16;          ///< rows per band, >= 1 (the last band may have fewer)
  std::size_t grain = 16; ///< pixels per parallel chunk within a band, >= 1 (only speed depends on it)
};

/// Calls pixel(x, y) once for every pixel of the options.width x options.height image (sizes
/// >= 0; the renderers validate() theirs first), band by band from the top, on up to
/// options.threads threads (0 = all, 1 = the calling thread). After each band it reports
/// Progress{Phase::rendering, rows done / height} through a ProgressGate (at most about every
/// 50 ms, and always after the last band). When on_progress returns false no further band
/// starts and for_each_pixel() returns false: the rows of the finished bands were visited, no
/// pixel of a later band. Returns true when on_progress never cancelled. An exception from
/// `pixel` or on_progress propagates after the workers have stopped.
/// Thread safety: `pixel` is called concurrently for distinct pixels and must make each pixel's
/// result from that pixel alone (its own random stream), so the image does not depend on the
/// threads or the bands; on_progress runs on the calling thread only.
bool for_each_pixel(const ImageOptions& options, const ImageBands& bands,
                    const std::function<void(int x, int y)>& pixel);

}  // namespace radiosity::detail
