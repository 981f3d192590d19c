#include "tests/support/denoiser_checks.h"

#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <vector>

namespace chorus::test {

Image runWithThreads(const BaseDenoiser& denoiser, const DenoiseInput& input, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  return denoiser.run(input);
}

std::string firstNonFinite(const Image& image) {
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < image.channels(); ++c)
        if (!std::isfinite(image(x, y, c)))
          return "value " + std::to_string(image(x, y, c)) + " at (" + std::to_string(x) + ", " +
                 std::to_string(y) + ") channel " + std::to_string(c);
  return "";
}

bool bitIdentical(const Image& a, const Image& b) {
  return a.sameShape(b) && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

Image gaussianBlur(const Image& image, float sigma) {
  const int radius = int(std::ceil(3.0f * sigma));
  std::vector<double> taps(size_t(2 * radius + 1));
  for (int i = -radius; i <= radius; ++i)
    taps[size_t(i + radius)] = std::exp(-double(i * i) / (2.0 * sigma * sigma));
  Image out(image.width(), image.height(), image.channels());
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < image.channels(); ++c) {
        double sum = 0, weight = 0;
        for (int dy = -radius; dy <= radius; ++dy)
          for (int dx = -radius; dx <= radius; ++dx) {
            const int qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= image.width() || qy >= image.height()) continue;
            const double w = taps[size_t(dx + radius)] * taps[size_t(dy + radius)];
            sum += w * image(qx, qy, c);
            weight += w;
          }
        out(x, y, c) = float(sum / weight);
      }
  return out;
}

float maxDeviationFrom(const Image& image, const float expected[3]) {
  float worst = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(image(x, y, c) - expected[c]));
  return worst;
}

}  // namespace chorus::test
