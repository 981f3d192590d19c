#include "denoise/base/variance_calibration.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "denoise/base/filters/box_filter.h"
#include "denoise/base/variance_estimates.h"
#include "denoise/util/parallel_rows.h"

namespace chorus {

Image colorVarianceCalibration(const DenoiseInput& input, int radius, float maxFactor) {
  if (radius <= 0 || !input.halves) return {};
  const SubBuffer& h1 = (*input.halves)[0];
  const SubBuffer& h2 = (*input.halves)[1];
  const Image& own = input.whole.color.varianceOfMean;
  const int w = input.width(), h = input.height(), channels = own.channels();
  // The two boxes' inputs: the halves' estimate and the recorded variance, both 0 where either
  // is missing, so that the two boxes average over the same pixels.
  // Without recorded counts the halves are taken to hold equal counts (share ¼).
  const bool counted = h1.sampleCount.sameSize(own) && h2.sampleCount.sameSize(own);
  Image spread(w, h, channels), recorded(w, h, channels);
  parallelRows(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const double n1 = counted ? h1.sampleCount(x, y, 0) : 1.0;
      const double n2 = counted ? h2.sampleCount(x, y, 0) : 1.0;
      const double share = n1 > 0 && n2 > 0 ? twoBufferShare(n1, n2, TwoBufferTarget::Whole) : 0.0;
      for (int c = 0; c < channels; ++c) {
        const double d = double(h1.color.mean(x, y, c)) - double(h2.color.mean(x, y, c));
        const float estimate = float(d * d * share), v = own(x, y, c);
        const bool known = share > 0 && std::isfinite(estimate) && std::isfinite(v) && v >= 0;
        spread(x, y, c) = known ? estimate : 0.0f;
        recorded(x, y, c) = known ? v : 0.0f;
      }
    }
  });
  const Image spreadBox = boxFilter(spread, radius), recordedBox = boxFilter(recorded, radius);
  Image factor(w, h, channels);
  parallelChunks(factor.size(), [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      const float f = spreadBox.data()[k] / recordedBox.data()[k];
      factor.data()[k] =
          std::min(recordedBox.data()[k] > 0.0f && std::isfinite(f) ? f : 1.0f, maxFactor);
    }
  });
  return factor;
}

Image calibratedVariance(const Image& variance, const Image& factor) {
  if (factor.empty()) return variance;
  if (!factor.sameShape(variance))
    throw std::invalid_argument("calibratedVariance: the factor's shape differs");
  Image out(variance.width(), variance.height(), variance.channels());
  parallelChunks(out.size(), [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) out.data()[k] = variance.data()[k] * factor.data()[k];
  });
  return out;
}

Image calibratedWholeColorVariance(const DenoiseInput& input, int radius, float maxFactor) {
  const Image factor = colorVarianceCalibration(input, radius, maxFactor);
  if (factor.empty()) return {};
  return calibratedVariance(input.whole.color.varianceOfMean, factor);
}

}  // namespace chorus
