// Dual-buffer NL-means (Rousselle et al. 2012) on the synthetic scene: error reduction, every
// buffer part including single-sample quarters (variance fallback), constant and black images,
// determinism, non-finite inputs, registry.
#include "denoise/base/dual_buffer_nlm.h"

#include <gtest/gtest.h>

#include <iostream>
#include <limits>

#include "denoise/base/registry.h"
#include "denoise/metrics/metrics.h"
#include "denoise/util/error.h"
#include "tests/support/denoiser_checks.h"
#include "tests/support/synthetic_scene.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

test::SyntheticScene scene64(const test::SyntheticSceneOptions& extra = {}) {
  test::SyntheticSceneOptions o = extra;
  o.width = o.height = 64;
  return test::makeSyntheticScene(o);
}

TEST(DualBufferNlm, ReducesRelMseOnEveryBufferPart) {
  for (int samples : {1, 4}) {  // 1: each quarter holds one sample (4 spp in total)
    test::SyntheticSceneOptions o;
    o.samplesPerSubBuffer = samples;
    const test::SyntheticScene scene = scene64(o);
    for (BufferPart part : {BufferPart::HalfA, BufferPart::HalfB, BufferPart::Full}) {
      const DenoiseInput input = scene.buffers.input(part);
      const Image out = DualBufferNlMeans().run(input);
      ASSERT_EQ(test::firstNonFinite(out), "") << partName(part);
      const double noisy = relMse(input.whole.color.mean, scene.truth);
      const double denoised = relMse(out, scene.truth);
      std::cout << samples << " sample(s) per quarter, " << partName(part) << ": relMSE noisy "
                << noisy << ", nlm " << denoised << "\n";
      // Measured: 1.5–2.5× with one sample per quarter (colour-only weights from a one-sample
      // guide), 4–5× with four.
      EXPECT_LT(denoised * (samples == 1 ? 1.4 : 3.0), noisy) << partName(part) << ", " << samples;
    }
  }
}

TEST(DualBufferNlm, RandomSamplingPathAlsoDenoises) {
  // The synthetic scene samples independently at random, the case of sampling=random.
  const test::SyntheticScene scene = scene64();
  const DenoiseInput input = scene.fullInput();
  DualBufferNlMeansParams params;
  params.sampling = "random";
  const Image out = DualBufferNlMeans(params).run(input);
  EXPECT_LT(relMse(out, scene.truth) * 4, relMse(input.whole.color.mean, scene.truth));
}

TEST(DualBufferNlm, ConstantStaysConstantAndBlackStaysBlack) {
  for (const std::array<float, 3> value :
       {std::array<float, 3>{0.3f, 1.5f, 7.0f}, std::array<float, 3>{0.0f, 0.0f, 0.0f}}) {
    test::SyntheticSceneOptions o;
    o.constantColor = value;
    const test::SyntheticScene scene = scene64(o);
    const Image out = DualBufferNlMeans().run(scene.fullInput());
    EXPECT_LE(test::maxDeviationFrom(out, value.data()), 1e-5f * value[2]) << value[2];
  }
}

TEST(DualBufferNlm, DeterministicForAnyThreadCount) {
  test::SyntheticSceneOptions o;
  o.width = 150;  // three filter tiles per row
  o.height = 40;
  const test::SyntheticScene scene = test::makeSyntheticScene(o);
  const DualBufferNlMeans nlm;
  EXPECT_TRUE(test::bitIdentical(test::runWithThreads(nlm, scene.fullInput(), 1),
                                 test::runWithThreads(nlm, scene.fullInput(), 2)));
}

TEST(DualBufferNlm, NonFiniteAndExtremeInputsGiveFiniteOutputs) {
  test::SyntheticSceneOptions o;
  o.fireflyProbability = 0.02f;
  o.fireflyScale = 1e5f;
  const test::SyntheticScene scene = scene64(o);
  DenoiseInput input = scene.fullInput();
  const float nan = std::numeric_limits<float>::quiet_NaN(),
              inf = std::numeric_limits<float>::infinity();
  SubBuffer& a = input.halves->at(0);
  for (int x = 0; x < 64; ++x) {
    a.color.varianceOfMean(x, 10, 1) = nan;
    input.halves->at(1).color.varianceOfMean(x, 11, 1) = inf;
    a.sampleCount(x, 12, 0) = 0;
  }
  a.color.mean(5, 5, 0) = nan;
  a.color.mean(6, 5, 1) = inf;
  input.halves->at(1).color.mean(30, 30, 0) = 1e30f;
  EXPECT_EQ(test::firstNonFinite(DualBufferNlMeans().run(input)), "");
}

TEST(DualBufferNlm, RequirementsRegistryAndParameters) {
  const auto nlm = createDenoiser("nlm:r=7:k=0.5:alpha=0.5:sampling=random");
  EXPECT_EQ(nlm->name(), "nlm");
  EXPECT_FALSE(nlm->requirements().features);
  EXPECT_TRUE(nlm->requirements().halves);
  EXPECT_THROW(createDenoiser("nlm:window=3"), Error);
  EXPECT_THROW(createDenoiser("nlm:k=-1"), Error);
  EXPECT_THROW(createDenoiser("nlm:sampling=sobol"), Error);
  const test::SyntheticScene scene = scene64();
  DenoiseInput input = scene.fullInput();
  input.halves.reset();
  EXPECT_THROW(DualBufferNlMeans().run(input), Error);
}

}  // namespace
}  // namespace chorus
