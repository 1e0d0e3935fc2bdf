// for_each_pixel(): the one parallel pixel loop with progress and cancel (image_loop.hpp).
#include "image/image_loop.hpp"

#include <algorithm>

#include "core/assert.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"

namespace radiosity::detail {

bool for_each_pixel(const ImageOptions& options, const ImageBands& bands,
                    const std::function<void(int x, int y)>& pixel) {
  RADIOSITY_ASSERT(bands.rows >= 1 && options.width >= 0 && options.height >= 0);
  const int height = options.height;
  const std::size_t width = static_cast<std::size_t>(options.width);
  // Parallel inside a band, progress and cancel between bands, so the callback runs on this
  // thread and a cancel leaves whole rows done.
  ProgressGate gate(options.on_progress);
  for (int y0 = 0; y0 < height; y0 += bands.rows) {
    const int y1 = y0 + std::min(bands.rows, height - y0);
    const std::size_t count = static_cast<std::size_t>(y1 - y0) * width;
    parallel_for(options.threads, count, bands.grain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k)
        pixel(static_cast<int>(k % width), y0 + static_cast<int>(k / width));
    });
    const Progress progress{Phase::rendering, static_cast<double>(y1) / height, 0, 0.0};
    if (!gate.report(progress, y1 == height)) return false;
  }
  return true;
}

}  // namespace radiosity::detail
