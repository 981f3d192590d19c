#include "tests/support/gaussian_buffers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

namespace chorus::test {

DenoiseInput gaussianHalves(const Image& truth, const Image& sigma, const SubBuffer& features,
                            uint32_t seed) {
  const int w = truth.width(), h = truth.height();
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  DenoiseInput input;
  input.whole = features;
  input.halves = std::array<SubBuffer, 2>{features, features};
  SubBuffer& a = (*input.halves)[0];
  SubBuffer& b = (*input.halves)[1];
  a.color.mean = b.color.mean = input.whole.color.mean = Image(w, h, 3);
  a.color.varianceOfMean = b.color.varianceOfMean = input.whole.color.varianceOfMean =
      Image(w, h, 3);
  for (size_t k = 0; k < truth.size(); ++k) {
    const float s = sigma.data()[k], halfStd = s * std::sqrt(2.0f);
    const float x1 = truth.data()[k] + halfStd * normal(rng);
    const float x2 = truth.data()[k] + halfStd * normal(rng);
    a.color.mean.data()[k] = x1;
    b.color.mean.data()[k] = x2;
    input.whole.color.mean.data()[k] = 0.5f * (x1 + x2);
    a.color.varianceOfMean.data()[k] = b.color.varianceOfMean.data()[k] = 2.0f * s * s;
    input.whole.color.varianceOfMean.data()[k] = s * s;
  }
  return input;
}

void overstateColorVariances(DenoiseInput& input, float factor) {
  auto scale = [&](SubBuffer& buffer) {
    Image& variance = buffer.color.varianceOfMean;
    for (size_t k = 0; k < variance.size(); ++k) variance.data()[k] *= factor;
  };
  scale(input.whole);
  if (input.halves)
    for (SubBuffer& half : *input.halves) scale(half);
}

TruthAndSigma unrepeatedDetail(int width, int height, float amplitude) {
  TruthAndSigma scene{Image(width, height, 3), Image(width, height, 3)};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) {
        scene.truth(x, y, c) = 0.5f + amplitude * std::sin(0.001f * float(x * 7919 + y * 104729));
        scene.sigma(x, y, c) = 0.02f;
      }
  return scene;
}

OverstatedDetail overstatedDetail(int size, float samples, float factor, uint32_t seed) {
  OverstatedDetail d{unrepeatedDetail(size, size, 0.04f), {}};
  d.input = gaussianHalves(d.scene.truth, d.scene.sigma, flatFeatures(size, size, samples), seed);
  overstateColorVariances(d.input, factor);
  return d;
}

DenoiseInput unequalHalves(int size, float n1, float n2, float sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  DenoiseInput input;
  input.whole = flatFeatures(size, size, n1 + n2);
  input.halves =
      std::array<SubBuffer, 2>{flatFeatures(size, size, n1), flatFeatures(size, size, n2)};
  SubBuffer& a = (*input.halves)[0];
  SubBuffer& b = (*input.halves)[1];
  for (SubBuffer* buffer : {&input.whole, &a, &b}) {
    buffer->color.mean = Image(size, size, 3);
    buffer->color.varianceOfMean = Image(size, size, 3);
  }
  auto recorded = [&](float n) { return n >= 2 ? sigma * sigma / n : 0.0f; };
  for (size_t k = 0; k < input.whole.color.mean.size(); ++k) {
    const float x1 = 0.5f + sigma / std::sqrt(n1) * normal(rng);
    const float x2 = 0.5f + sigma / std::sqrt(n2) * normal(rng);
    a.color.mean.data()[k] = x1;
    b.color.mean.data()[k] = x2;
    input.whole.color.mean.data()[k] = (n1 * x1 + n2 * x2) / (n1 + n2);
    a.color.varianceOfMean.data()[k] = recorded(n1);
    b.color.varianceOfMean.data()[k] = recorded(n2);
    input.whole.color.varianceOfMean.data()[k] = recorded(n1 + n2);
  }
  return input;
}

SubBuffer flatFeatures(int width, int height, float samples) {
  SubBuffer features = SubBuffer::zeros(width, height);
  features.albedo.mean.fill(0.5f);
  for (int i = 0; i < width * height; ++i) features.normal.mean.data()[i * 3 + 2] = 1.0f;
  features.depth.mean.fill(2.0f);
  features.visibility.mean.fill(1.0f);
  features.sampleCount.fill(samples);
  return features;
}

HighlightOnWall highlightOnWall(int x0, int y0) {
  HighlightOnWall scene{x0, y0, Image(64, 64, 3), Image(64, 64, 3)};
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) {
        scene.truth(x, y, c) = scene.inHighlight(x, y) ? 1000.0f : 0.1f;
        scene.sigma(x, y, c) = scene.inHighlight(x, y) ? 500.0f : 0.05f;
      }
  return scene;
}

double HighlightOnWall::wallError(const Image& image, bool near) const {
  double e = 0;
  for (int y = 0; y < truth.height(); ++y)
    for (int x = 0; x < truth.width(); ++x) {
      const int d = std::max({x0 - x, x - (x0 + 2), y0 - y, y - (y0 + 1), 0});
      if (inHighlight(x, y) || (near ? d > 2 : d <= 8)) continue;
      for (int c = 0; c < 3; ++c) e += std::pow(image(x, y, c) - truth(x, y, c), 2.0);
    }
  return e;
}

}  // namespace chorus::test
