#pragma once
// The median of one channel over a small square neighbourhood, for the steps that judge a pixel
// by its neighbours (nonfinite_fill.cpp, guarded_denoiser.cpp).
#include <algorithm>
#include <cmath>
#include <optional>

#include "common/image/image.h"

namespace chorus {

// The median of channel c of `image` over the (2 kRadius + 1)^2 neighbourhood of (x, y) clipped
// to the image, the pixel itself left out if `withCentre` is false, non-finite values always;
// with an even count the upper of the two middle values. Empty if no value is left.
template <int kRadius>
std::optional<float> neighbourhoodMedian(const Image& image, int x, int y, int c,
                                         bool withCentre = true) {
  float window[(2 * kRadius + 1) * (2 * kRadius + 1)];
  int n = 0;
  for (int ny = std::max(0, y - kRadius); ny <= std::min(image.height() - 1, y + kRadius); ++ny)
    for (int nx = std::max(0, x - kRadius); nx <= std::min(image.width() - 1, x + kRadius); ++nx) {
      const float v = image(nx, ny, c);
      if (std::isfinite(v) && (withCentre || nx != x || ny != y)) window[n++] = v;
    }
  if (n == 0) return std::nullopt;
  std::nth_element(window, window + n / 2, window + n);
  return window[n / 2];
}

}  // namespace chorus
