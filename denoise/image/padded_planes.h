#pragma once
// PaddedPlanes: several float planes of one width × height in one allocation, with row and
// plane strides padded for the cache. With plain strides (a width of 1024 floats is 4 KiB),
// the same pixel of every plane and of rows a few apart maps to the same L1 cache set, and a
// filter that reads ~10 planes × 5 rows per tap thrashes L1. Here consecutive rows start one
// cache line apart in set terms, and consecutive planes three lines apart.
#include <cstddef>
#include <vector>

namespace chorus {

class PaddedPlanes {
 public:
  PaddedPlanes() = default;
  PaddedPlanes(int width, int height, int planes, float fill = 0.0f)
      : width_(width),
        height_(height),
        planes_(planes),
        // Row stride ≡ 16 floats (one 64-byte line) mod 1024 floats (4 KiB).
        rowStride_(((size_t(width) + 15) / 16) * 16 + 16),
        // Plane stride ≡ 48 floats (three lines) mod 4 KiB.
        planeStride_(((rowStride_ * size_t(height) + 1023) / 1024) * 1024 + 48),
        data_(planeStride_ * size_t(planes), fill) {}

  int width() const { return width_; }
  int height() const { return height_; }
  int planes() const { return planes_; }
  size_t rowStride() const { return rowStride_; }
  // Offset of pixel (x, y) inside every plane.
  size_t index(int x, int y) const { return size_t(y) * rowStride_ + size_t(x); }

  float* plane(int k) { return data_.data() + size_t(k) * planeStride_; }
  const float* plane(int k) const { return data_.data() + size_t(k) * planeStride_; }

 private:
  int width_ = 0, height_ = 0, planes_ = 0;
  size_t rowStride_ = 0, planeStride_ = 0;
  std::vector<float> data_;
};

}  // namespace chorus
