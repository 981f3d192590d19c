// The colour variance's calibration to the halves (denoise/base/variance_calibration.h): it
// restores the level of the noise the means actually carry, from independent halves of equal
// or unequal sample counts, and keeps the recorded variance's structure.
#include "denoise/base/variance_calibration.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "tests/support/gaussian_buffers.h"

namespace chorus {
namespace {

constexpr int kSize = 64;

// Noise whose level rises from left to right (σ 0.02 → 0.08) on a smooth truth.
struct Level {
  Image truth{kSize, kSize, 3}, sigma{kSize, kSize, 3};
  Level() {
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        for (int c = 0; c < 3; ++c) {
          truth(x, y, c) = 0.3f + 0.002f * float(x + y);
          sigma(x, y, c) = 0.02f + 0.06f * float(x) / float(kSize - 1);
        }
  }
  // Mean over the columns [x0, x1) of variance / σ².
  double ratio(const Image& variance, int x0, int x1) const {
    double sum = 0;
    int n = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = x0; x < x1; ++x)
        for (int c = 0; c < 3; ++c, ++n) sum += variance(x, y, c) / std::pow(sigma(x, y, c), 2.0f);
    return sum / n;
  }
};

TEST(VarianceCalibration, BringsAnOverstatedVarianceToTheHalvesLevel) {
  const Level level;
  DenoiseInput input =
      test::gaussianHalves(level.truth, level.sigma, test::flatFeatures(kSize, kSize, 64), 7);
  test::overstateColorVariances(input, 2.5f);
  const Image factor = colorVarianceCalibration(input, 3);
  ASSERT_FALSE(factor.empty());
  const Image whole = calibratedVariance(input.whole.color.varianceOfMean, factor);
  EXPECT_NEAR(level.ratio(input.whole.color.varianceOfMean, 0, kSize), 2.5, 1e-4);
  // Each third of the image, whose noise differs by up to 4× in σ², comes out at its own level.
  for (int third = 0; third < 3; ++third) {
    const double r = level.ratio(whole, third * kSize / 3, (third + 1) * kSize / 3);
    EXPECT_NEAR(r, 1.0, 0.08) << "third " << third;
  }
  // The halves take the same factor: each at its own variance (2σ²).
  const Image half = calibratedVariance((*input.halves)[0].color.varianceOfMean, factor);
  EXPECT_NEAR(level.ratio(half, 0, kSize) / 2.0, 1.0, 0.05);
}

// Halves of 4 and 8 samples of per-sample variance s²: the whole's mean (12 samples) has
// variance s² / 12, and (h1 − h2)² · 4 · 8 / 12² estimates it without bias; with the equal-count
// weight ¼ it would come out 12.5 % high.
TEST(VarianceCalibration, WeighsHalvesOfUnequalCountsWithoutBias) {
  // Exact recorded variances: factor 1 expected.
  const DenoiseInput input = test::unequalHalves(kSize, 4, 8, 0.2f, 11);
  const Image factor = colorVarianceCalibration(input, 3);
  double mean = 0;
  for (size_t k = 0; k < factor.size(); ++k) mean += factor.data()[k];
  mean /= double(factor.size());
  // 12 288 squared differences: standard error of their mean ≈ 1.3 %.
  EXPECT_NEAR(mean, 1.0, 0.04);
}

// Halves without recorded sample counts (another renderer's buffers) count as equal halves.
TEST(VarianceCalibration, TakesHalvesWithoutCountsAsEqual) {
  const Level level;
  DenoiseInput input =
      test::gaussianHalves(level.truth, level.sigma, test::flatFeatures(kSize, kSize, 64), 9);
  test::overstateColorVariances(input, 2.0f);
  for (SubBuffer* buffer : {&input.whole, &(*input.halves)[0], &(*input.halves)[1]})
    buffer->sampleCount = Image();
  const Image whole =
      calibratedVariance(input.whole.color.varianceOfMean, colorVarianceCalibration(input, 3));
  EXPECT_NEAR(level.ratio(whole, 0, kSize), 1.0, 0.05);
}

// Capped at 1 (SBF's use) the factor only lowers a variance: an understated one (0.4× the
// noise) stays as recorded, an overstated one (2.5×) comes down as without the cap.
TEST(VarianceCalibration, CappedFactorOnlyLowersTheVariance) {
  const Level level;
  for (float stated : {0.4f, 2.5f}) {
    DenoiseInput input =
        test::gaussianHalves(level.truth, level.sigma, test::flatFeatures(kSize, kSize, 64), 13);
    test::overstateColorVariances(input, stated);
    const Image capped = colorVarianceCalibration(input, 3, 1.0f);
    const Image free = colorVarianceCalibration(input, 3);
    ASSERT_FALSE(capped.empty());
    double mean = 0;
    for (size_t k = 0; k < capped.size(); ++k) {
      ASSERT_LE(capped.data()[k], 1.0f);
      ASSERT_EQ(capped.data()[k], std::min(free.data()[k], 1.0f));
      mean += capped.data()[k] / double(capped.size());
    }
    if (stated < 1.0f)
      EXPECT_GT(mean, 0.97) << "an understated variance stays as recorded";
    else
      EXPECT_NEAR(mean, 1.0 / stated, 0.05);
  }
}

TEST(VarianceCalibration, LeavesTheVarianceAloneWithoutHalvesOrRadius) {
  const Level level;
  DenoiseInput input =
      test::gaussianHalves(level.truth, level.sigma, test::flatFeatures(kSize, kSize, 16), 3);
  EXPECT_TRUE(colorVarianceCalibration(input, 0).empty());
  input.halves.reset();
  const Image factor = colorVarianceCalibration(input, 3);
  EXPECT_TRUE(factor.empty());
  const Image same = calibratedVariance(input.whole.color.varianceOfMean, factor);
  for (size_t k = 0; k < same.size(); ++k)
    ASSERT_EQ(same.data()[k], input.whole.color.varianceOfMean.data()[k]);
}

TEST(VarianceCalibration, GivesFiniteFactorsWhereValuesAreMissing) {
  const Level level;
  DenoiseInput input =
      test::gaussianHalves(level.truth, level.sigma, test::flatFeatures(kSize, kSize, 16), 5);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < 8; ++x) {
      (*input.halves)[0].color.mean(x, y, 0) = nan;  // a column band without one half
      input.whole.color.varianceOfMean(x + 20, y, 1) = inf;
    }
  input.whole.color.varianceOfMean(40, 40, 2) = -1.0f;
  (*input.halves)[1].sampleCount(50, 50, 0) = 0.0f;
  const Image factor = colorVarianceCalibration(input, 3);
  for (size_t k = 0; k < factor.size(); ++k) {
    ASSERT_TRUE(std::isfinite(factor.data()[k])) << k;
    ASSERT_GE(factor.data()[k], 0.0f) << k;
  }
  // Where nothing is missing, the level is the halves' (exact variances here: factor ≈ 1).
  EXPECT_NEAR(factor(48, 10, 0), 1.0, 0.5);
}

}  // namespace
}  // namespace chorus
