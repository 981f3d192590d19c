// Joint NL-means on the synthetic scene: error reduction, sharp feature edges, constant and black
// images, all buffer parts with and without halves, one sample per buffer, determinism,
// non-finite inputs, parameters.
#include "denoise/base/joint_nlmeans.h"

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

// Documented in README.md (joint NL-means): measured relMSE 0.053 → 0.0049 (11×) at 64×64,
// 16 spp, cross-filtered halves.
constexpr double kMinImprovement = 6.0;

TEST(JointNlMeans, ReducesRelMseOnTheSyntheticScene) {
  const test::SyntheticScene scene = scene64();
  const DenoiseInput input = scene.fullInput();
  const double noisy = relMse(input.whole.color.mean, scene.truth);
  const double denoised = relMse(JointNlMeans().run(input), scene.truth);
  std::cout << "relMSE noisy " << noisy << ", jnlm " << denoised << "\n";
  EXPECT_LT(denoised * kMinImprovement, noisy);
}

TEST(JointNlMeans, KeepsFeatureEdgesSharp) {
  const test::SyntheticScene scene = scene64();
  const DenoiseInput input = scene.fullInput();
  const Image out = JointNlMeans().run(input);
  const double noisyEdges = test::maskedRelMse(input.whole.color.mean, scene.truth, scene.edgeMask);
  const double edges = test::maskedRelMse(out, scene.truth, scene.edgeMask);
  const double blurEdges = test::maskedRelMse(test::gaussianBlur(input.whole.color.mean, 1.5f),
                                              scene.truth, scene.edgeMask);
  std::cout << "edge relMSE noisy " << noisyEdges << ", jnlm " << edges << ", blur " << blurEdges
            << "\n";
  EXPECT_LT(edges * 3.0, noisyEdges);
  EXPECT_LT(edges * 10.0, blurEdges);
}

TEST(JointNlMeans, ConstantStaysConstantAndBlackStaysBlack) {
  for (const std::array<float, 3> value :
       {std::array<float, 3>{0.3f, 1.5f, 7.0f}, std::array<float, 3>{0.0f, 0.0f, 0.0f}}) {
    test::SyntheticSceneOptions o;
    o.constantColor = value;
    const test::SyntheticScene scene = scene64(o);
    DenoiseInput input = scene.fullInput();
    EXPECT_LE(test::maxDeviationFrom(JointNlMeans().run(input), value.data()), 1e-5f * value[2]);
    input.halves.reset();
    EXPECT_LE(test::maxDeviationFrom(JointNlMeans().run(input), value.data()), 1e-5f * value[2]);
  }
}

TEST(JointNlMeans, RunsOnEveryBufferPartWithAndWithoutHalves) {
  const test::SyntheticScene scene = scene64();
  for (BufferPart part : {BufferPart::HalfA, BufferPart::HalfB, BufferPart::Full})
    for (bool halves : {true, false}) {
      DenoiseInput input = scene.buffers.input(part);
      if (!halves) input.halves.reset();
      const Image out = JointNlMeans().run(input);
      ASSERT_EQ(out.width(), 64);
      ASSERT_EQ(out.channels(), 3);
      EXPECT_EQ(test::firstNonFinite(out), "");
      EXPECT_LT(relMse(out, scene.truth) * 4, relMse(input.whole.color.mean, scene.truth))
          << partName(part) << (halves ? " with halves" : " without halves");
    }
}

// 4 spp in K = 4 quarters, run on half A: each half holds one sample, so its own variance does
// not exist and the two-buffer estimate stands in.
TEST(JointNlMeans, OneSamplePerBuffer) {
  test::SyntheticSceneOptions o;
  o.samplesPerSubBuffer = 1;
  const test::SyntheticScene scene = scene64(o);
  const DenoiseInput input = scene.buffers.input(BufferPart::HalfA);
  const Image out = JointNlMeans().run(input);
  ASSERT_EQ(test::firstNonFinite(out), "");
  const double noisy = relMse(input.whole.color.mean, scene.truth);
  const double denoised = relMse(out, scene.truth);
  std::cout << "2 spp: relMSE noisy " << noisy << ", jnlm " << denoised << "\n";
  EXPECT_LT(denoised * 3, noisy);
}

TEST(JointNlMeans, DeterministicForAnyThreadCount) {
  test::SyntheticSceneOptions o;
  o.width = 150;
  o.height = 40;
  const test::SyntheticScene scene = test::makeSyntheticScene(o);
  const JointNlMeans jnlm;
  EXPECT_TRUE(test::bitIdentical(test::runWithThreads(jnlm, scene.fullInput(), 1),
                                 test::runWithThreads(jnlm, scene.fullInput(), 2)));
}

TEST(JointNlMeans, NonFiniteInputsGiveFiniteOutputs) {
  const test::SyntheticScene scene = scene64();
  const float nan = std::numeric_limits<float>::quiet_NaN(),
              inf = std::numeric_limits<float>::infinity();
  for (bool halves : {true, false}) {
    DenoiseInput input = scene.fullInput();
    if (!halves) input.halves.reset();
    for (int x = 0; x < 64; ++x) {
      input.whole.albedo.varianceOfMean(x, 10, 1) = nan;
      input.whole.depth.mean(x, 20, 0) = inf;
      input.whole.normal.mean(x, 30, 2) = nan;
    }
    input.whole.color.mean(5, 5, 0) = nan;
    input.whole.color.varianceOfMean(6, 6, 1) = inf;
    if (halves) {
      (*input.halves)[0].color.mean(7, 7, 2) = -inf;
      (*input.halves)[1].color.varianceOfMean(8, 8, 0) = nan;
    }
    EXPECT_EQ(test::firstNonFinite(JointNlMeans().run(input)), "") << halves;
  }
}

TEST(JointNlMeans, RegistryAndParameters) {
  const auto jnlm = createDenoiser("jnlm:r=3:f=1:k=0.5:kf=0.7:tau=0.002:refineFeatures=true");
  EXPECT_EQ(jnlm->name(), "jnlm");
  EXPECT_TRUE(jnlm->requirements().features);
  EXPECT_FALSE(jnlm->requirements().halves);
  EXPECT_THROW(createDenoiser("jnlm:r=0"), Error);
  EXPECT_THROW(createDenoiser("jnlm:f=-1"), Error);
  EXPECT_THROW(createDenoiser("jnlm:k=0"), Error);
  EXPECT_THROW(createDenoiser("jnlm:window=3"), Error);
  const test::SyntheticScene scene = scene64();
  const Image out = jnlm->run(scene.fullInput());
  EXPECT_LT(relMse(out, scene.truth) * 4, relMse(scene.fullInput().whole.color.mean, scene.truth));
}

}  // namespace
}  // namespace chorus
