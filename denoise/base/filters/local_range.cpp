#include "denoise/base/filters/local_range.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "denoise/util/parallel_rows.h"

namespace chorus {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// lo = min and hi = max over the taps t = −radius … radius of each row value's neighbours
// value + t · step that lie in [0, n) (step 1 along a row's values, `channels` for the pixels
// of a row), t in the outer loop so that the inner one runs over whole rows (vectorised).
void minMaxRow(const float* loIn, const float* hiIn, float* loOut, float* hiOut, ptrdiff_t n,
               int radius, ptrdiff_t step) {
  float* __restrict lo = loOut;
  float* __restrict hi = hiOut;
  std::fill(lo, lo + n, kInf);
  std::fill(hi, hi + n, -kInf);
  for (int t = -radius; t <= radius; ++t) {
    const ptrdiff_t shift = ptrdiff_t(t) * step;
    const float* __restrict l = loIn + shift;
    const float* __restrict h = hiIn + shift;
    for (ptrdiff_t i = std::max(ptrdiff_t(0), -shift); i < std::min(n, n - shift); ++i) {
      lo[i] = std::min(lo[i], l[i]);
      hi[i] = std::max(hi[i], h[i]);
    }
  }
}

// One separable pass of min and max along x (horizontal) or y, in the order of the taps.
void pass(const Image& loIn, const Image& hiIn, Image& loOut, Image& hiOut, int radius,
          bool horizontal) {
  const int h = loIn.height();
  const ptrdiff_t n = ptrdiff_t(loIn.width()) * loIn.channels();
  parallelRows(0, h, [&](int y) {
    const ptrdiff_t at = ptrdiff_t(y) * n;
    float *lo = loOut.data() + at, *hi = hiOut.data() + at;
    if (horizontal) {
      minMaxRow(loIn.data() + at, hiIn.data() + at, lo, hi, n, radius, loIn.channels());
      return;
    }
    // Along y: the rows y − radius … y + radius (clipped) in order, whole rows at a time.
    std::fill(lo, lo + n, kInf);
    std::fill(hi, hi + n, -kInf);
    for (int qy = std::max(0, y - radius); qy <= std::min(h - 1, y + radius); ++qy) {
      const float* __restrict l = loIn.data() + ptrdiff_t(qy) * n;
      const float* __restrict u = hiIn.data() + ptrdiff_t(qy) * n;
      float* __restrict lr = lo;
      float* __restrict hr = hi;
      for (ptrdiff_t i = 0; i < n; ++i) {
        lr[i] = std::min(lr[i], l[i]);
        hr[i] = std::max(hr[i], u[i]);
      }
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
  pass(lo, hi, rows.lo, rows.hi, radius, true);
  pass(rows.lo, rows.hi, lo, hi, radius, false);
  return {std::move(lo), std::move(hi)};
}

}  // namespace chorus
