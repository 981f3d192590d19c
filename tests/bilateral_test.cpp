// The `bilateral` denoiser (joint cross-bilateral with a colour range term) on the synthetic
// scene: error reduction, sharp feature edges, constant and black images, determinism,
// non-finite inputs, parameters, and that it is one candidate of the shared filter.
#include "denoise/base/bilateral.h"

#include <gtest/gtest.h>

#include <iostream>
#include <limits>

#include "denoise/base/cross_bilateral.h"
#include "denoise/base/input_planes.h"
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

// Documented in README.md (bilateral): measured relMSE 0.053 → 0.0049 (11×) at 64×64, 16 spp.
constexpr double kMinImprovement = 5.0;

TEST(Bilateral, ReducesRelMseAndKeepsEdges) {
  const test::SyntheticScene scene = scene64();
  const DenoiseInput input = scene.fullInput();
  const Image out = Bilateral().run(input);
  const double noisy = relMse(input.whole.color.mean, scene.truth);
  const double denoised = relMse(out, scene.truth);
  const double noisyEdges = test::maskedRelMse(input.whole.color.mean, scene.truth, scene.edgeMask);
  const double edges = test::maskedRelMse(out, scene.truth, scene.edgeMask);
  std::cout << "relMSE noisy " << noisy << ", bilateral " << denoised << "; edges noisy "
            << noisyEdges << ", bilateral " << edges << "\n";
  EXPECT_LT(denoised * kMinImprovement, noisy);
  EXPECT_LT(edges * 2, noisyEdges);
}

TEST(Bilateral, IsTheSharedFilterWithTheColourTerm) {
  const test::SyntheticScene scene = scene64();
  const SubBuffer& b = scene.fullInput().whole;
  const float sigmaS[] = {4.0f};
  const auto expected =
      crossBilateralCandidates(sanitizedMean(b.color), sanitizedVarianceOfMean(b.color),
                               makeFeatureGuide(b, {}), sigmaS, 3.0f);
  EXPECT_TRUE(
      test::bitIdentical(Bilateral().run(scene.fullInput()), expected[0].filtered.toImage()));
}

TEST(Bilateral, ConstantStaysConstantAndBlackStaysBlack) {
  for (const std::array<float, 3> value :
       {std::array<float, 3>{0.3f, 1.5f, 7.0f}, std::array<float, 3>{0.0f, 0.0f, 0.0f}}) {
    test::SyntheticSceneOptions o;
    o.constantColor = value;
    const Image out = Bilateral().run(scene64(o).fullInput());
    EXPECT_LE(test::maxDeviationFrom(out, value.data()), 1e-5f * value[2]) << value[2];
  }
}

TEST(Bilateral, DeterministicAndFinite) {
  test::SyntheticSceneOptions o;
  o.width = 150;
  o.height = 30;
  const test::SyntheticScene scene = test::makeSyntheticScene(o);
  const Bilateral bilateral;
  EXPECT_TRUE(test::bitIdentical(test::runWithThreads(bilateral, scene.fullInput(), 1),
                                 test::runWithThreads(bilateral, scene.fullInput(), 2)));
  DenoiseInput input = scene.fullInput();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  input.whole.color.mean(3, 3, 1) = nan;
  input.whole.color.varianceOfMean(4, 3, 1) = nan;
  input.whole.normal.varianceOfMean(5, 3, 0) = nan;
  input.whole.depth.mean(6, 3, 0) = std::numeric_limits<float>::infinity();
  EXPECT_EQ(test::firstNonFinite(bilateral.run(input)), "");
}

TEST(Bilateral, RegistryAndParameters) {
  const auto bilateral = createDenoiser("bilateral:sigmaS=2:sigmaC=0:sigmaD=0");
  EXPECT_EQ(bilateral->name(), "bilateral");
  EXPECT_TRUE(bilateral->requirements().features);
  EXPECT_FALSE(bilateral->requirements().halves);
  EXPECT_THROW(createDenoiser("bilateral:sigmaS=-1"), Error);
  EXPECT_THROW(createDenoiser("bilateral:sigmaC=nan"), Error);
  EXPECT_THROW(createDenoiser("bilateral:k=1"), Error);
  const test::SyntheticScene scene = scene64();
  EXPECT_TRUE(test::bitIdentical(createDenoiser("bilateral:sigmaS=0")->run(scene.fullInput()),
                                 scene.fullInput().whole.color.mean));
}

}  // namespace
}  // namespace chorus
