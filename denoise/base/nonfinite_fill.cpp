#include "denoise/base/nonfinite_fill.h"

#include "denoise/base/filters/neighbourhood_median.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

namespace chorus {

size_t fillNonFiniteColor(SubBuffer& buffer) {
  Image& mean = buffer.color.mean;
  Image& variance = buffer.color.varianceOfMean;
  const int w = mean.width(), h = mean.height();
  size_t filled = 0;
  for (int c = 0; c < 3; ++c) {
    std::vector<size_t> missing;
    for (size_t i = 0; i < mean.pixelCount(); ++i)
      if (!std::isfinite(mean.data()[i * 3 + size_t(c)])) missing.push_back(i);
    filled += missing.size();
    // Rings from the border of each hole inwards: every pass fills the values that have a
    // finite neighbour, from the values known before the pass (independent of the order).
    while (!missing.empty()) {
      std::vector<std::pair<size_t, std::array<float, 2>>> ring;
      std::vector<size_t> rest;
      for (size_t i : missing) {
        const int x = int(i % size_t(w)), y = int(i / size_t(w));
        const std::optional<float> median = neighbourhoodMedian<1>(mean, x, y, c, false);
        if (!median) {
          rest.push_back(i);
          continue;
        }
        int count = 0;
        double varianceSum = 0;
        for (int qy = std::max(0, y - 1); qy <= std::min(h - 1, y + 1); ++qy)
          for (int qx = std::max(0, x - 1); qx <= std::min(w - 1, x + 1); ++qx) {
            if ((qx == x && qy == y) || !std::isfinite(mean(qx, qy, c))) continue;
            ++count;
            const float v = variance(qx, qy, c);
            varianceSum += std::isfinite(v) && v > 0.0f ? double(v) : 0.0;
          }
        ring.push_back({i, {*median, float(varianceSum / count)}});
      }
      if (ring.empty()) {  // no finite value of this channel anywhere
        for (size_t i : rest) mean.data()[i * 3 + size_t(c)] = 0.0f;
        for (size_t i : rest) variance.data()[i * 3 + size_t(c)] = 0.0f;
        break;
      }
      for (const auto& [i, value] : ring) {
        mean.data()[i * 3 + size_t(c)] = value[0];
        variance.data()[i * 3 + size_t(c)] = value[1];
      }
      missing = std::move(rest);
    }
  }
  return filled;
}

}  // namespace chorus
