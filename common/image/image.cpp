#include "common/image/image.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace chorus {

Image::Image(int width, int height, int channels, float fill)
    : width_(width), height_(height), channels_(channels) {
  if (width < 0 || height < 0 || channels < 0)
    throw std::invalid_argument("Image: negative size " + std::to_string(width) + "x" +
                                std::to_string(height) + "x" + std::to_string(channels));
  data_.assign(size_t(width) * size_t(height) * size_t(channels), fill);
}

float& Image::at(int x, int y, int c) {
  if (x < 0 || y < 0 || c < 0 || x >= width_ || y >= height_ || c >= channels_)
    throw std::out_of_range("Image::at(" + std::to_string(x) + ", " + std::to_string(y) + ", " +
                            std::to_string(c) + ") outside " + std::to_string(width_) + "x" +
                            std::to_string(height_) + "x" + std::to_string(channels_));
  return data_[index(x, y, c)];
}

float Image::at(int x, int y, int c) const {
  return const_cast<Image*>(this)->at(x, y, c);
}

void Image::fill(float value) {
  std::fill(data_.begin(), data_.end(), value);
}

Image Image::channel(int c) const {
  return channelRange(c, 1);
}

Image Image::channelRange(int first, int count) const {
  if (first < 0 || count < 0 || first + count > channels_)
    throw std::out_of_range("Image::channelRange outside the image's channels");
  Image out(width_, height_, count);
  for (size_t p = 0; p < pixelCount(); ++p)
    for (int c = 0; c < count; ++c) out.data_[p * count + c] = data_[p * channels_ + first + c];
  return out;
}

void Image::setChannel(int c, const Image& source) {
  if (!sameSize(source) || source.channels() != 1 || c < 0 || c >= channels_)
    throw std::invalid_argument("Image::setChannel: shape mismatch");
  for (size_t p = 0; p < pixelCount(); ++p) data_[p * channels_ + c] = source.data_[p];
}

}  // namespace chorus
