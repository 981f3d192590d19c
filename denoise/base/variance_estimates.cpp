#include "denoise/base/variance_estimates.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "denoise/base/filters/box_filter.h"
#include "denoise/util/parallel_rows.h"

namespace chorus {
namespace {

bool oneSample(float n) {
  return n > 0.0f && n < 2.0f;
}

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

double twoBufferShare(double n1, double n2, TwoBufferTarget target) {
  switch (target) {
    case TwoBufferTarget::Whole:
      return n1 * n2 / ((n1 + n2) * (n1 + n2));
    case TwoBufferTarget::FirstHalf:
      return n2 / (n1 + n2);
    case TwoBufferTarget::SecondHalf:
      return n1 / (n1 + n2);
  }
  return 0.0;
}

Image twoBufferVariance(const SubBuffer& h1, const SubBuffer& h2, Quantity q,
                        TwoBufferTarget target) {
  const Image& x1 = h1.get(q).mean;
  const Image& x2 = h2.get(q).mean;
  const bool counted = h1.sampleCount.sameSize(x1) && h2.sampleCount.sameSize(x1);
  const int channels = x1.channels();
  Image sq(x1.width(), x1.height(), channels);
  for (int y = 0; y < sq.height(); ++y)
    for (int x = 0; x < sq.width(); ++x) {
      // Equal counts where none are recorded, and where a half has no sample (a 1-spp render:
      // a rough estimate from the one mean there is still better than a variance of 0).
      const bool known = counted && h1.sampleCount(x, y, 0) > 0 && h2.sampleCount(x, y, 0) > 0;
      const double n1 = known ? h1.sampleCount(x, y, 0) : 1.0;
      const double n2 = known ? h2.sampleCount(x, y, 0) : 1.0;
      const double share = twoBufferShare(n1, n2, target);
      for (int c = 0; c < channels; ++c) {
        const float d = x1(x, y, c) - x2(x, y, c);
        sq(x, y, c) = std::isfinite(d) ? float(double(d) * double(d) * share) : 0.0f;
      }
    }
  return boxFilter(sq, kVarianceFallbackRadius);
}

Image wholeVarianceOfMean(const DenoiseInput& input, Quantity q) {
  const MeanVariance& whole = input.whole.get(q);
  if (!input.halves) return whole.varianceOfMean;
  const auto& halves = halvesOf(input);
  return withFallback(whole.varianceOfMean, input.whole.sampleCount,
                      twoBufferVariance(halves[0], halves[1], q, TwoBufferTarget::Whole));
}

Image halfVarianceOfMean(const DenoiseInput& input, int which, Quantity q) {
  const auto& halves = halvesOf(input);
  const SubBuffer& half = halves.at(size_t(which));
  const TwoBufferTarget target =
      which == 0 ? TwoBufferTarget::FirstHalf : TwoBufferTarget::SecondHalf;
  return withFallback(half.get(q).varianceOfMean, half.sampleCount,
                      twoBufferVariance(halves[0], halves[1], q, target));
}

bool hasOneSamplePixels(const SubBuffer& buffer) {
  const Image& count = buffer.sampleCount;
  return count.sameSize(buffer.color.mean) &&
         std::any_of(count.values().begin(), count.values().end(), oneSample);
}

Image spatialVarianceWhereOneSample(const SubBuffer& buffer, Quantity q, const Image& variance) {
  const Image& mean = buffer.get(q).mean;
  const Image& count = buffer.sampleCount;
  if (!hasOneSamplePixels(buffer)) return variance;
  const int w = mean.width(), h = mean.height(), r = kSpatialVarianceRadius;
  constexpr int kTaps = (2 * kSpatialVarianceRadius + 1) * (2 * kSpatialVarianceRadius + 1);
  constexpr double kMadToSigma = 1.4826;  // σ of a normal distribution per median |deviation|
  Image spread(w, h, mean.channels());
  parallelRows(0, h, [&](int y) {
    std::array<float, kTaps> values;
    for (int x = 0; x < w; ++x) {
      const float n = count(x, y, 0);
      if (!oneSample(n)) continue;  // withFallback keeps `variance` there
      for (int c = 0; c < mean.channels(); ++c) {
        int taken = 0;
        for (int qy = std::max(0, y - r); qy <= std::min(h - 1, y + r); ++qy)
          for (int qx = std::max(0, x - r); qx <= std::min(w - 1, x + r); ++qx) {
            const float v = mean(qx, qy, c);
            if (count(qx, qy, 0) > 0.0f && std::isfinite(v)) values[size_t(taken++)] = v;
          }
        if (taken < 2) {
          spread(x, y, c) = 0.0f;
          continue;
        }
        float* const first = values.data();
        float* const middle = first + taken / 2;
        std::nth_element(first, middle, first + taken);
        const float median = *middle;
        for (int i = 0; i < taken; ++i) values[size_t(i)] = std::abs(values[size_t(i)] - median);
        std::nth_element(first, middle, first + taken);
        const double sigma = kMadToSigma * double(*middle);
        spread(x, y, c) =
            float(std::min(sigma * sigma / n, double(std::numeric_limits<float>::max())));
      }
    }
  });
  return withFallback(variance, count, spread);
}

}  // namespace chorus
