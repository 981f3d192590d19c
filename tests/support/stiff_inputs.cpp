#include "tests/support/stiff_inputs.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <utility>

namespace chorus::test {
namespace {

constexpr double kMaxFloat = std::numeric_limits<float>::max();

}  // namespace

void addColorSample(SubBuffer& sub, int x, int y, const double value[3]) {
  const double n = sub.sampleCount(x, y, 0), n1 = n + 1;
  for (int c = 0; c < 3; ++c) {
    const double mean = sub.color.mean(x, y, c);
    const double m2 = double(sub.color.varianceOfMean(x, y, c)) * n * (n - 1);
    const double delta = value[c] - mean;
    const double newMean = mean + delta / n1;
    const double newM2 = m2 + delta * (value[c] - newMean);
    sub.color.mean(x, y, c) = float(std::min(newMean, kMaxFloat));
    sub.color.varianceOfMean(x, y, c) = float(std::min(newM2 / (n1 * n), kMaxFloat));
  }
  sub.sampleCount(x, y, 0) = float(n1);
}

SampleBuffers withFireflies(const SampleBuffers& buffers, int k, int count, double factor,
                            uint32_t seed) {
  SampleBuffers out = buffers;
  SubBuffer& sub = out.sub(k);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> px(0, sub.width() - 1), py(0, sub.height() - 1);
  std::set<std::pair<int, int>> used;
  while (int(used.size()) < std::min(count, sub.width() * sub.height())) {
    const int x = px(rng), y = py(rng);
    if (!used.insert({x, y}).second) continue;
    const double luminance = 0.2126 * sub.color.mean(x, y, 0) + 0.7152 * sub.color.mean(x, y, 1) +
                             0.0722 * sub.color.mean(x, y, 2);
    const double v = std::min(factor * std::max(luminance, 1e-3), kMaxFloat);
    const double value[3] = {v, v, v};
    addColorSample(sub, x, y, value);
  }
  return out;
}

Image bandScales(int width, int height, const std::vector<double>& scales) {
  Image out(width, height, 1);
  const int bands = int(scales.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      out(x, y, 0) = float(scales[size_t(std::min(bands - 1, x * bands / width))]);
  return out;
}

SampleBuffers scaledColor(const SampleBuffers& buffers, const Image& scale) {
  SampleBuffers out = buffers;
  for (int k = 0; k < out.splitCount(); ++k) {
    SubBuffer& sub = out.sub(k);
    for (int y = 0; y < sub.height(); ++y)
      for (int x = 0; x < sub.width(); ++x) {
        const double s = scale(x, y, 0);
        for (int c = 0; c < 3; ++c) {
          sub.color.mean(x, y, c) = float(sub.color.mean(x, y, c) * s);
          sub.color.varianceOfMean(x, y, c) =
              float(std::min(double(sub.color.varianceOfMean(x, y, c)) * s * s, kMaxFloat));
        }
      }
  }
  return out;
}

Image scaledImage(const Image& image, const Image& scale) {
  Image out = image;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < image.channels(); ++c)
        out(x, y, c) = float(double(image(x, y, c)) * scale(x, y, 0));
  return out;
}

SampleBuffers withNanRect(const SampleBuffers& buffers, int x0, int y0, int x1, int y1) {
  SampleBuffers out = buffers;
  for (int k = 0; k < out.splitCount(); ++k)
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x)
        for (int c = 0; c < 3; ++c)
          out.sub(k).color.mean(x, y, c) = std::numeric_limits<float>::quiet_NaN();
  return out;
}

Image outsideRect(int width, int height, int x0, int y0, int x1, int y1) {
  Image out(width, height, 1, 1.0f);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) out(x, y, 0) = 0.0f;
  return out;
}

}  // namespace chorus::test
