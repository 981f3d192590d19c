#include "tools/sweep/crop_window.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "denoise/metrics/metrics.h"

namespace chorus::sweep {

CropWindow worstWindow(const Image& noisy, const Image& reference, int size) {
  const Image error = relMseMap(noisy, reference);
  const int w = error.width(), h = error.height();
  CropWindow best{0, 0, std::min(size, w), std::min(size, h)};
  // Summed-area table (one row and column of zeros in front), in double.
  std::vector<double> sat(size_t(w + 1) * size_t(h + 1), 0.0);
  auto at = [&](int x, int y) -> double& { return sat[size_t(y) * size_t(w + 1) + size_t(x)]; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float e = error(x, y, 0);
      at(x + 1, y + 1) = (std::isfinite(e) ? e : 0.0) + at(x, y + 1) + at(x + 1, y) - at(x, y);
    }
  double bestSum = -1;
  for (int y = 0; y + best.height <= h; ++y)
    for (int x = 0; x + best.width <= w; ++x) {
      const double sum = at(x + best.width, y + best.height) - at(x, y + best.height) -
                         at(x + best.width, y) + at(x, y);
      if (sum > bestSum) bestSum = sum, best.x = x, best.y = y;
    }
  return best;
}

Image cropImage(const Image& image, const CropWindow& window) {
  Image out(window.width, window.height, image.channels());
  for (int y = 0; y < window.height; ++y)
    std::copy_n(image.pixel(window.x, window.y + y),
                size_t(window.width) * size_t(image.channels()), out.pixel(0, y));
  return out;
}

}  // namespace chorus::sweep
