#pragma once
// PlanarImage: width × height × channels float32 stored one channel plane after another
// (structure of arrays), so that filters' inner loops stream over contiguous pixels of one
// channel and vectorise. Converts to and from the interleaved Image.
#include <cstddef>
#include <vector>

#include "common/image/image.h"

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
  size_t pixelCount() const { return size_t(width_) * size_t(height_); }

  float* plane(int c) { return data_.data() + size_t(c) * pixelCount(); }
  const float* plane(int c) const { return data_.data() + size_t(c) * pixelCount(); }
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
