// The synthetic test scene: its ground truth is the expectation of its samples, its features
// are exact away from edges, and its edge mask finds the edges.
#include "tests/support/synthetic_scene.h"

#include <gtest/gtest.h>

#include <cmath>

namespace chorus::test {
namespace {

TEST(SyntheticScene, ColourMeanIsUnbiasedForTheTruth) {
  SyntheticSceneOptions options;
  options.width = options.height = 24;
  options.samplesPerSubBuffer = 16;
  options.fireflyProbability = 0.01f;
  options.fireflyScale = 20.0f;
  const SyntheticScene scene = makeSyntheticScene(options);
  const SubBuffer full = scene.buffers.part(BufferPart::Full);
  // Sum over pixels of (mean − truth) has variance Σ varianceOfMean: a z-score per channel.
  for (int c = 0; c < 3; ++c) {
    double sum = 0, variance = 0;
    for (int y = 0; y < options.height; ++y)
      for (int x = 0; x < options.width; ++x) {
        sum += full.color.mean(x, y, c) - scene.truth(x, y, c);
        variance += full.color.varianceOfMean(x, y, c);
      }
    EXPECT_LT(std::abs(sum) / std::sqrt(variance), 4.0) << "channel " << c;
  }
  EXPECT_EQ(full.sampleCount(3, 3, 0), 64.0f);
}

TEST(SyntheticScene, PerSampleVarianceMatchesTheExponentialNoise) {
  SyntheticSceneOptions options;
  options.width = options.height = 32;
  options.subBuffers = 1;
  options.samplesPerSubBuffer = 256;
  const SyntheticScene scene = makeSyntheticScene(options);
  const SubBuffer& sub = scene.buffers.sub(0);
  // Exponential factor: per-sample variance = radiance², away from edges.
  double ratio = 0;
  int count = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      if (scene.edgeMask(x, y, 0) > 0) continue;
      const double truth = scene.truth(x, y, 1);
      ratio += sub.color.varianceOfMean(x, y, 1) * 256.0 / (truth * truth);
      ++count;
    }
  ASSERT_GT(count, 300);
  EXPECT_NEAR(ratio / count, 1.0, 0.1);
}

TEST(SyntheticScene, FeaturesAreExactAwayFromEdgesAndVaryAcrossThem) {
  SyntheticSceneOptions options;
  options.width = options.height = 32;
  const SyntheticScene scene = makeSyntheticScene(options);
  ASSERT_GT(scene.edgePixelCount, 32);
  ASSERT_LT(scene.edgePixelCount, 32 * 32 / 2);
  const SubBuffer full = scene.buffers.part(BufferPart::Full);
  int edgeWithVariance = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      // The plane's depth is 2 + v; the sphere (centre (0.62, 0.4), radius 0.2) is nearer.
      const double u = (x + 0.5) / 32, v = (y + 0.5) / 32;
      const double r = std::hypot((u - 0.62) / 0.2, (v - 0.4) / 0.2);
      if (r > 1.1) {
        EXPECT_NEAR(scene.depth(x, y, 0), 2.0 + v, 1e-5) << x << "," << y;
      }
      if (scene.edgeMask(x, y, 0) == 0) {
        // Albedo is piecewise constant; normals too on the plane (the sphere's vary smoothly).
        EXPECT_EQ(full.albedo.varianceOfMean(x, y, 0), 0.0f) << x << "," << y;
        if (r > 1.1) {
          EXPECT_EQ(full.normal.varianceOfMean(x, y, 2), 0.0f) << x << "," << y;
        }
      } else if (full.albedo.varianceOfMean(x, y, 0) > 0 ||
                 full.normal.varianceOfMean(x, y, 0) > 0) {
        ++edgeWithVariance;
      }
    }
  EXPECT_GT(edgeWithVariance, 10);
  // Albedo edge at u = 0.5 (orange | blue) in the upper part of the plane.
  EXPECT_NEAR(scene.albedo(2, 2, 0), 0.8f, 1e-6);
  EXPECT_NEAR(scene.albedo(29, 2, 0), 0.15f, 1e-6);
}

TEST(SyntheticScene, ConstantColourAndDeterminism) {
  SyntheticSceneOptions options;
  options.width = options.height = 12;
  options.constantColor = std::array<float, 3>{0.25f, 0.5f, 2.0f};
  const SyntheticScene a = makeSyntheticScene(options), b = makeSyntheticScene(options);
  const SubBuffer full = a.buffers.part(BufferPart::Full);
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 12; ++x) {
      EXPECT_EQ(full.color.mean(x, y, 2), 2.0f);
      EXPECT_EQ(full.color.varianceOfMean(x, y, 2), 0.0f);
      EXPECT_EQ(a.truth(x, y, 1), 0.5f);
    }
  for (int k = 0; k < 4; ++k) {
    const auto va = a.buffers.sub(k).normal.mean.values(),
               vb = b.buffers.sub(k).normal.mean.values();
    EXPECT_TRUE(std::equal(va.begin(), va.end(), vb.begin()));
  }
}

TEST(SyntheticScene, MaskedRelMseCountsOnlyTheMask) {
  Image image(2, 1, 1), reference(2, 1, 1), mask(2, 1, 1);
  image(0, 0, 0) = 1.0f;  // error 1 in pixel 0, none in pixel 1
  mask(1, 0, 0) = 1.0f;
  EXPECT_EQ(maskedRelMse(image, reference, mask), 0.0);
  mask(0, 0, 0) = 1.0f;
  EXPECT_NEAR(maskedRelMse(image, reference, mask), 0.5 * 1.0 / 0.01, 1e-9);
}

}  // namespace
}  // namespace chorus::test
