#include "common/image/tonemap.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace chorus {

Tonemapper parseTonemapper(const std::string& name) {
  if (name == "clamp") return Tonemapper::Clamp;
  if (name == "reinhard") return Tonemapper::Reinhard;
  if (name == "aces") return Tonemapper::AcesFit;
  throw Error("unknown tonemapper '" + name + "' (known: clamp, reinhard, aces)");
}

float tonemap(float linear, const DisplayOptions& options) {
  float v = linear * std::exp2(options.exposureStops);
  if (!(v > 0.0f)) return 0.0f;  // negatives and NaN
  switch (options.tonemapper) {
    case Tonemapper::Clamp:
      break;
    case Tonemapper::Reinhard:
      v = std::isinf(v) ? 1.0f : v / (1.0f + v);
      break;
    case Tonemapper::AcesFit:
      v = std::isinf(v) ? 1.0f : (v * (2.51f * v + 0.03f)) / (v * (2.43f * v + 0.59f) + 0.14f);
      break;
  }
  return std::clamp(v, 0.0f, 1.0f);
}

float linearToSrgb(float linear) {
  const float v = std::clamp(linear, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

uint8_t toDisplayByte(float linear, const DisplayOptions& options) {
  return uint8_t(std::lround(255.0f * linearToSrgb(tonemap(linear, options))));
}

}  // namespace chorus
