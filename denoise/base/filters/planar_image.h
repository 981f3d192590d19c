#pragma once
// Channel-planar float images for the filters' inner loops: each channel is one contiguous
// width × height plane, so a row of one channel is contiguous and the loops vectorise.
#include <cstddef>
#include <vector>

#include "denoise/image/image.h"

namespace chorus {

class PlanarImage {
 public:
  PlanarImage() = default;
  PlanarImage(int width, int height, int channels, float fill = 0.0f)
      : width_(width),
        height_(height),
        channels_(channels),
        data_(size_t(width) * size_t(height) * size_t(channels), fill) {}
  explicit PlanarImage(const Image& image);

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  size_t planeSize() const { return size_t(width_) * size_t(height_); }

  float* plane(int c) { return data_.data() + size_t(c) * planeSize(); }
  const float* plane(int c) const { return data_.data() + size_t(c) * planeSize(); }
  float* row(int c, int y) { return plane(c) + size_t(y) * size_t(width_); }
  const float* row(int c, int y) const { return plane(c) + size_t(y) * size_t(width_); }
  float& operator()(int x, int y, int c) { return row(c, y)[x]; }
  float operator()(int x, int y, int c) const { return row(c, y)[x]; }

  Image toImage() const;

 private:
  int width_ = 0, height_ = 0, channels_ = 0;
  std::vector<float> data_;
};

}  // namespace chorus
