#pragma once
// 0/1 validity masks for the NL-means row kernels (nlmeans_row_kernels.h): the pixels whose
// neighbours exist form a rectangle of the image, so a mask is filled row by row instead of
// testing every pixel.
#include <algorithm>
#include <vector>

#include "denoise/base/filters/pixel_rect.h"

namespace chorus {

// 1 inside `valid`, 0 elsewhere, over the rectangle `area` (row-major).
inline void fillRectMask(const PixelRect& area, const PixelRect& valid, float* mask) {
  const int w = area.width();
  for (int y = area.y0; y < area.y1; ++y) {
    float* row = mask + size_t(y - area.y0) * size_t(w);
    std::fill(row, row + w, 0.0f);
    if (y < valid.y0 || y >= valid.y1) continue;
    const int a = std::clamp(valid.x0 - area.x0, 0, w), b = std::clamp(valid.x1 - area.x0, 0, w);
    std::fill(row + a, row + std::max(a, b), 1.0f);
  }
}

// The mask of `valid` over `area`: `ones` (at least area.area() ones) where `area` lies inside
// `valid` — most tiles and offsets; × 1 changes nothing, not even a NaN — else filled into
// `storage`.
inline const float* rectMaskOrOnes(const PixelRect& area, const PixelRect& valid,
                                   std::vector<float>& storage, const float* ones) {
  if (area.intersect(valid) == area) return ones;
  storage.resize(size_t(area.area()));
  fillRectMask(area, valid, storage.data());
  return storage.data();
}

// values[i] *= mask[i] for i < n, skipped when mask is rectMaskOrOnes' `ones`.
inline void multiplyByMask(float* values, size_t n, const float* mask, const float* ones) {
  if (mask == ones) return;
  for (size_t i = 0; i < n; ++i) values[i] *= mask[i];
}

}  // namespace chorus
