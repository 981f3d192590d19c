// SURE: on images with known truth and Gaussian noise of known variance, the mean SURE over
// many seeds matches the true MSE within 3 standard errors, for a linear filter written here
// and for the cross-bilateral candidates (with and without the colour range term, whose exact
// derivative the filter supplies). Dropping the derivative term must fail the same check.
#include "denoise/base/filters/sure.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include "denoise/base/cross_bilateral/cross_bilateral.h"
#include "denoise/base/input_planes.h"

namespace chorus {
namespace {

constexpr int kW = 24, kH = 20, kSeeds = 400;

// Smooth shading with a step: the truth μ.
Image truthImage() {
  Image truth(kW, kH, 3);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int c = 0; c < 3; ++c)
        truth(x, y, c) = 0.3f + 0.2f * std::sin(0.3f * x + c) + (x > 12 ? 0.4f : 0.0f);
  return truth;
}

// Known, spatially varying noise variance σ².
Image varianceImage() {
  Image variance(kW, kH, 3);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int c = 0; c < 3; ++c) variance(x, y, c) = 0.002f + 0.01f * float(y) / kH;
  return variance;
}

Image noisyImage(const Image& truth, const Image& variance, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  Image noisy = truth;
  for (size_t i = 0; i < noisy.size(); ++i)
    noisy.data()[i] += std::sqrt(variance.data()[i]) * gauss(rng);
  return noisy;
}

struct Filtered {
  Image output, derivative;
};

// A 5×5 binomial filter with clipped, renormalised borders; ∂F(p)/∂y(p) = h(0)/Σh exactly.
Filtered binomialFilter(const Image& y, const Image& /*variance*/) {
  const float taps[5] = {1, 4, 6, 4, 1};
  Filtered f{Image(kW, kH, 3), Image(kW, kH, 1)};
  for (int py = 0; py < kH; ++py)
    for (int px = 0; px < kW; ++px) {
      double sum[3] = {}, weight = 0;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const int qx = px + dx, qy = py + dy;
          if (qx < 0 || qy < 0 || qx >= kW || qy >= kH) continue;
          const double h = taps[dx + 2] * taps[dy + 2];
          weight += h;
          for (int c = 0; c < 3; ++c) sum[c] += h * y(qx, qy, c);
        }
      for (int c = 0; c < 3; ++c) f.output(px, py, c) = float(sum[c] / weight);
      f.derivative(px, py, 0) = float(36.0 / weight);
    }
  return f;
}

// Features with an edge at x = 12 (albedo) and a normal tilt for y > 10, noise-free, so the
// feature-only cross-bilateral is linear in the colour.
SubBuffer bufferWithFeatures(const Image& noisy, const Image& variance) {
  SubBuffer b = SubBuffer::zeros(kW, kH);
  b.color.mean = noisy;
  b.color.varianceOfMean = variance;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      for (int c = 0; c < 3; ++c) b.albedo.mean(x, y, c) = x > 12 ? 0.8f : 0.2f;
      b.normal.mean(x, y, 2) = 1.0f;
      b.normal.mean(x, y, 0) = y > 10 ? 0.6f : 0.0f;
      b.depth.mean(x, y, 0) = 1.0f + 0.05f * y;
      b.sampleCount(x, y, 0) = 16;
    }
  return b;
}

using FilterFn = std::function<Filtered(const Image& noisy, const Image& variance)>;

struct SureCheck {
  double meanDifference, standardError, meanMse;
};

// Per seed: d = mean over pixels of SURE − true MSE; returns the mean of d and its standard
// error over the seeds.
SureCheck checkSure(const FilterFn& filterFn, bool dropDerivative = false) {
  const Image truth = truthImage(), variance = varianceImage();
  double sum = 0, sumSquares = 0, mseSum = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const Image noisy = noisyImage(truth, variance, uint32_t(1000 + seed));
    Filtered f = filterFn(noisy, variance);
    if (dropDerivative) f.derivative.fill(0.0f);
    const Image sure = sureMap(f.output, noisy, variance, f.derivative);
    double meanSure = 0, mse = 0;
    for (float v : sure.values()) meanSure += v / double(sure.size());
    for (size_t i = 0; i < truth.size(); ++i) {
      const double e = f.output.data()[i] - truth.data()[i];
      mse += e * e / double(truth.size());
    }
    const double d = meanSure - mse;
    sum += d;
    sumSquares += d * d;
    mseSum += mse;
  }
  const double mean = sum / kSeeds;
  const double sd = std::sqrt((sumSquares - kSeeds * mean * mean) / (kSeeds - 1));
  return {mean, sd / std::sqrt(double(kSeeds)), mseSum / kSeeds};
}

FilterFn bilateral(float sigmaS, float sigmaC) {
  return [=](const Image& noisy, const Image& variance) {
    const SubBuffer b = bufferWithFeatures(noisy, variance);
    const float sigmas[] = {sigmaS};
    auto cand = crossBilateralCandidates(sanitizedMean(b.color),
                                         sanitizedVarianceOfMean(b.color.varianceOfMean),
                                         makeFeatureGuide(b, {}), sigmas, sigmaC);
    return Filtered{cand[0].filtered.toImage(), cand[0].derivative.toImage()};
  };
}

TEST(Sure, MatchesTrueMseForALinearFilter) {
  const SureCheck check = checkSure(binomialFilter);
  EXPECT_LT(std::abs(check.meanDifference), 3 * check.standardError)
      << "mean SURE − MSE " << check.meanDifference << ", SE " << check.standardError;
  // The test can fail: without the 2σ² ∂F/∂y term SURE is far off.
  const SureCheck wrong = checkSure(binomialFilter, true);
  EXPECT_GT(std::abs(wrong.meanDifference), 10 * wrong.standardError);
}

TEST(Sure, MatchesTrueMseForFeatureOnlyCrossBilateral) {
  for (float sigmaS : {1.0f, 3.0f}) {
    const SureCheck check = checkSure(bilateral(sigmaS, 0.0f));
    EXPECT_LT(std::abs(check.meanDifference), 3 * check.standardError)
        << "σs " << sigmaS << ": mean SURE − MSE " << check.meanDifference << ", SE "
        << check.standardError << ", MSE " << check.meanMse;
  }
}

TEST(Sure, MatchesTrueMseWithTheColourRangeTerm) {
  // Nonlinear in the colour; Stein's lemma still holds with the exact derivative.
  const SureCheck check = checkSure(bilateral(2.0f, 1.0f));
  EXPECT_LT(std::abs(check.meanDifference), 3 * check.standardError)
      << "mean SURE − MSE " << check.meanDifference << ", SE " << check.standardError;
  const SureCheck wrong = checkSure(bilateral(2.0f, 1.0f), true);
  EXPECT_GT(std::abs(wrong.meanDifference), 10 * wrong.standardError);
}

TEST(Sure, TermAndMapFormulas) {
  // (F − y)² + 2σ² ∂F/∂y − σ²
  EXPECT_FLOAT_EQ(sureTerm(1.5f, 1.0f, 0.2f, 0.25f), 0.25f + 0.1f - 0.2f);
  Image f(1, 1, 3, 1.0f), y(1, 1, 3, 0.0f), v(1, 1, 3, 0.5f), d(1, 1, 1, 1.0f);
  f(0, 0, 2) = 3.0f;
  // Channels: 1 + 0.5, 1 + 0.5, 9 + 0.5 → mean 12.5 / 3.
  EXPECT_FLOAT_EQ(sureMap(f, y, v, d)(0, 0, 0), 12.5f / 3.0f);
  EXPECT_THROW(sureMap(f, y, Image(2, 1, 3), d), std::invalid_argument);
  v(0, 0, 1) = std::numeric_limits<float>::quiet_NaN();  // counts as 0
  EXPECT_FLOAT_EQ(sureMap(f, y, v, d)(0, 0, 0), 12.0f / 3.0f);
  f(0, 0, 0) = 1e30f;
  EXPECT_TRUE(std::isfinite(sureMap(f, y, v, d)(0, 0, 0)));
}

}  // namespace
}  // namespace chorus
