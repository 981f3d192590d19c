// The two-buffer fallback of denoise/base/variance_estimates.h: where a buffer has one sample
// its variance of the mean comes from the halves' squared difference, weighted by their counts.
// A held-out input at 4 spp has halves of one and two quarters (one and two samples).
#include "denoise/base/variance_estimates.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/denoiser_checks.h"
#include "tests/support/gaussian_buffers.h"

namespace chorus {
namespace {

constexpr int kSize = 64;
constexpr float kSigma = 0.2f;  // per-sample standard deviation

DenoiseInput halvesOf(float n1, float n2, unsigned seed) {
  return test::unequalHalves(kSize, n1, n2, kSigma, seed);
}

double meanOf(const Image& image) {
  double sum = 0;
  for (size_t k = 0; k < image.size(); ++k) sum += image.data()[k];
  return sum / double(image.size());
}

// The one-sample half's fallback against its true variance σ²: E[(x1 − x2)²] = σ² (1 + ½), so
// the share n2 / (n1 + n2) = ⅔ gives σ²; the equal-count ½ gave ¾ σ². Seeds average the noise of
// 12 288 squared differences (their mean's standard error ≈ 1.3 % per seed).
TEST(VarianceEstimates, OneSampleHalfBesideTwoSamplesIsUnbiased) {
  double first = 0, second = 0;
  constexpr int kSeeds = 4;
  for (unsigned seed = 1; seed <= kSeeds; ++seed) {
    const DenoiseInput input = halvesOf(1, 2, seed);
    first += meanOf(halfVarianceOfMean(input, 0, Quantity::Color)) / (kSigma * kSigma) / kSeeds;
    // The same with the halves swapped: the second half is the one-sample one.
    const DenoiseInput swapped = halvesOf(2, 1, seed + 100);
    second += meanOf(halfVarianceOfMean(swapped, 1, Quantity::Color)) / (kSigma * kSigma) / kSeeds;
  }
  EXPECT_NEAR(first, 1.0, 0.04);
  EXPECT_NEAR(second, 1.0, 0.04);
}

TEST(VarianceEstimates, BuffersWithTheirOwnEstimateKeepIt) {
  const DenoiseInput input = halvesOf(1, 2, 7);
  const Image own = halfVarianceOfMean(input, 1, Quantity::Color);
  const Image whole = wholeVarianceOfMean(input, Quantity::Color);
  for (size_t k = 0; k < own.size(); ++k) {
    ASSERT_EQ(own.data()[k], (*input.halves)[1].color.varianceOfMean.data()[k]);
    ASSERT_EQ(whole.data()[k], input.whole.color.varianceOfMean.data()[k]);
  }
}

// A whole of one sample (a 1-spp render: one half holds it, the other none) has no two-buffer
// estimate of its own; it keeps the equal-count one, (x1 − x2)² / 4, finite and not all zero.
TEST(VarianceEstimates, OneSampleWholeKeepsARoughEstimate) {
  DenoiseInput input = halvesOf(1, 1, 3);
  input.whole.sampleCount = Image(kSize, kSize, 1);
  input.whole.sampleCount.fill(1.0f);
  (*input.halves)[1].sampleCount.fill(0.0f);
  const Image whole = wholeVarianceOfMean(input, Quantity::Color);
  const Image expected = twoBufferVariance((*input.halves)[0], (*input.halves)[1], Quantity::Color,
                                           TwoBufferTarget::Whole);
  for (size_t k = 0; k < whole.size(); ++k) {
    ASSERT_TRUE(std::isfinite(whole.data()[k]));
    ASSERT_EQ(whole.data()[k], expected.data()[k]);
  }
  // Two one-sample halves of variance σ² each: E[(x1 − x2)² / 4] = σ² / 2.
  EXPECT_NEAR(meanOf(whole) / (kSigma * kSigma), 0.5, 0.03);
}

// One-sample pixels (a 1-spp render) record variance 0; the spatial estimate, the squared MAD of
// their 3x3 neighbourhood, recovers the per-sample variance σ² of i.i.d. Gaussian noise (it is
// consistent, not unbiased: the median of 9 deviations gives 0.989 σ² here; four seeds average
// 4096 pixels each).
// Pixels with 2 samples or more keep their own variance bit for bit; without counts nothing
// changes.
TEST(VarianceEstimates, OneSamplePixelsGetTheirNeighbourhoodsSpread) {
  double ratio = 0;
  constexpr int kSeeds = 4;
  for (unsigned seed = 1; seed <= kSeeds; ++seed) {
    const DenoiseInput input = halvesOf(1, 2, seed);
    const SubBuffer& one = (*input.halves)[0];
    ASSERT_EQ(meanOf(one.color.varianceOfMean), 0.0);
    ratio += meanOf(spatialVarianceWhereOneSample(one, Quantity::Color, one.color.varianceOfMean)) /
             (kSigma * kSigma) / kSeeds;
    const SubBuffer& two = (*input.halves)[1];
    EXPECT_TRUE(test::bitIdentical(
        spatialVarianceWhereOneSample(two, Quantity::Color, two.color.varianceOfMean),
        two.color.varianceOfMean));
    SubBuffer uncounted = one;
    uncounted.sampleCount = Image();
    EXPECT_TRUE(test::bitIdentical(
        spatialVarianceWhereOneSample(uncounted, Quantity::Color, one.color.varianceOfMean),
        one.color.varianceOfMean));
  }
  EXPECT_NEAR(ratio, 1.0, 0.1);
}

}  // namespace
}  // namespace chorus
