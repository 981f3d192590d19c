// RDFC (Rousselle et al. 2013) on the synthetic scene: error reduction, sharp feature edges,
// constant and black images, all buffer parts, one sample per buffer, determinism, non-finite
// inputs, parameters.
#include "denoise/base/rdfc/rdfc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "denoise/metrics/metrics.h"
#include "tests/support/denoiser_checks.h"
#include "tests/support/synthetic_scene.h"

namespace chorus {
namespace {

// Documented in docs/members/rdfc-jnlm.md (RDFC): measured relMSE 0.053 → 0.0032 (17×) at 64×64, 16
// spp.
constexpr double kMinImprovement = 8.0;

TEST(Rdfc, ReducesRelMseOnTheSyntheticScene) {
  const test::SyntheticScene scene = test::syntheticScene(64);
  const DenoiseInput input = scene.fullInput();
  const RdfcResult result = runRdfc(input, RdfcParams{});
  const double noisy = relMse(input.whole.color.mean, scene.truth);
  const double first = relMse(result.firstPass, scene.truth);
  const double denoised = relMse(result.output, scene.truth);
  std::cout << "relMSE noisy " << noisy << ", first pass " << first << ", rdfc " << denoised
            << "\n";
  EXPECT_LT(denoised * kMinImprovement, noisy);
  EXPECT_LT(denoised, first);  // the second pass helps
}

TEST(Rdfc, KeepsFeatureEdgesSharp) {
  test::expectKeepsFeatureEdgesSharp(Rdfc(), 3.0, 2.0f, 3.0);
}

TEST(Rdfc, ConstantStaysConstantAndBlackStaysBlack) {
  test::expectConstantStaysConstant(Rdfc(), 1e-5f);
  test::expectBlackStaysBlack(Rdfc());
}

TEST(Rdfc, RunsOnEveryBufferPart) {
  test::expectRunsOnEveryBufferPart(Rdfc(), /*withHalves=*/true, 5);
}

// 4 spp in K = 4 quarters: run on half A, each of its halves holds one sample per pixel, so
// per-buffer variances are 0 ("not measured"); with the whole's variance missing as well, the
// two-buffer estimate must stand in.
TEST(Rdfc, OneSamplePerBufferUsesTheTwoBufferVariance) {
  test::SyntheticSceneOptions o;
  o.samplesPerSubBuffer = 1;
  const test::SyntheticScene scene = test::syntheticScene(64, o);
  DenoiseInput input = scene.buffers.input(BufferPart::HalfA);
  for (const SubBuffer& half : *input.halves)
    for (float v : half.color.varianceOfMean.values()) ASSERT_EQ(v, 0.0f);
  const double noisy = relMse(input.whole.color.mean, scene.truth);
  const double withSampleVariance = relMse(Rdfc().run(input), scene.truth);
  for (float& v : input.whole.color.varianceOfMean.values()) v = 0.0f;
  for (int x = 0; x < 64; ++x) input.whole.color.varianceOfMean(x, 3, 1) = std::nanf("");
  const Image out = Rdfc().run(input);
  ASSERT_EQ(test::firstNonFinite(out), "");
  const double withTwoBuffer = relMse(out, scene.truth);
  std::cout << "2 spp: relMSE noisy " << noisy << ", rdfc " << withSampleVariance
            << ", without sample variance " << withTwoBuffer << "\n";
  EXPECT_LT(withSampleVariance * 3, noisy);
  EXPECT_LT(withTwoBuffer * 3, noisy);
}

TEST(Rdfc, DeterministicForAnyThreadCount) {
  // 150 wide: several tiles per row and column.
  test::expectDeterministicAcrossThreads(Rdfc(), test::syntheticScene(150, 40));
}

TEST(Rdfc, NonFiniteInputsGiveFiniteOutputs) {
  test::expectFiniteOnNonFiniteInputs(Rdfc(), test::syntheticScene(64), [](DenoiseInput& input) {
    SubBuffer& a = (*input.halves)[0];
    for (int x = 0; x < 64; ++x) {
      input.whole.albedo.varianceOfMean(x, 10, 1) = test::kNan;
      input.whole.visibility.varianceOfMean(x, 11, 0) = test::kNan;
      input.whole.depth.mean(x, 20, 0) = test::kInf;
      a.normal.mean(x, 30, 0) = test::kNan;
    }
    a.color.mean(5, 5, 0) = test::kNan;
    (*input.halves)[1].color.mean(6, 6, 2) = test::kInf;
    input.whole.color.varianceOfMean(7, 7, 1) = test::kInf;
    input.whole.color.varianceOfMean(8, 8, 1) = -1.0f;
    input.whole.color.mean(9, 9, 0) = test::kNan;
  });
}

// The second pass's variance on numbers worked by hand: one row of three pixels, levels 1, 8, 3
// (mean 4), (b1 − b2)²/4 = 1, 400, 4. Knee 1: the middle pixel (level 8 = 2 × 4) is smoothed as
// 400 / 4 = 100 and multiplied back by 4; knee 0: as is. Taps [w, 1, w] / (taps used), w = e^−2,
// only horizontal in one row. Scaling colour by s scales the variance by s².
TEST(Rdfc, SecondPassVarianceSmoothsBrightPixelsInRelativeUnits) {
  const float level[3] = {1.0f, 8.0f, 3.0f}, halfDifference[3] = {1.0f, 20.0f, 2.0f};
  const double w = std::exp(-2.0);
  const double kneed[3] = {(1 + 100 * w) / (1 + w), 4 * (w + 100 + 4 * w) / (1 + 2 * w),
                           (100 * w + 4) / (1 + w)};
  const double plain[3] = {(1 + 400 * w) / (1 + w), (w + 400 + 4 * w) / (1 + 2 * w),
                           (400 * w + 4) / (1 + w)};
  for (double s : {1.0, 1e-10, 1e10}) {
    Image first1(3, 1, 3), first2(3, 1, 3), guide(3, 1, 3);
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 3; ++c) {
        guide(x, 0, c) = float(level[x] * s);
        first1(x, 0, c) = float((level[x] + halfDifference[x]) * s);
        first2(x, 0, c) = float((level[x] - halfDifference[x]) * s);
      }
    const Image withKnee = rdfcSecondPassVariance(first1, first2, guide, 1.0f);
    const Image without = rdfcSecondPassVariance(first1, first2, guide, 0.0f);
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(withKnee(x, 0, c) / (s * s), kneed[x], 1e-5 * kneed[x]) << x << " " << s;
        EXPECT_NEAR(without(x, 0, c) / (s * s), plain[x], 1e-5 * plain[x]) << x << " " << s;
      }
  }
}

TEST(Rdfc, NeedsHalves) {
  test::expectNeedsHalves(Rdfc());
}

TEST(Rdfc, RegistryAndParameters) {
  const auto rdfc = test::expectCreates(
      "rdfc:r=6:kc=0.5:kf=0.7:tau=0.002:rescale=false:selectionKnee=0:varianceKnee=0", "rdfc",
      {.features = true, .halves = true});
  test::expectRejected({"rdfc:r=0", "rdfc:kc=-1", "rdfc:tau=nan", "rdfc:k=1",
                        "rdfc:selectionKnee=-1", "rdfc:selectionKnee=inf", "rdfc:varianceKnee=-1"});
  test::expectReducesRelMse(*rdfc, 4);
}

}  // namespace
}  // namespace chorus
