#include "denoise/base/input_planes.h"

#include <cmath>

namespace chorus {

PlanarImage sanitizedMean(const MeanVariance& quantity) {
  PlanarImage out(quantity.mean);
  for (int c = 0; c < out.channels(); ++c) {
    float* p = out.plane(c);
    for (size_t i = 0; i < out.pixelCount(); ++i) p[i] = std::isfinite(p[i]) ? p[i] : 0.0f;
  }
  return out;
}

Image clampedFinite(const Image& image) {
  Image out = image;
  for (float& v : out.values()) v = clampedFinite(v);
  return out;
}

PlanarImage sanitizedVarianceOfMean(const Image& varianceOfMean) {
  PlanarImage out(varianceOfMean);
  for (int c = 0; c < out.channels(); ++c) {
    float* p = out.plane(c);
    for (size_t i = 0; i < out.pixelCount(); ++i)
      p[i] = std::isfinite(p[i]) && p[i] > 0.0f ? p[i] : 0.0f;
  }
  return out;
}

PlanarImage perSampleVariance(const MeanVariance& feature, const Image& sampleCount) {
  PlanarImage out(feature.varianceOfMean);
  for (int c = 0; c < out.channels(); ++c) {
    float* p = out.plane(c);
    for (size_t i = 0; i < out.pixelCount(); ++i) {
      const float n = sampleCount.data()[i];
      const float v = p[i] * (n > 0.0f ? n : 1.0f);
      p[i] = std::isfinite(v) ? std::max(v, 0.0f) : kUnknownVariance;
    }
  }
  return out;
}

float maxFiniteDepth(const Image& depth) {
  float maxDepth = 0.0f;
  for (float d : depth.values())
    if (std::isfinite(d)) maxDepth = std::max(maxDepth, d);
  return maxDepth > 0.0f ? maxDepth : 1.0f;
}

}  // namespace chorus
