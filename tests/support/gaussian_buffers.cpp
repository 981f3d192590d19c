#include "tests/support/gaussian_buffers.h"

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

}  // namespace chorus::test
