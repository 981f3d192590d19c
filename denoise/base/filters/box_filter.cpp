#include "denoise/base/filters/box_filter.h"

#include <algorithm>

#include "denoise/planes/planar_image.h"
#include "denoise/util/parallel_rows.h"
#include "denoise/util/simd_clones.h"

// The row and column kernels are built for AVX-512F, AVX2 and the baseline (simd_clones.h),
// without contraction into FMA, so that every build sums the same way (and the fused NL-means
// weights, which share them, stay bit-identical to the general path). After the includes: GCC
// does not inline across different optimisation options.
#pragma GCC optimize("fp-contract=off")

namespace chorus {
namespace {

using box_kernels::kMaxDirectRadius;
using box_kernels::roundUp4;

// 1 / (true count) of the clipped box along an axis of length n, padded to a multiple of 4.
void inverseCounts(int n, int r, std::vector<float>& inv) {
  inv.assign(size_t(roundUp4(n)), 0.0f);
  for (int x = 0; x < n; ++x)
    inv[size_t(x)] = 1.0f / float(std::min(n - 1, x + r) - std::max(0, x - r) + 1);
}

// Sums of 2R + 1 taps for one row: `padded` holds the row between R zeros on either side (adding
// the zeros is exact, so clipped and interior pixels sum their taps the same way, in ascending
// order); out[x] = sum · invCount[x]. Plain loops: the vectoriser turns them into one pixel per
// lane (the same sums in the same order at any vector width).
template <int R>
[[gnu::always_inline]] inline void boxRowDirect(const float* __restrict padded,
                                                float* __restrict out, int n,
                                                const float* __restrict invCount) {
  for (int x = 0; x < n; ++x) {
    float acc = padded[x];
    for (int j = 1; j <= 2 * R; ++j) acc += padded[x + j];
    out[x] = acc * invCount[x];
  }
}

// out[x] = inv · Σ_{j < N} rows[j][x] for x < n, rows in order.
template <int N>
[[gnu::always_inline]] inline void columnSum(const float* const* rows, float inv,
                                             float* __restrict out, int n) {
  const float* __restrict r[N];
  for (int j = 0; j < N; ++j) r[j] = rows[j];
  for (int x = 0; x < n; ++x) {
    float acc = r[0][x];
    for (int j = 1; j < N; ++j) acc += r[j][x];
    out[x] = acc * inv;
  }
}

[[gnu::always_inline]] inline void columnSumAny(const float* const* rows, int n, float inv,
                                                float* out, int width) {
  switch (n) {
    case 1:
      return columnSum<1>(rows, inv, out, width);
    case 2:
      return columnSum<2>(rows, inv, out, width);
    case 3:
      return columnSum<3>(rows, inv, out, width);
    case 4:
      return columnSum<4>(rows, inv, out, width);
    case 5:
      return columnSum<5>(rows, inv, out, width);
    case 6:
      return columnSum<6>(rows, inv, out, width);
    case 7:
      return columnSum<7>(rows, inv, out, width);
    case 8:
      return columnSum<8>(rows, inv, out, width);
    default:
      return columnSum<9>(rows, inv, out, width);
  }
}

[[gnu::always_inline]] inline void boxRowAny(const float* padded, float* out, int n, int r,
                                             const float* invCount) {
  switch (r) {
    case 1:
      return boxRowDirect<1>(padded, out, n, invCount);
    case 2:
      return boxRowDirect<2>(padded, out, n, invCount);
    case 3:
      return boxRowDirect<3>(padded, out, n, invCount);
    default:
      return boxRowDirect<4>(padded, out, n, invCount);
  }
}

// Small radii: direct taps, exact and independent of where the plane starts. Computes the crop
// only: the row pass covers the crop's columns on every row the column pass reads.
void boxFilterDirect(const float* src, int width, int height, int radius, const PixelRect& crop,
                     float* dst, std::vector<float>& tmp) {
  const int cw = crop.width();
  const int rowBegin = std::max(0, crop.y0 - radius), rowEnd = std::min(height, crop.y1 + radius);
  // The columns the row pass reads, with zeros where they fall outside the plane.
  const int readBegin = crop.x0 - radius, readWidth = cw + 2 * radius;
  const size_t stride = size_t(roundUp4(cw));
  const size_t paddedSize = size_t(roundUp4(readWidth) + 4);
  thread_local std::vector<float> invX, invY;
  invX.assign(stride, 0.0f);
  for (int x = 0; x < cw; ++x) {
    const int px = crop.x0 + x;
    invX[size_t(x)] = 1.0f / float(std::min(width - 1, px + radius) - std::max(0, px - radius) + 1);
  }
  inverseCounts(height, radius, invY);
  tmp.resize(stride * size_t(rowEnd - rowBegin) + paddedSize);
  float* padded = tmp.data() + stride * size_t(rowEnd - rowBegin);
  std::fill(padded, padded + paddedSize, 0.0f);
  const int copyBegin = std::max(0, readBegin), copyEnd = std::min(width, readBegin + readWidth);
  for (int y = rowBegin; y < rowEnd; ++y) {
    const float* row = src + size_t(y) * size_t(width);
    std::copy(row + copyBegin, row + copyEnd, padded + (copyBegin - readBegin));
    box_kernels::rowSums(padded, tmp.data() + size_t(y - rowBegin) * stride, cw, radius,
                         invX.data());
  }
  // Column pass: each output row is the mean of the clipped run of row means.
  const float* rows[2 * kMaxDirectRadius + 1];
  for (int y = crop.y0; y < crop.y1; ++y) {
    const int a = std::max(0, y - radius), b = std::min(height - 1, y + radius);
    for (int j = a; j <= b; ++j) rows[j - a] = tmp.data() + size_t(j - rowBegin) * stride;
    box_kernels::columnSums(rows, b - a + 1, invY[size_t(y)],
                            dst + size_t(y - crop.y0) * size_t(cw), cw);
  }
}

// Large radii: running sums in double precision (no drift over long rows).
void boxFilterRunning(const float* src, float* dst, int width, int height, int radius,
                      std::vector<float>& tmp) {
  const size_t w = size_t(width);
  tmp.resize(w * size_t(height));
  for (int y = 0; y < height; ++y) {
    const float* in = src + size_t(y) * w;
    float* out = tmp.data() + size_t(y) * w;
    double s = 0.0;
    for (int j = 0; j < std::min(radius, width); ++j) s += in[j];
    for (int x = 0; x < width; ++x) {
      if (x + radius < width) s += in[x + radius];
      const int a = std::max(0, x - radius), b = std::min(width - 1, x + radius);
      out[x] = float(s / double(b - a + 1));
      if (x - radius >= 0) s -= in[x - radius];
    }
  }
  std::vector<double> sums(w, 0.0);
  for (int j = 0; j < std::min(radius, height); ++j)
    for (size_t x = 0; x < w; ++x) sums[x] += tmp[size_t(j) * w + x];
  for (int y = 0; y < height; ++y) {
    if (y + radius < height)
      for (size_t x = 0; x < w; ++x) sums[x] += tmp[size_t(y + radius) * w + x];
    const int a = std::max(0, y - radius), b = std::min(height - 1, y + radius);
    const double inv = 1.0 / double(b - a + 1);
    for (size_t x = 0; x < w; ++x) dst[size_t(y) * w + x] = float(sums[x] * inv);
    if (y - radius >= 0)
      for (size_t x = 0; x < w; ++x) sums[x] -= tmp[size_t(y - radius) * w + x];
  }
}

}  // namespace

namespace box_kernels {

CHORUS_SIMD_CLONES void rowSums(const float* padded, float* out, int n, int r,
                                const float* invCount) {
  boxRowAny(padded, out, n, r, invCount);
}

CHORUS_SIMD_CLONES void columnSums(const float* const* rows, int count, float inv, float* out,
                                   int n) {
  columnSumAny(rows, count, inv, out, n);
}

}  // namespace box_kernels

void boxFilterCrop(const float* src, int width, int height, int radius, const PixelRect& crop,
                   float* dst, std::vector<float>& tmp) {
  if (crop.empty()) return;
  if (radius <= 0) {
    for (int y = crop.y0; y < crop.y1; ++y)
      std::copy(src + size_t(y) * size_t(width) + size_t(crop.x0),
                src + size_t(y) * size_t(width) + size_t(crop.x1),
                dst + size_t(y - crop.y0) * size_t(crop.width()));
    return;
  }
  if (radius <= kMaxDirectRadius) {
    boxFilterDirect(src, width, height, radius, crop, dst, tmp);
    return;
  }
  std::vector<float> whole(size_t(width) * size_t(height));
  boxFilterRunning(src, whole.data(), width, height, radius, tmp);
  for (int y = crop.y0; y < crop.y1; ++y)
    std::copy(whole.data() + size_t(y) * size_t(width) + size_t(crop.x0),
              whole.data() + size_t(y) * size_t(width) + size_t(crop.x1),
              dst + size_t(y - crop.y0) * size_t(crop.width()));
}

void boxFilterPlane(const float* src, float* dst, int width, int height, int radius,
                    std::vector<float>& tmp) {
  if (width <= 0 || height <= 0) return;
  if (radius <= 0) {
    if (dst != src) std::copy(src, src + size_t(width) * size_t(height), dst);
    return;
  }
  if (radius <= kMaxDirectRadius) {
    // The row pass goes to tmp before the column pass writes dst, so src may be dst.
    boxFilterDirect(src, width, height, radius, PixelRect::image(width, height), dst, tmp);
    return;
  }
  boxFilterRunning(src, dst, width, height, radius, tmp);
}

Image boxFilter(const Image& image, int radius) {
  PlanarImage planes(image);
  // The channels side by side (each plane is filtered alone, so the results do not change).
  parallelRows(0, planes.channels(), [&](int c) {
    std::vector<float> tmp;
    boxFilterPlane(planes.plane(c), planes.plane(c), planes.width(), planes.height(), radius, tmp);
  });
  return planes.toImage();
}

}  // namespace chorus
