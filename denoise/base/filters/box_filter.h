#pragma once
// Box filter that averages over the pixels that exist: at a border the (2r+1)² box is clipped
// to the buffer and the sum is divided by the true count in both axes (separable: a row pass,
// then a column pass). Small radii sum the taps directly (exact, vectorised, the same result
// for a pixel whatever rectangle it is computed in); larger radii use double-precision running
// sums.
#include <vector>

#include "common/image/image.h"
#include "denoise/base/filters/pixel_rect.h"

namespace chorus {

// dst = box(src) over a width × height plane (row-major, contiguous rows). src and dst may be
// the same buffer. `tmp` is scratch, resized as needed.
void boxFilterPlane(const float* src, float* dst, int width, int height, int radius,
                    std::vector<float>& tmp);

// The box filter of a width × height plane evaluated only on `crop` (a rectangle inside the
// plane, in its coordinates), written as a crop.width() × crop.height() plane to dst; the
// clipping and counts are those of the whole plane. dst must not overlap src.
void boxFilterCrop(const float* src, int width, int height, int radius, const PixelRect& crop,
                   float* dst, std::vector<float>& tmp);

// The direct-tap kernels, shared with the fused NL-means weights (nlmeans_weights.cpp), which
// must sum in the same order to give bit-identical results.
namespace box_kernels {
// Radii up to this sum their taps directly; beyond, running sums are cheaper.
inline constexpr int kMaxDirectRadius = 4;
inline int roundUp4(int n) {
  return (n + 3) / 4 * 4;
}
// out[x] = invCount[x] · Σ_{j=0}^{2r} padded[x + j] for x < n, taps in ascending order; padded
// holds the row between r zeros; out and invCount have room for roundUp4(n) values.
void rowSums(const float* padded, float* out, int n, int r, const float* invCount);
// out[x] = inv · Σ_{j < count} rows[j][x] for x < n, rows in order (count ≤ 2 kMaxDirectRadius +
// 1).
void columnSums(const float* const* rows, int count, float inv, float* out, int n);
}  // namespace box_kernels

// Every channel of `image` box-filtered with the given radius.
Image boxFilter(const Image& image, int radius);

}  // namespace chorus
