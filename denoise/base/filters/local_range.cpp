#include "denoise/base/filters/local_range.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "denoise/util/parallel_rows.h"

namespace chorus {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// lo[i] = min(lo[i], l[i]) and hi[i] = max(hi[i], u[i]) for i in [begin, end) (vectorised).
void takeMinMax(float* __restrict lo, float* __restrict hi, const float* __restrict l,
                const float* __restrict u, ptrdiff_t begin, ptrdiff_t end) {
  for (ptrdiff_t i = begin; i < end; ++i) {
    lo[i] = std::min(lo[i], l[i]);
    hi[i] = std::max(hi[i], u[i]);
  }
}

// One separable pass of min and max along x (horizontal) or y, in the order of the taps, each
// tap over a whole row at a time: along x the row's values shifted by t · channels (the taps
// that lie in the row), along y the rows y − radius … y + radius that lie in the image.
void pass(const Image& loIn, const Image& hiIn, Image& loOut, Image& hiOut, int radius,
          bool horizontal) {
  const int h = loIn.height();
  const ptrdiff_t n = ptrdiff_t(loIn.width()) * loIn.channels();
  parallelRows(0, h, [&](int y) {
    const ptrdiff_t at = ptrdiff_t(y) * n;
    float *lo = loOut.data() + at, *hi = hiOut.data() + at;
    std::fill(lo, lo + n, kInf);
    std::fill(hi, hi + n, -kInf);
    if (horizontal) {
      for (int t = -radius; t <= radius; ++t) {
        const ptrdiff_t shift = ptrdiff_t(t) * loIn.channels();
        takeMinMax(lo, hi, loIn.data() + at + shift, hiIn.data() + at + shift,
                   std::max(ptrdiff_t(0), -shift), std::min(n, n - shift));
      }
      return;
    }
    for (int qy = std::max(0, y - radius); qy <= std::min(h - 1, y + radius); ++qy)
      takeMinMax(lo, hi, loIn.data() + ptrdiff_t(qy) * n, hiIn.data() + ptrdiff_t(qy) * n, 0, n);
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
