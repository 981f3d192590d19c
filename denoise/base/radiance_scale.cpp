#include "denoise/base/radiance_scale.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "denoise/base/filters/box_filter.h"
#include "denoise/base/variance_estimates.h"

namespace chorus {
namespace {

constexpr float kSaturatedFloat = std::numeric_limits<float>::max();
constexpr float kMinFloat = std::numeric_limits<float>::min();

// The exponent of the least power of two ≥ value / 2^limit (0 when value is within the limit).
int exponentAbove(double value, int limit) {
  if (!(value > std::ldexp(1.0, limit))) return 0;
  int e = 0;
  std::frexp(value, &e);  // value < 2^e
  return e - limit;
}

// The two-buffer estimate (h1 − h2)² / 4 of the whole's variance of the mean (/ 2: a half's)
// as a relative variance: box((h1 − h2)²) / box(m²) · m², m the whole's mean (radius 2).
// Noise that scales with the radiance (path tracing's) keeps the spatial structure of m² and
// does not smear across edges as a box of the variance itself would.
Image relativeTwoBufferVariance(const std::array<SubBuffer, 2>& halves, const Image& mean,
                                bool whole) {
  const Image& a = halves[0].color.mean;
  const Image& b = halves[1].color.mean;
  Image squared(a.width(), a.height(), a.channels()), level = squared;
  for (size_t i = 0; i < squared.size(); ++i) {
    const float d = a.data()[i] - b.data()[i], m = mean.data()[i];
    squared.data()[i] = std::isfinite(d) ? d * d * (whole ? 0.25f : 0.5f) : 0.0f;
    level.data()[i] = std::isfinite(m) ? m * m : 0.0f;
  }
  const Image squaredBox = boxFilter(squared, kVarianceFallbackRadius);
  const Image levelBox = boxFilter(level, kVarianceFallbackRadius);
  Image out(a.width(), a.height(), a.channels());
  for (size_t i = 0; i < out.size(); ++i) {
    const float relative =
        levelBox.data()[i] > 0.0f ? squaredBox.data()[i] / levelBox.data()[i] : 0.0f;
    const float v = level.data()[i] > 0.0f ? relative * level.data()[i] : squaredBox.data()[i];
    out.data()[i] = std::isfinite(v) ? v : 0.0f;
  }
  return out;
}

template <typename Input, typename Fn>
void forEachPart(Input& input, Fn&& fn) {
  fn(input.whole);
  if (input.halves)
    for (auto& half : *input.halves) fn(half);
}

double largestFinite(const Image& image, bool magnitude) {
  double largest = 0;
  for (float v : image.values())
    if (std::isfinite(v)) largest = std::max(largest, magnitude ? std::abs(double(v)) : double(v));
  return largest;
}

}  // namespace

int radianceScaleExponent(const DenoiseInput& input) {
  double largestMean = 0, largestVariance = 0;
  forEachPart(input, [&](const SubBuffer& part) {
    largestMean = std::max(largestMean, largestFinite(part.color.mean, true));
    largestVariance = std::max(largestVariance, largestFinite(part.color.varianceOfMean, false));
  });
  // The variance bounds how far up and requires how far down the image may be scaled.
  const int varianceDown = (exponentAbove(largestVariance, 2 * kMaxRadianceExponent) + 1) / 2;
  const int down = std::max(exponentAbove(largestMean, kMaxRadianceExponent), varianceDown);
  if (down > 0 || !(largestMean > 0) || largestMean >= std::ldexp(1.0, -kMaxRadianceExponent))
    return down;
  int up = 0;
  std::frexp(largestMean, &up);  // largestMean / 2^up in [0.5, 1)
  if (largestVariance > 0) {
    int varianceExponent = 0;
    std::frexp(largestVariance, &varianceExponent);
    up = std::max(up, (varianceExponent - 2 * kMaxRadianceExponent + 1) / 2);
  }
  return std::min(up, 0);
}

void scaleColor(DenoiseInput& input, int exponent) {
  if (exponent == 0) return;
  forEachPart(input, [&](SubBuffer& part) {
    for (float& v : part.color.mean.values()) v = std::ldexp(v, exponent);
  });
  // A variance at FLT_MAX (or +Inf) is saturated: the film clamps there, so it only says "at
  // least this". One below FLT_MIN (0 or subnormal) of a non-zero mean has underflowed (the
  // square of a radiance below ~1e-19). Scaled, either would be far off; where the input has
  // halves, the two-buffer estimate from their scaled means takes its place when larger.
  std::optional<Image> estimates[2];  // for the whole (¼ (h1 − h2)²) and for a half (½ …)
  auto estimate = [&](bool whole) -> const Image* {
    if (!input.halves) return nullptr;
    std::optional<Image>& e = estimates[whole ? 0 : 1];
    if (!e) e = relativeTwoBufferVariance(*input.halves, input.whole.color.mean, whole);
    return &*e;
  };
  auto scaleVariance = [&](Image& variance, const Image& mean, bool whole) {
    const Image* fallback = nullptr;
    for (size_t i = 0; i < variance.size(); ++i) {
      float& v = variance.data()[i];
      const bool saturated = v >= kSaturatedFloat;  // also +Inf; NaN stays NaN
      const bool underflowed = exponent > 0 && v >= 0.0f && v < kMinFloat && mean.data()[i] != 0;
      v = std::ldexp(saturated ? kSaturatedFloat : v, 2 * exponent);
      if (!saturated && !underflowed) continue;
      if (!fallback) fallback = estimate(whole);
      if (fallback && std::isfinite(fallback->data()[i])) v = std::max(v, fallback->data()[i]);
    }
  };
  scaleVariance(input.whole.color.varianceOfMean, input.whole.color.mean, true);
  if (input.halves)
    for (SubBuffer& half : *input.halves)
      scaleVariance(half.color.varianceOfMean, half.color.mean, false);
}

void scaleImage(Image& image, int exponent) {
  if (exponent == 0) return;
  for (float& v : image.values())
    v = std::clamp(std::ldexp(v, exponent), -kSaturatedFloat, kSaturatedFloat);
}

}  // namespace chorus
