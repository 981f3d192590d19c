#pragma once
// PaddedPlanes: several float planes of one width × height in one allocation, with row and
// plane strides padded for the cache. With plain strides (a width of 1024 floats is 4 KiB),
// the same pixel of every plane and of rows a few apart maps to the same L1 cache set, and a
// filter that reads ~10 planes × 5 rows per tap thrashes L1. Here consecutive rows start one
// cache line apart in set terms, and consecutive planes three lines apart. An optional margin
// of zero columns on each side lets filters read a few pixels past the left and right borders
// (index(x, y) is valid for x ∈ [−margin, width + margin)). Pixels start uninitialised: the
// owner writes every pixel before reading it.
#include <algorithm>
#include <cstddef>
#include <memory>

namespace chorus {

class PaddedPlanes {
 public:
  PaddedPlanes() = default;
  PaddedPlanes(int width, int height, int planes, int margin = 0)
      : width_(width),
        height_(height),
        planes_(planes),
        margin_(margin),
        // Row stride ≡ 16 floats (one 64-byte line) mod 1024 floats (4 KiB).
        rowStride_(((size_t(width) + 2 * size_t(margin) + 15) / 16) * 16 + 16),
        // Plane stride ≡ 48 floats (three lines) mod 4 KiB.
        planeStride_(((rowStride_ * size_t(height) + 1023) / 1024) * 1024 + 48),
        data_(new float[planeStride_ * size_t(planes)]) {
    // Only the margins must read as zero; the pixels are the owner's to write (not zeroing
    // them saves a pass over memory), the alignment padding is never read.
    for (int k = 0; k < planes; ++k)
      for (int y = 0; y < height; ++y) {
        float* row = plane(k) + size_t(y) * rowStride_;
        std::fill(row, row + margin, 0.0f);
        std::fill(row + margin + width, row + 2 * margin + width, 0.0f);
      }
  }
  PaddedPlanes(PaddedPlanes&&) noexcept = default;
  PaddedPlanes& operator=(PaddedPlanes&&) noexcept = default;

  int width() const { return width_; }
  int height() const { return height_; }
  int planes() const { return planes_; }
  int margin() const { return margin_; }
  size_t rowStride() const { return rowStride_; }
  // Offset of pixel (x, y) inside every plane.
  size_t index(int x, int y) const {
    return size_t(y) * rowStride_ + size_t(margin_) + size_t(ptrdiff_t(x));
  }

  float* plane(int k) { return data_.get() + size_t(k) * planeStride_; }
  const float* plane(int k) const { return data_.get() + size_t(k) * planeStride_; }

 private:
  int width_ = 0, height_ = 0, planes_ = 0, margin_ = 0;
  size_t rowStride_ = 0, planeStride_ = 0;
  std::unique_ptr<float[]> data_;
};

}  // namespace chorus
