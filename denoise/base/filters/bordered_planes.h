#pragma once
// Planar float images with a zero border, for the NL-means row kernels (nlmeans_row_kernels.h):
// a kernel may read any neighbour within `pad` pixels of the image without bounds checks.
// Unlike PaddedPlanes (denoise/planes/padded_planes.h: SIMD-aligned rows with horizontal margins
// only, for à-trous), the border surrounds the image on all four sides.
#include <algorithm>
#include <cstddef>
#include <memory>

#include "common/image/image.h"
#include "denoise/util/parallel_rows.h"

namespace chorus {

class BorderedPlanes {
 public:
  BorderedPlanes() = default;
  // Zeroed in parallel (the planes run to hundreds of megabytes, set up between parallel loops).
  BorderedPlanes(int width, int height, int channels, int pad)
      : pad_(pad),
        stride_(size_t(width + 2 * pad)),
        planeSize_(stride_ * size_t(height + 2 * pad)),
        data_(new float[planeSize_ * size_t(channels)]) {
    float* values = data_.get();
    parallelChunks(planeSize_ * size_t(channels), [&](size_t begin, size_t end) {
      std::fill(values + begin, values + end, 0.0f);
    });
  }
  // Channel c of this ← channel sourceChannel of image × scale (rows in parallel: the filters
  // set up dozens of planes before their parallel loops).
  void set(int c, const Image& image, int sourceChannel, float scale = 1.0f) {
    parallelRows(0, image.height(), [&](int y) {
      float* row = mutableRow(c, y);
      for (int x = 0; x < image.width(); ++x) row[x] = scale * image(x, y, sourceChannel);
    });
  }
  float* mutableRow(int c, int y) {
    return data_.get() + size_t(c) * planeSize_ + size_t(y + pad_) * stride_ + size_t(pad_);
  }
  // Floats from a pixel of channel c to the same pixel of channel c + 1.
  size_t planeStride() const { return planeSize_; }
  // Pointer to pixel (0, y) of channel c; valid for x, y within `pad` of the image.
  const float* row(int c, int y) const {
    return data_.get() + size_t(c) * planeSize_ + size_t(y + pad_) * stride_ + size_t(pad_);
  }

 private:
  int pad_ = 0;
  size_t stride_ = 0, planeSize_ = 0;
  std::unique_ptr<float[]> data_;
};

// Offsets o ∈ [−r, r] along one axis with x + o in [lo, hi): a box's true pixel count.
inline int boxOverlap(int x, int r, int lo, int hi) {
  return std::max(0, std::min(x + r + 1, hi) - std::max(x - r, lo));
}

}  // namespace chorus
