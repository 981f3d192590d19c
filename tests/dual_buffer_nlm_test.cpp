// Dual-buffer NL-means (Rousselle et al. 2012) on the synthetic scene: error reduction, every
// buffer part including single-sample quarters (variance fallback), constant and black images,
// determinism, non-finite inputs, registry.
#include "denoise/base/nlm/dual_buffer_nlm.h"

#include <gtest/gtest.h>

#include <iostream>

#include "denoise/metrics/metrics.h"
#include "tests/support/denoiser_checks.h"
#include "tests/support/synthetic_scene.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

TEST(DualBufferNlm, ReducesRelMseOnEveryBufferPart) {
  // Measured: 1.5–2.5× with one sample per quarter (colour-only weights from a one-sample
  // guide), 4–5× with four.
  test::expectReducesRelMseOnEveryBufferPart(DualBufferNlMeans(), 1.4, 3.0);
}

TEST(DualBufferNlm, RandomSamplingPathAlsoDenoises) {
  // The synthetic scene samples independently at random, the case of sampling=random.
  const test::SyntheticScene scene = test::syntheticScene(64);
  const DenoiseInput input = scene.fullInput();
  DualBufferNlMeansParams params;
  params.sampling = "random";
  const Image out = DualBufferNlMeans(params).run(input);
  EXPECT_LT(relMse(out, scene.truth) * 4, relMse(input.whole.color.mean, scene.truth));
}

TEST(DualBufferNlm, ConstantStaysConstantAndBlackStaysBlack) {
  test::expectConstantStaysConstant(DualBufferNlMeans(), 1e-5f);
  test::expectBlackStaysBlack(DualBufferNlMeans());
}

TEST(DualBufferNlm, DeterministicForAnyThreadCount) {
  // 150 wide: three filter tiles per row.
  test::expectDeterministicAcrossThreads(DualBufferNlMeans(), test::syntheticScene(150, 40));
}

TEST(DualBufferNlm, NonFiniteAndExtremeInputsGiveFiniteOutputs) {
  test::SyntheticSceneOptions o;
  o.fireflyProbability = 0.02f;
  o.fireflyScale = 1e5f;
  const test::SyntheticScene scene = test::syntheticScene(64, o);
  test::expectFiniteOnNonFiniteInputs(DualBufferNlMeans(), scene, [](DenoiseInput& input) {
    SubBuffer &a = input.halves->at(0), &b = input.halves->at(1);
    for (int x = 0; x < 64; ++x) {
      a.color.varianceOfMean(x, 10, 1) = test::kNan;
      b.color.varianceOfMean(x, 11, 1) = test::kInf;
      a.sampleCount(x, 12, 0) = 0;
    }
    a.color.mean(5, 5, 0) = test::kNan;
    a.color.mean(6, 5, 1) = test::kInf;
    b.color.mean(30, 30, 0) = 1e30f;
  });
}

TEST(DualBufferNlm, RequirementsRegistryAndParameters) {
  test::expectCreates("nlm:r=7:k=0.5:alpha=0.5:sampling=random", "nlm",
                      {.features = false, .halves = true});
  test::expectRejected({"nlm:window=3", "nlm:k=-1", "nlm:sampling=sobol"});
  test::expectNeedsHalves(DualBufferNlMeans());
}

}  // namespace
}  // namespace chorus
