#include "denoise/base/filters/local_range.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "denoise/util/parallel_rows.h"

namespace chorus {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// One separable pass of min and max along x (sx = 1) or y (sy = 1).
void pass(const Image& loIn, const Image& hiIn, Image& loOut, Image& hiOut, int radius, int sx,
          int sy) {
  const int w = loIn.width(), h = loIn.height(), channels = loIn.channels();
  parallelRows(0, h, [&](int y) {
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) {
        float lo = kInf, hi = -kInf;
        for (int t = -radius; t <= radius; ++t) {
          const int qx = x + t * sx, qy = y + t * sy;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          lo = std::min(lo, loIn(qx, qy, c));
          hi = std::max(hi, hiIn(qx, qy, c));
        }
        loOut(x, y, c) = lo;
        hiOut(x, y, c) = hi;
      }
  });
}

}  // namespace

LocalRange localRange(const Image& image, int radius) {
  Image lo = image, hi = image;
  for (size_t i = 0; i < image.size(); ++i)
    if (!std::isfinite(image.data()[i])) {
      lo.data()[i] = kInf;
      hi.data()[i] = -kInf;
    }
  LocalRange rows{Image(image.width(), image.height(), image.channels()),
                  Image(image.width(), image.height(), image.channels())};
  pass(lo, hi, rows.lo, rows.hi, radius, 1, 0);
  pass(rows.lo, rows.hi, lo, hi, radius, 0, 1);
  return {std::move(lo), std::move(hi)};
}

}  // namespace chorus
