// The joint cross-bilateral filter against a naive double-precision evaluation of its formula,
// its SURE derivative against finite differences, determinism and robustness.
#include "denoise/base/cross_bilateral/cross_bilateral.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>
#include <random>

#include "denoise/base/input_planes.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

// A small buffer with random colour, features (some variances zero, some large) and counts.
SubBuffer randomBuffer(int w, int h, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  SubBuffer b = SubBuffer::zeros(w, h);
  for (Quantity q : kAllQuantities) {
    for (float& v : b.get(q).mean.values()) v = u(rng);
    for (float& v : b.get(q).varianceOfMean.values()) v = u(rng) < 0.5f ? 0.0f : 0.01f * u(rng);
  }
  for (float& v : b.depth.mean.values()) v = 1.0f + 4.0f * u(rng);
  for (float& n : b.sampleCount.values()) n = float(1 + int(8 * u(rng)));
  return b;
}

struct NaiveResult {
  double filtered, derivative;
};

// The header's formula, evaluated directly for one pixel and channel in double.
NaiveResult naive(const SubBuffer& b, int px, int py, int c, float sigmaS, float sigmaC,
                  const FeatureSigmas& sigmas) {
  const int radius = sigmaS > 0 ? int(std::lround(2.0 * sigmaS)) : 0;
  double maxDepth = 0;
  for (float d : b.depth.mean.values()) maxDepth = std::max(maxDepth, double(d));
  struct Feature {
    const MeanVariance* f;
    double sigma, scale;
  };
  const Feature features[3] = {{&b.normal, sigmas.normal, 1.0},
                               {&b.albedo, sigmas.albedo, 1.0},
                               {&b.depth, sigmas.depth, 1.0 / maxDepth}};
  double sumW = 0, sumWc = 0, sumWtc = 0, sumWt = 0;
  for (int qy = std::max(0, py - radius); qy <= std::min(b.height() - 1, py + radius); ++qy)
    for (int qx = std::max(0, px - radius); qx <= std::min(b.width() - 1, px + radius); ++qx) {
      const double d2 = double((qx - px) * (qx - px) + (qy - py) * (qy - py));
      double exponent = sigmaS > 0 ? d2 / (2.0 * sigmaS * sigmaS) : 0.0;
      for (const Feature& f : features)
        for (int k = 0; k < f.f->mean.channels(); ++k) {
          const double diff = (f.f->mean(px, py, k) - f.f->mean(qx, qy, k)) * f.scale;
          const double var = (f.f->varianceOfMean(px, py, k) * b.sampleCount(px, py, 0) +
                              f.f->varianceOfMean(qx, qy, k) * b.sampleCount(qx, qy, 0)) *
                             f.scale * f.scale;
          exponent += diff * diff / (2.0 * f.sigma * f.sigma * std::max(var, 0.01));
        }
      double t = 0;
      if (sigmaC > 0)
        for (int k = 0; k < 3; ++k) {
          const double diff = b.color.mean(px, py, k) - b.color.mean(qx, qy, k);
          const double den =
              2.0 * sigmaC * sigmaC *
                  (b.color.varianceOfMean(px, py, k) + b.color.varianceOfMean(qx, qy, k)) +
              1e-10;
          exponent += diff * diff / den;
          if (k == c) t = 2.0 * diff / den;
        }
      const double w = std::exp(-exponent);
      sumW += w;
      sumWc += w * b.color.mean(qx, qy, c);
      sumWtc += w * t * b.color.mean(qx, qy, c);
      sumWt += w * t;
    }
  const double filtered = sumWc / sumW;
  return {filtered, 1.0 / sumW - (sumWtc - filtered * sumWt) / sumW};
}

std::vector<BilateralCandidate> filter(const SubBuffer& b, const std::vector<float>& sigmaS,
                                       float sigmaC, const FeatureSigmas& sigmas = {}) {
  return crossBilateralCandidates(sanitizedMean(b.color),
                                  sanitizedVarianceOfMean(b.color.varianceOfMean),
                                  makeFeatureGuide(b, sigmas), sigmaS, sigmaC);
}

TEST(CrossBilateral, MatchesTheNaiveFormula) {
  const SubBuffer b = randomBuffer(13, 11, 7);
  const std::vector<float> sigmaS = {2.5f, 0.0f, 1.0f};
  for (float sigmaC : {0.0f, 1.5f}) {
    const auto candidates = filter(b, sigmaS, sigmaC);
    ASSERT_EQ(candidates.size(), sigmaS.size());
    for (size_t s = 0; s < sigmaS.size(); ++s)
      for (int y = 0; y < 11; ++y)
        for (int x = 0; x < 13; ++x)
          for (int c = 0; c < 3; ++c) {
            const NaiveResult expected = naive(b, x, y, c, sigmaS[s], sigmaC, {});
            const size_t i = size_t(y * 13 + x);
            ASSERT_NEAR(candidates[s].filtered.plane(c)[i], expected.filtered, 2e-5)
                << "sigmaS " << sigmaS[s] << " sigmaC " << sigmaC << " at " << x << "," << y;
            ASSERT_NEAR(candidates[s].derivative.plane(c)[i], expected.derivative, 2e-5)
                << "sigmaS " << sigmaS[s] << " sigmaC " << sigmaC << " at " << x << "," << y;
          }
  }
}

TEST(CrossBilateral, SigmaZeroIsTheIdentity) {
  const SubBuffer b = randomBuffer(9, 7, 3);
  const auto candidates = filter(b, {0.0f}, 0.0f);
  const PlanarImage color(b.color.mean);
  for (int c = 0; c < 3; ++c)
    for (size_t i = 0; i < color.pixelCount(); ++i) {
      EXPECT_EQ(candidates[0].filtered.plane(c)[i], color.plane(c)[i]);
      EXPECT_EQ(candidates[0].derivative.plane(c)[i], 1.0f);
    }
}

TEST(CrossBilateral, RangeDerivativeMatchesFiniteDifferences) {
  SubBuffer b = randomBuffer(10, 9, 11);
  for (float& v : b.color.varianceOfMean.values()) v = 0.02f;
  // Uniform features, so that the colour range term decides the weights.
  for (Quantity q : {Quantity::Albedo, Quantity::Normal, Quantity::Depth}) b.get(q).mean.fill(0.5f);
  const int px = 4, py = 5, c = 1;
  const float h = 1e-3f;
  const auto base = filter(b, {1.5f}, 1.0f);
  SubBuffer plus = b, minus = b;
  plus.color.mean(px, py, c) += h;
  minus.color.mean(px, py, c) -= h;
  const size_t i = size_t(py * 10 + px);
  const double numeric = (double(filter(plus, {1.5f}, 1.0f)[0].filtered.plane(c)[i]) -
                          double(filter(minus, {1.5f}, 1.0f)[0].filtered.plane(c)[i])) /
                         (2.0 * h);
  EXPECT_NEAR(base[0].derivative.plane(c)[i], numeric, 2e-3);
  // The range term makes the derivative differ from the feature-only 1/Σw.
  EXPECT_GT(
      std::abs(base[0].derivative.plane(c)[i] - filter(b, {1.5f}, 0.0f)[0].derivative.plane(c)[i]),
      1e-3);
}

TEST(CrossBilateral, SmoothAppliesFeatureOnlyWeightsToEveryPlane) {
  const SubBuffer b = randomBuffer(12, 10, 5);
  const PlanarImage color(b.color.mean);
  const FeatureGuide guide = makeFeatureGuide(b, {});
  const PlanarImage smoothed = crossBilateralSmooth(color, guide, 2.0f);
  const float sigmas[] = {2.0f};
  const auto candidates = crossBilateralCandidates(color, PlanarImage(12, 10, 3), guide, sigmas, 0);
  for (int c = 0; c < 3; ++c)
    for (size_t i = 0; i < color.pixelCount(); ++i)
      EXPECT_FLOAT_EQ(smoothed.plane(c)[i], candidates[0].filtered.plane(c)[i]);
}

TEST(CrossBilateral, DeterministicForAnyThreadCount) {
  const SubBuffer b = randomBuffer(300, 40, 9);  // several tiles per row
  std::vector<BilateralCandidate> one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = filter(b, {1.0f, 4.0f}, 2.0f);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = filter(b, {1.0f, 4.0f}, 2.0f);
  }
  for (size_t s = 0; s < 2; ++s)
    for (int c = 0; c < 3; ++c)
      for (size_t i = 0; i < one[s].filtered.pixelCount(); ++i) {
        ASSERT_EQ(one[s].filtered.plane(c)[i], two[s].filtered.plane(c)[i]);
        ASSERT_EQ(one[s].derivative.plane(c)[i], two[s].derivative.plane(c)[i]);
      }
}

TEST(CrossBilateral, NonFiniteInputsGiveFiniteOutputs) {
  SubBuffer b = randomBuffer(16, 12, 13);
  const float nan = std::numeric_limits<float>::quiet_NaN(),
              inf = std::numeric_limits<float>::infinity();
  b.albedo.varianceOfMean(3, 3, 0) = nan;
  b.normal.mean(5, 5, 1) = nan;
  b.depth.mean(7, 2, 0) = inf;
  b.depth.varianceOfMean(7, 2, 0) = nan;
  b.color.mean(9, 9, 2) = inf;
  b.color.varianceOfMean(1, 1, 0) = nan;
  b.sampleCount(2, 2, 0) = 0;  // unknown count
  for (const auto& cand : filter(b, {0.0f, 2.0f}, 1.0f))
    for (int c = 0; c < 3; ++c)
      for (size_t i = 0; i < cand.filtered.pixelCount(); ++i) {
        ASSERT_TRUE(std::isfinite(cand.filtered.plane(c)[i])) << i;
        ASSERT_TRUE(std::isfinite(cand.derivative.plane(c)[i])) << i;
      }
}

TEST(CrossBilateral, FeatureGuideScalesDepthAndUsesPerSampleVariance) {
  SubBuffer b = SubBuffer::zeros(2, 1);
  b.depth.mean(0, 0, 0) = 2.0f;
  b.depth.mean(1, 0, 0) = 4.0f;
  b.depth.varianceOfMean(1, 0, 0) = 0.5f;
  b.sampleCount(0, 0, 0) = 8;
  b.sampleCount(1, 0, 0) = 8;
  const FeatureGuide guide = makeFeatureGuide(b, {0.0f, 0.0f, 0.5f});  // depth only
  ASSERT_EQ(guide.value.channels(), 1);
  // Depth / max depth (4), divided by √2 σ.
  EXPECT_NEAR(guide.value.plane(0)[0], 0.5 / (std::sqrt(2.0) * 0.5), 1e-6);
  // Per-sample variance 0.5 × 8, scaled by 1 / 4².
  EXPECT_NEAR(guide.variance.plane(0)[1], 4.0 / 16.0, 1e-7);
}

}  // namespace
}  // namespace chorus
