// SBF (Li et al. 2012) on the synthetic scene: error reduction, sharp feature edges, constant
// and black images, all three buffer parts, determinism, non-finite inputs and the Tungsten
// peer buffers.
#include "denoise/base/sbf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>

#include "denoise/base/registry.h"
#include "denoise/buffers/tungsten_dir.h"
#include "denoise/image/exr_io.h"
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

// Documented in README.md (SBF): measured relMSE 0.053 → 0.0041 (13×) at 64×64, 16 spp.
constexpr double kMinImprovement = 6.0;

TEST(Sbf, ReducesRelMseOnTheSyntheticScene) {
  const test::SyntheticScene scene = scene64();
  const DenoiseInput input = scene.fullInput();
  const Image out = Sbf().run(input);
  const double noisy = relMse(input.whole.color.mean, scene.truth);
  const double denoised = relMse(out, scene.truth);
  std::cout << "relMSE noisy " << noisy << ", sbf " << denoised << "\n";
  EXPECT_LT(denoised * kMinImprovement, noisy);
}

TEST(Sbf, KeepsFeatureEdgesSharp) {
  const test::SyntheticScene scene = scene64();
  const DenoiseInput input = scene.fullInput();
  const Image out = Sbf().run(input);
  const double noisyEdges = test::maskedRelMse(input.whole.color.mean, scene.truth, scene.edgeMask);
  const double edges = test::maskedRelMse(out, scene.truth, scene.edgeMask);
  // A feature-blind blur of SBF's typical width smears the edges.
  const double blurEdges = test::maskedRelMse(test::gaussianBlur(input.whole.color.mean, 2.0f),
                                              scene.truth, scene.edgeMask);
  std::cout << "edge relMSE noisy " << noisyEdges << ", sbf " << edges << ", blur " << blurEdges
            << " over " << scene.edgePixelCount << " pixels\n";
  EXPECT_LT(edges * 3.0, noisyEdges);
  EXPECT_LT(edges * 3.0, blurEdges);
}

TEST(Sbf, SelectsWideFiltersInFlatRegions) {
  const test::SyntheticScene scene = scene64();
  const SbfResult result = runSbf(scene.fullInput().whole, SbfParams{});
  int flat = 0, wide = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      if (scene.edgeMask(x, y, 0) > 0) continue;
      ++flat;
      wide += result.selection(x, y, 0) >= 3 ? 1 : 0;  // σ_s ≥ 4
    }
  EXPECT_GT(wide, flat / 2) << wide << " of " << flat;
}

TEST(Sbf, ConstantStaysConstantAndBlackStaysBlack) {
  for (const std::array<float, 3> value :
       {std::array<float, 3>{0.3f, 1.5f, 7.0f}, std::array<float, 3>{0.0f, 0.0f, 0.0f}}) {
    test::SyntheticSceneOptions o;
    o.constantColor = value;
    const test::SyntheticScene scene = scene64(o);
    const Image out = Sbf().run(scene.fullInput());
    EXPECT_LE(test::maxDeviationFrom(out, value.data()), 1e-5f * value[2]) << value[2];
  }
}

TEST(Sbf, RunsOnEveryBufferPart) {
  const test::SyntheticScene scene = scene64();
  for (BufferPart part : {BufferPart::HalfA, BufferPart::HalfB, BufferPart::Full}) {
    DenoiseInput input = scene.buffers.input(part);
    input.halves.reset();  // SBF needs no halves
    const Image out = Sbf().run(input);
    ASSERT_EQ(out.width(), 64);
    ASSERT_EQ(out.channels(), 3);
    EXPECT_EQ(test::firstNonFinite(out), "");
    EXPECT_LT(relMse(out, scene.truth) * 5, relMse(input.whole.color.mean, scene.truth))
        << partName(part);
  }
}

TEST(Sbf, DeterministicForAnyThreadCount) {
  test::SyntheticSceneOptions o;
  o.width = 150;  // two tiles per row
  o.height = 40;
  const test::SyntheticScene scene = test::makeSyntheticScene(o);
  const Sbf sbf;
  EXPECT_TRUE(test::bitIdentical(test::runWithThreads(sbf, scene.fullInput(), 1),
                                 test::runWithThreads(sbf, scene.fullInput(), 2)));
}

TEST(Sbf, NonFiniteInputsGiveFiniteOutputs) {
  const test::SyntheticScene scene = scene64();
  DenoiseInput input = scene.fullInput();
  const float nan = std::numeric_limits<float>::quiet_NaN(),
              inf = std::numeric_limits<float>::infinity();
  for (int x = 0; x < 64; ++x) {
    input.whole.albedo.varianceOfMean(x, 10, 1) = nan;
    input.whole.depth.mean(x, 20, 0) = inf;
    input.whole.depth.varianceOfMean(x, 20, 0) = nan;
  }
  input.whole.color.mean(5, 5, 0) = nan;
  input.whole.color.varianceOfMean(6, 6, 1) = inf;
  input.whole.normal.mean(7, 7, 2) = -inf;
  input.whole.sampleCount(8, 8, 0) = 0;
  EXPECT_EQ(test::firstNonFinite(Sbf().run(input)), "");
}

TEST(Sbf, RegistryAndParameters) {
  const auto sbf = createDenoiser("sbf:sigmaS=0/2/4:sigmaMse=4:sigmaN=1");
  EXPECT_EQ(sbf->name(), "sbf");
  EXPECT_TRUE(sbf->requirements().features);
  EXPECT_FALSE(sbf->requirements().halves);
  EXPECT_THROW(createDenoiser("sbf:sigmaS=1/x"), Error);
  EXPECT_THROW(createDenoiser("sbf:sigmaS="), Error);
  EXPECT_THROW(createDenoiser("sbf:sigmaMse=-1"), Error);
  EXPECT_THROW(createDenoiser("sbf:sigma=1"), Error);
  // Only the identity candidate: the output is the input.
  const test::SyntheticScene scene = scene64();
  const Image out = createDenoiser("sbf:sigmaS=0")->run(scene.fullInput());
  EXPECT_TRUE(test::bitIdentical(out, scene.fullInput().whole.color.mean));
}

TEST(Sbf, TungstenPeerBuffers) {
  CHORUS_REQUIRE_SHARED(shared);
  for (const char* name : {"room", "glossy"}) {
    const auto dir = shared / "peers/tungsten-nfor" / name;
    const DenoiseInput input = readTungstenDirectory(dir / "spp4");
    const Image reference = readExrLayer(dir / "reference.exr");
    const Image out = Sbf().run(input);
    ASSERT_EQ(test::firstNonFinite(out), "") << name;
    const double noisy = relMse(input.whole.color.mean, reference),
                 denoised = relMse(out, reference);
    std::cout << name << " spp4: relMSE noisy " << noisy << ", sbf " << denoised << "\n";
    EXPECT_LT(denoised * 2, noisy) << name;
  }
}

}  // namespace
}  // namespace chorus
