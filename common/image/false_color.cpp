#include "common/image/false_color.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace chorus {

namespace {

// Display-referred (sRGB-encoded) stops, evenly spaced on [0, 1].
constexpr std::array<std::array<float, 3>, 5> kStops = {{{0.15f, 0.05f, 0.35f},
                                                         {0.20f, 0.30f, 0.55f},
                                                         {0.15f, 0.55f, 0.55f},
                                                         {0.40f, 0.75f, 0.35f},
                                                         {0.98f, 0.90f, 0.15f}}};

// Inverse of the sRGB curve, so that the PNG writer reproduces the stops exactly.
float srgbToLinear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

}  // namespace

Image falseColor(const Image& image, int channel, float lo, float hi) {
  Image out(image.width(), image.height(), 3);
  const float scale = hi > lo ? 1.0f / (hi - lo) : 0.0f;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const float v = image(x, y, channel);
      if (std::isnan(v)) continue;
      const float t = std::clamp((v - lo) * scale, 0.0f, 1.0f) * float(kStops.size() - 1);
      const size_t i = std::min(size_t(t), kStops.size() - 2);
      const float f = t - float(i);
      for (int c = 0; c < 3; ++c)
        out(x, y, c) = srgbToLinear(kStops[i][size_t(c)] * (1 - f) + kStops[i + 1][size_t(c)] * f);
    }
  return out;
}

}  // namespace chorus
