#pragma once
// Image: width × height × channels float32, interleaved (pixel-major: all channels of a pixel
// are adjacent), rows top to bottom. Checked access (`at`) for tests and tools; unchecked
// `operator()` and raw spans for hot loops.
#include <cstddef>
#include <span>
#include <vector>

namespace chorus {

class Image {
 public:
  Image() = default;
  Image(int width, int height, int channels, float fill = 0.0f);

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  size_t pixelCount() const { return size_t(width_) * size_t(height_); }
  size_t size() const { return data_.size(); }
  bool empty() const { return data_.empty(); }
  bool sameShape(const Image& other) const {
    return width_ == other.width_ && height_ == other.height_ && channels_ == other.channels_;
  }
  bool sameSize(const Image& other) const {
    return width_ == other.width_ && height_ == other.height_;
  }

  // Unchecked element access.
  float& operator()(int x, int y, int c) { return data_[index(x, y, c)]; }
  float operator()(int x, int y, int c) const { return data_[index(x, y, c)]; }
  // Bounds-checked element access; throws std::out_of_range.
  float& at(int x, int y, int c);
  float at(int x, int y, int c) const;

  float* pixel(int x, int y) { return data_.data() + index(x, y, 0); }
  const float* pixel(int x, int y) const { return data_.data() + index(x, y, 0); }
  float* data() { return data_.data(); }
  const float* data() const { return data_.data(); }
  std::span<float> values() { return data_; }
  std::span<const float> values() const { return data_; }

  void fill(float value);
  // One channel of this image as a 1-channel image.
  Image channel(int c) const;
  // Channels [first, first + count) as a new image.
  Image channelRange(int first, int count) const;
  // Replaces channel c of this image by the only channel of `source` (same size).
  void setChannel(int c, const Image& source);

 private:
  size_t index(int x, int y, int c) const {
    return (size_t(y) * size_t(width_) + size_t(x)) * size_t(channels_) + size_t(c);
  }

  int width_ = 0, height_ = 0, channels_ = 0;
  std::vector<float> data_;
};

}  // namespace chorus
