// NFOR (Bitterli et al. 2016) on the synthetic scene: error reduction, edges, every buffer part
// including 4 spp quarters (one sample each, so the variance falls back to the two-buffer
// estimate), constant and black images, determinism, non-finite inputs, registry.
#include "denoise/base/nfor/nfor.h"
#include "denoise/base/selection_knee.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "denoise/base/variance_estimates.h"
#include "denoise/metrics/metrics.h"
#include "tests/support/denoiser_checks.h"
#include "tests/support/synthetic_scene.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

TEST(Nfor, ReducesRelMseAndKeepsEdges) {
  test::expectReducesRelMse(NforDenoiser(), 8);
  test::expectKeepsFeatureEdgesSharp(NforDenoiser(), 3, 2.0f, 3);
}

TEST(Nfor, RunsOnEveryBufferPartIncludingSingleSampleQuarters) {
  test::expectReducesRelMseOnEveryBufferPart(NforDenoiser(), 3, 3);
}

TEST(Nfor, SingleSampleHalvesFallBackToTheTwoBufferVariance) {
  test::SyntheticSceneOptions o;
  o.samplesPerSubBuffer = 1;
  const test::SyntheticScene scene = test::syntheticScene(64, o);
  // On half A at 4 spp the halves are quarters with one sample: their own variance is 0.
  const DenoiseInput input = scene.buffers.input(BufferPart::HalfA);
  ASSERT_EQ(input.halves->at(0).sampleCount(3, 3, 0), 1.0f);
  const Image v = halfVarianceOfMean(input, 0, Quantity::Color);
  const Image expected = twoBufferVariance(input.halves->at(0), input.halves->at(1),
                                           Quantity::Color, TwoBufferTarget::FirstHalf);
  int positive = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    ASSERT_TRUE(std::isfinite(v.data()[i]));
    EXPECT_EQ(v.data()[i], expected.data()[i]);
    positive += v.data()[i] > 0 ? 1 : 0;
  }
  EXPECT_GT(positive, int(v.size()) * 9 / 10);  // smoothed: zero only where nothing is noisy
  // Where a buffer has its own estimate (≥ 2 samples), it is used as it is.
  const DenoiseInput full = scene.fullInput();
  EXPECT_TRUE(test::bitIdentical(halfVarianceOfMean(full, 1, Quantity::Color),
                                 full.halves->at(1).color.varianceOfMean));
}

TEST(Nfor, ConstantStaysConstantAndBlackStaysBlack) {
  test::expectConstantStaysConstant(NforDenoiser(), 1e-4f);
  test::expectBlackStaysBlack(NforDenoiser());
}

TEST(Nfor, DeterministicForAnyThreadCount) {
  // 90 wide: three regression tiles per row.
  test::SyntheticSceneOptions o;
  o.fireflyProbability = 0.01f;
  test::expectDeterministicAcrossThreads(NforDenoiser(), test::syntheticScene(90, 40, o));
}

TEST(Nfor, NonFiniteAndExtremeInputsGiveFiniteOutputs) {
  test::SyntheticSceneOptions o;
  o.fireflyProbability = 0.02f;
  o.fireflyScale = 1e5f;
  const test::SyntheticScene scene = test::syntheticScene(64, o);
  // (The black band is not expected to stay black here: NFOR's windows reach into it from the
  // firefly-laden neighbourhood, whose huge variance makes the band look similar.)
  test::expectFiniteOnNonFiniteInputs(NforDenoiser(), scene, [](DenoiseInput& input) {
    SubBuffer& a = input.halves->at(0);
    for (int x = 0; x < 64; ++x) {
      // A feature without samples on two rows (as in Tungsten's buffers), a black zero-variance
      // band, an infinite depth.
      input.whole.visibility.varianceOfMean(x, 10, 0) = test::kNan;
      input.whole.albedo.varianceOfMean(x, 11, 2) = test::kNan;
      for (int y = 40; y < 44; ++y)
        for (SubBuffer* b : {&input.whole, &a, &input.halves->at(1)})
          for (int c = 0; c < 3; ++c) {
            b->color.mean(x, y, c) = 0.0f;
            b->color.varianceOfMean(x, y, c) = 0.0f;
          }
      a.depth.mean(x, 20, 0) = test::kInf;
    }
    a.color.mean(5, 5, 0) = test::kNan;
    a.color.mean(6, 5, 1) = test::kInf;
    input.whole.color.varianceOfMean(7, 7, 1) = test::kInf;
    a.normal.mean(8, 8, 2) = -test::kInf;
    input.whole.color.mean(30, 30, 0) = 1e30f;
  });
}

// The selection's knee (selection_knee.h), on numbers worked by hand: an image whose mean |colour|
// is 1, knee 16: a pixel at level 8 keeps its errors, one at 64 (or −64) has them divided by
// (64 / 16)² = 16, in both maps; knee 0 changes nothing; scaling colour and level by s and the
// errors by s² scales the result by s² (the selection does not depend on the unit of radiance).
TEST(Nfor, SelectionKneePutsBrightPixelsOnTheRelativeScale) {
  Image colour(4, 1, 1), level(4, 1, 1), mse0(4, 1, 1), mse1(4, 1, 1);
  const float c[4] = {0.5f, 1.5f, -1.0f, 1.0f}, l[4] = {8.0f, 64.0f, -64.0f, 16.0f};
  const float e0[4] = {3.0f, 32.0f, 160.0f, 5.0f}, e1[4] = {-1.0f, 48.0f, 16.0f, 7.0f};
  const auto fill = [&](double s) {
    for (int x = 0; x < 4; ++x) {
      colour(x, 0, 0) = float(c[x] * s);
      level(x, 0, 0) = float(l[x] * s);
      mse0(x, 0, 0) = float(e0[x] * s * s);
      mse1(x, 0, 0) = float(e1[x] * s * s);
    }
  };
  // As NFOR applies it: the maps per pixel and channel, the level's own values.
  const auto kneeErrors = [&](float knee) {
    float* const maps[] = {mse0.data(), mse1.data()};
    kneeBrightErrors(
        maps, level.size(), [&](size_t e) { return double(level.data()[e]); },
        kneeLevel({colour.data(), colour.size()}, knee));
  };
  const float expected0[4] = {3.0f, 2.0f, 10.0f, 5.0f}, expected1[4] = {-1.0f, 3.0f, 1.0f, 7.0f};
  for (double s : {1.0, 1e-15, 1e15}) {
    fill(s);
    kneeErrors(16.0f);
    for (int x = 0; x < 4; ++x) {
      EXPECT_NEAR(mse0(x, 0, 0) / (s * s), expected0[x], 1e-5 * std::abs(expected0[x])) << x;
      EXPECT_NEAR(mse1(x, 0, 0) / (s * s), expected1[x], 1e-5 * std::abs(expected1[x])) << x;
    }
  }
  fill(1.0);
  kneeErrors(0.0f);
  for (int x = 0; x < 4; ++x) EXPECT_EQ(mse0(x, 0, 0), e0[x]);
}

TEST(Nfor, RequirementsRegistryAndParameters) {
  test::expectCreates("nfor:k1=0.4:k2=1.2:regressionR=7:selectionKnee=0:varianceKnee=64", "nfor",
                      {.features = true, .halves = true});
  test::expectRejected({"nfor:bandwidth=1", "nfor:k1=0", "nfor:regressionR=-1",
                        "nfor:selectionKnee=-1", "nfor:varianceKnee=-1", "nfor:varianceKnee=nan"});
  test::expectNeedsHalves(NforDenoiser());
}

}  // namespace
}  // namespace chorus
