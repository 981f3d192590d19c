#include "denoise/base/variance_estimates.h"

#include <array>
#include <cmath>
#include <stdexcept>

#include "denoise/base/filters/box_filter.h"

namespace chorus {
namespace {

// `estimate` where 0 < count < 2, else `variance`.
Image withFallback(const Image& variance, const Image& count, const Image& estimate) {
  Image out = variance;
  if (!count.sameSize(variance)) return out;  // no sample counts recorded: trust the variance
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) {
      const float n = count(x, y, 0);
      if (!(n > 0.0f && n < 2.0f)) continue;
      for (int c = 0; c < out.channels(); ++c) out(x, y, c) = estimate(x, y, c);
    }
  return out;
}

const std::array<SubBuffer, 2>& halvesOf(const DenoiseInput& input) {
  if (!input.halves) throw std::invalid_argument("variance fallback needs two halves");
  return *input.halves;
}

}  // namespace

Image twoBufferVariance(const Image& x1, const Image& x2, float scale) {
  Image sq(x1.width(), x1.height(), x1.channels());
  for (size_t i = 0; i < sq.size(); ++i) {
    const float d = x1.data()[i] - x2.data()[i];
    sq.data()[i] = std::isfinite(d) ? d * d * scale : 0.0f;
  }
  return boxFilter(sq, kVarianceFallbackRadius);
}

Image wholeVarianceOfMean(const DenoiseInput& input, Quantity q) {
  const MeanVariance& whole = input.whole.get(q);
  if (!input.halves) return whole.varianceOfMean;
  const auto& halves = halvesOf(input);
  return withFallback(whole.varianceOfMean, input.whole.sampleCount,
                      twoBufferVariance(halves[0].get(q).mean, halves[1].get(q).mean, 0.25f));
}

Image halfVarianceOfMean(const DenoiseInput& input, int which, Quantity q) {
  const auto& halves = halvesOf(input);
  const SubBuffer& half = halves.at(size_t(which));
  return withFallback(half.get(q).varianceOfMean, half.sampleCount,
                      twoBufferVariance(halves[0].get(q).mean, halves[1].get(q).mean, 0.5f));
}

}  // namespace chorus
