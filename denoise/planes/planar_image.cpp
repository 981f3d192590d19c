#include "denoise/planes/planar_image.h"

namespace chorus {

PlanarImage::PlanarImage(const Image& image)
    : PlanarImage(image.width(), image.height(), image.channels()) {
  const float* src = image.data();
  const size_t n = pixelCount();
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < channels_; ++c) data_[size_t(c) * n + i] = src[i * size_t(channels_) + c];
}

Image PlanarImage::toImage() const {
  Image image(width_, height_, channels_);
  float* dst = image.data();
  const size_t n = pixelCount();
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < channels_; ++c) dst[i * size_t(channels_) + c] = data_[size_t(c) * n + i];
  return image;
}

}  // namespace chorus
