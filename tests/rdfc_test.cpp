// RDFC (Rousselle et al. 2013) on the synthetic scene: error reduction, sharp feature edges,
// constant and black images, all buffer parts, one sample per buffer, determinism, non-finite
// inputs, parameters.
#include "denoise/base/rdfc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>

#include "denoise/base/registry.h"
#include "denoise/metrics/metrics.h"
#include "denoise/util/error.h"
#include "tests/support/denoiser_checks.h"
#include "tests/support/synthetic_scene.h"

namespace chorus {
namespace {

test::SyntheticScene scene64(const test::SyntheticSceneOptions& extra = {}) {
  test::SyntheticSceneOptions o = extra;
  o.width = o.height = 64;
  return test::makeSyntheticScene(o);
}

// Documented in README.md (RDFC): measured relMSE 0.053 → 0.0032 (17×) at 64×64, 16 spp.
constexpr double kMinImprovement = 8.0;

TEST(Rdfc, ReducesRelMseOnTheSyntheticScene) {
  const test::SyntheticScene scene = scene64();
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
  const test::SyntheticScene scene = scene64();
  const DenoiseInput input = scene.fullInput();
  const Image out = Rdfc().run(input);
  const double noisyEdges = test::maskedRelMse(input.whole.color.mean, scene.truth, scene.edgeMask);
  const double edges = test::maskedRelMse(out, scene.truth, scene.edgeMask);
  const double blurEdges = test::maskedRelMse(test::gaussianBlur(input.whole.color.mean, 2.0f),
                                              scene.truth, scene.edgeMask);
  std::cout << "edge relMSE noisy " << noisyEdges << ", rdfc " << edges << ", blur " << blurEdges
            << " over " << scene.edgePixelCount << " pixels\n";
  EXPECT_LT(edges * 3.0, noisyEdges);
  EXPECT_LT(edges * 3.0, blurEdges);
}

TEST(Rdfc, ConstantStaysConstantAndBlackStaysBlack) {
  for (const std::array<float, 3> value :
       {std::array<float, 3>{0.3f, 1.5f, 7.0f}, std::array<float, 3>{0.0f, 0.0f, 0.0f}}) {
    test::SyntheticSceneOptions o;
    o.constantColor = value;
    const test::SyntheticScene scene = scene64(o);
    const Image out = Rdfc().run(scene.fullInput());
    EXPECT_LE(test::maxDeviationFrom(out, value.data()), 1e-5f * value[2]) << value[2];
  }
}

TEST(Rdfc, RunsOnEveryBufferPart) {
  const test::SyntheticScene scene = scene64();
  for (BufferPart part : {BufferPart::HalfA, BufferPart::HalfB, BufferPart::Full}) {
    const DenoiseInput input = scene.buffers.input(part);
    ASSERT_TRUE(input.halves);
    const Image out = Rdfc().run(input);
    ASSERT_EQ(out.width(), 64);
    ASSERT_EQ(out.channels(), 3);
    EXPECT_EQ(test::firstNonFinite(out), "");
    EXPECT_LT(relMse(out, scene.truth) * 5, relMse(input.whole.color.mean, scene.truth))
        << partName(part);
  }
}

// 4 spp in K = 4 quarters: run on half A, each of its halves holds one sample per pixel, so
// per-buffer variances are 0 ("not measured"); with the whole's variance missing as well, the
// two-buffer estimate must stand in.
TEST(Rdfc, OneSamplePerBufferUsesTheTwoBufferVariance) {
  test::SyntheticSceneOptions o;
  o.samplesPerSubBuffer = 1;
  const test::SyntheticScene scene = scene64(o);
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
  test::SyntheticSceneOptions o;
  o.width = 150;  // several tiles per row and column
  o.height = 40;
  const test::SyntheticScene scene = test::makeSyntheticScene(o);
  const Rdfc rdfc;
  EXPECT_TRUE(test::bitIdentical(test::runWithThreads(rdfc, scene.fullInput(), 1),
                                 test::runWithThreads(rdfc, scene.fullInput(), 2)));
}

TEST(Rdfc, NonFiniteInputsGiveFiniteOutputs) {
  const test::SyntheticScene scene = scene64();
  DenoiseInput input = scene.fullInput();
  const float nan = std::numeric_limits<float>::quiet_NaN(),
              inf = std::numeric_limits<float>::infinity();
  SubBuffer& a = (*input.halves)[0];
  for (int x = 0; x < 64; ++x) {
    input.whole.albedo.varianceOfMean(x, 10, 1) = nan;
    input.whole.visibility.varianceOfMean(x, 11, 0) = nan;
    input.whole.depth.mean(x, 20, 0) = inf;
    a.normal.mean(x, 30, 0) = nan;
  }
  a.color.mean(5, 5, 0) = nan;
  (*input.halves)[1].color.mean(6, 6, 2) = inf;
  input.whole.color.varianceOfMean(7, 7, 1) = inf;
  input.whole.color.varianceOfMean(8, 8, 1) = -1.0f;
  input.whole.color.mean(9, 9, 0) = nan;
  EXPECT_EQ(test::firstNonFinite(Rdfc().run(input)), "");
}

TEST(Rdfc, NeedsHalves) {
  const test::SyntheticScene scene = scene64();
  DenoiseInput input = scene.fullInput();
  input.halves.reset();
  EXPECT_THROW(Rdfc().run(input), Error);
}

TEST(Rdfc, RegistryAndParameters) {
  const auto rdfc = createDenoiser("rdfc:r=6:kc=0.5:kf=0.7:tau=0.002:rescale=false");
  EXPECT_EQ(rdfc->name(), "rdfc");
  EXPECT_TRUE(rdfc->requirements().features);
  EXPECT_TRUE(rdfc->requirements().halves);
  EXPECT_THROW(createDenoiser("rdfc:r=0"), Error);
  EXPECT_THROW(createDenoiser("rdfc:kc=-1"), Error);
  EXPECT_THROW(createDenoiser("rdfc:tau=nan"), Error);
  EXPECT_THROW(createDenoiser("rdfc:k=1"), Error);
  const test::SyntheticScene scene = scene64();
  const Image out = rdfc->run(scene.fullInput());
  EXPECT_LT(relMse(out, scene.truth) * 4, relMse(scene.fullInput().whole.color.mean, scene.truth));
}

}  // namespace
}  // namespace chorus
