// Joint NL-means on the synthetic scene: error reduction, sharp feature edges, constant and black
// images, all buffer parts with and without halves, one sample per buffer, determinism,
// non-finite inputs, parameters.
#include "denoise/base/jnlm/joint_nlmeans.h"

#include <gtest/gtest.h>

#include <iostream>

#include "denoise/metrics/metrics.h"
#include "tests/support/denoiser_checks.h"
#include "tests/support/synthetic_scene.h"

namespace chorus {
namespace {

// Documented in docs/members/rdfc-jnlm.md (joint NL-means): measured relMSE 0.053 → 0.0049 (11×) at
// 64×64, 16 spp, cross-filtered halves.
constexpr double kMinImprovement = 6.0;

TEST(JointNlMeans, ReducesRelMseOnTheSyntheticScene) {
  test::expectReducesRelMse(JointNlMeans(), kMinImprovement);
}

TEST(JointNlMeans, KeepsFeatureEdgesSharp) {
  test::expectKeepsFeatureEdgesSharp(JointNlMeans(), 3.0, 1.5f, 10.0);
}

TEST(JointNlMeans, ConstantStaysConstantAndBlackStaysBlack) {
  for (bool halves : {true, false}) {
    const std::string name = halves ? "jnlm with halves" : "jnlm without halves";
    const test::DenoiseFn run = [halves](DenoiseInput input) {
      if (!halves) input.halves.reset();
      return JointNlMeans().run(input);
    };
    test::expectConstantStaysConstant(name, run, 1e-5f);
    test::expectBlackStaysBlack(name, run);
  }
}

TEST(JointNlMeans, RunsOnEveryBufferPartWithAndWithoutHalves) {
  for (bool halves : {true, false}) test::expectRunsOnEveryBufferPart(JointNlMeans(), halves, 4);
}

// 4 spp in K = 4 quarters, run on half A: each half holds one sample, so its own variance does
// not exist and the two-buffer estimate stands in.
TEST(JointNlMeans, OneSamplePerBuffer) {
  test::SyntheticSceneOptions o;
  o.samplesPerSubBuffer = 1;
  const test::SyntheticScene scene = test::syntheticScene(64, o);
  const DenoiseInput input = scene.buffers.input(BufferPart::HalfA);
  const Image out = JointNlMeans().run(input);
  ASSERT_EQ(test::firstNonFinite(out), "");
  const double noisy = relMse(input.whole.color.mean, scene.truth);
  const double denoised = relMse(out, scene.truth);
  std::cout << "2 spp: relMSE noisy " << noisy << ", jnlm " << denoised << "\n";
  EXPECT_LT(denoised * 3, noisy);
}

TEST(JointNlMeans, DeterministicForAnyThreadCount) {
  test::expectDeterministicAcrossThreads(JointNlMeans(), test::syntheticScene(150, 40));
}

TEST(JointNlMeans, NonFiniteInputsGiveFiniteOutputs) {
  const test::SyntheticScene scene = test::syntheticScene(64);
  for (bool halves : {true, false}) {
    SCOPED_TRACE(halves ? "with halves" : "without halves");
    test::expectFiniteOnNonFiniteInputs(JointNlMeans(), scene, [halves](DenoiseInput& input) {
      if (!halves) input.halves.reset();
      for (int x = 0; x < 64; ++x) {
        input.whole.albedo.varianceOfMean(x, 10, 1) = test::kNan;
        input.whole.depth.mean(x, 20, 0) = test::kInf;
        input.whole.normal.mean(x, 30, 2) = test::kNan;
      }
      input.whole.color.mean(5, 5, 0) = test::kNan;
      input.whole.color.varianceOfMean(6, 6, 1) = test::kInf;
      if (halves) {
        (*input.halves)[0].color.mean(7, 7, 2) = -test::kInf;
        (*input.halves)[1].color.varianceOfMean(8, 8, 0) = test::kNan;
      }
    });
  }
}

TEST(JointNlMeans, RegistryAndParameters) {
  const auto jnlm = test::expectCreates("jnlm:r=3:f=1:k=0.5:kf=0.7:tau=0.002:refineFeatures=true",
                                        "jnlm", {.features = true, .halves = false});
  test::expectRejected({"jnlm:r=0", "jnlm:f=-1", "jnlm:k=0", "jnlm:window=3"});
  test::expectReducesRelMse(*jnlm, 4);
}

}  // namespace
}  // namespace chorus
