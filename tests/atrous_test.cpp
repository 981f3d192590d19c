// À-trous (Dammertz et al. 2010, SVGF weights) on the synthetic scene: error reduction, sharp
// feature edges, constant and black images, all buffer parts, determinism, agreement of the
// SIMD kernels with the scalar one, non-finite inputs and the Tungsten peer buffers.
#include "denoise/base/atrous.h"

#include <gtest/gtest.h>

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

// Documented in README.md (à-trous): measured relMSE 0.053 → 0.0054 (9.8×) at 64×64, 16 spp.
constexpr double kMinImprovement = 5.0;

TEST(Atrous, ReducesRelMseOnTheSyntheticScene) {
  const test::SyntheticScene scene = scene64();
  const DenoiseInput input = scene.fullInput();
  const double noisy = relMse(input.whole.color.mean, scene.truth);
  const double denoised = relMse(Atrous().run(input), scene.truth);
  std::cout << "relMSE noisy " << noisy << ", atrous " << denoised << "\n";
  EXPECT_LT(denoised * kMinImprovement, noisy);
}

TEST(Atrous, DemodulationHelpsOnTheTexturedScene) {
  // The default (demodulate = true) was chosen by this measurement; see README.md.
  const test::SyntheticScene scene = scene64();
  AtrousParams plain;
  plain.demodulate = false;
  const double withAlbedo = relMse(Atrous().run(scene.fullInput()), scene.truth);
  const double without = relMse(Atrous(plain).run(scene.fullInput()), scene.truth);
  std::cout << "relMSE demodulated " << withAlbedo << ", not demodulated " << without << "\n";
  EXPECT_LT(withAlbedo * 2, without);
}

TEST(Atrous, KeepsFeatureEdgesSharp) {
  const test::SyntheticScene scene = scene64();
  const DenoiseInput input = scene.fullInput();
  const Image out = Atrous().run(input);
  const double noisyEdges = test::maskedRelMse(input.whole.color.mean, scene.truth, scene.edgeMask);
  const double edges = test::maskedRelMse(out, scene.truth, scene.edgeMask);
  const double blurEdges = test::maskedRelMse(test::gaussianBlur(input.whole.color.mean, 2.0f),
                                              scene.truth, scene.edgeMask);
  std::cout << "edge relMSE noisy " << noisyEdges << ", atrous " << edges << ", blur " << blurEdges
            << "\n";
  EXPECT_LT(edges * 2.0, noisyEdges);
  EXPECT_LT(edges * 10.0, blurEdges);
}

TEST(Atrous, ConstantStaysConstantAndBlackStaysBlack) {
  for (const std::array<float, 3> value :
       {std::array<float, 3>{0.3f, 1.5f, 7.0f}, std::array<float, 3>{0.0f, 0.0f, 0.0f}}) {
    test::SyntheticSceneOptions o;
    o.constantColor = value;
    const test::SyntheticScene scene = scene64(o);
    for (bool demodulate : {true, false}) {
      AtrousParams params;
      params.demodulate = demodulate;
      const Image out = Atrous(params).run(scene.fullInput());
      EXPECT_LE(test::maxDeviationFrom(out, value.data()), 1e-5f * value[2])
          << value[2] << " demodulate " << demodulate;
    }
  }
}

TEST(Atrous, RunsOnEveryBufferPart) {
  const test::SyntheticScene scene = scene64();
  for (BufferPart part : {BufferPart::HalfA, BufferPart::HalfB, BufferPart::Full}) {
    DenoiseInput input = scene.buffers.input(part);
    input.halves.reset();
    const Image out = Atrous().run(input);
    ASSERT_EQ(out.width(), 64);
    EXPECT_EQ(test::firstNonFinite(out), "");
    EXPECT_LT(relMse(out, scene.truth) * 4, relMse(input.whole.color.mean, scene.truth))
        << partName(part);
  }
}

// Widths that leave interior pixels for every vector width and odd remainders.
test::SyntheticScene oddScene(bool unknownNormals) {
  test::SyntheticSceneOptions o;
  o.width = 157;
  o.height = 41;
  o.featureNoise = 0.05f;
  test::SyntheticScene scene = test::makeSyntheticScene(o);
  if (unknownNormals)
    for (int k = 0; k < scene.buffers.splitCount(); ++k)
      for (int x = 10; x < 60; ++x)
        for (int c = 0; c < 3; ++c) scene.buffers.sub(k).normal.mean(x, 7, c) = 0.0f;
  return scene;
}

TEST(Atrous, DeterministicForAnyThreadCount) {
  const test::SyntheticScene scene = oddScene(false);
  const Atrous atrous;
  EXPECT_TRUE(test::bitIdentical(test::runWithThreads(atrous, scene.fullInput(), 1),
                                 test::runWithThreads(atrous, scene.fullInput(), 2)));
}

TEST(Atrous, VectorKernelsMatchTheScalarKernelBitForBit) {
  for (bool unknownNormals : {false, true})
    for (float sigmaN : {128.0f, 0.0f, 1.0f}) {
      const test::SyntheticScene scene = oddScene(unknownNormals);
      AtrousParams params;
      params.sigmaN = sigmaN;
      const SubBuffer& b = scene.buffers.part(BufferPart::Full);
      const Image scalar = runAtrous(b, params, AtrousKernelPath::Scalar);
      EXPECT_TRUE(test::bitIdentical(scalar, runAtrous(b, params, AtrousKernelPath::Sse2)))
          << "SSE2, σn " << sigmaN << ", unknown normals " << unknownNormals;
      EXPECT_TRUE(test::bitIdentical(scalar, runAtrous(b, params, AtrousKernelPath::Avx2)))
          << "AVX2 (or SSE2), σn " << sigmaN << ", unknown normals " << unknownNormals;
      EXPECT_TRUE(test::bitIdentical(scalar, runAtrous(b, params, AtrousKernelPath::Widest)))
          << "widest, σn " << sigmaN << ", unknown normals " << unknownNormals;
    }
}

// A light seen directly, recorded as in the chorus renderer: black albedo, bright colour, and a
// row of pixels mixing light and wall samples (mid albedo, huge variance) below it.
TEST(Atrous, DemodulationDoesNotLeakEmittersWithBlackAlbedo) {
  const test::SyntheticScene scene = scene64();
  DenoiseInput input = scene.fullInput();
  Image truth = scene.truth;
  SubBuffer& b = input.whole;
  for (int y = 10; y <= 20; ++y)
    for (int x = 20; x < 40; ++x)
      for (int c = 0; c < 3; ++c) {
        const bool mixed = y == 20;
        const float light = 50.0f, wall = scene.truth(x, 21, c);
        truth(x, y, c) = mixed ? 0.5f * (light + wall) : light;
        b.color.mean(x, y, c) = mixed ? (c == 1 ? 0.3f * light : 0.7f * light) : light;
        b.color.varianceOfMean(x, y, c) = mixed ? 0.25f * light * light / 16 : 0.0f;
        b.albedo.mean(x, y, c) = mixed ? 0.5f * scene.albedo(x, 21, c) : 0.0f;
      }
  Image ring(64, 64, 1);  // wall pixels within 3 of the light
  for (int y = 21; y <= 23; ++y)
    for (int x = 17; x < 43; ++x) ring(x, y, 0) = 1.0f;
  const double noisy = test::maskedRelMse(b.color.mean, truth, ring);
  const double denoised = test::maskedRelMse(Atrous().run(input), truth, ring);
  AtrousParams plain;
  plain.demodulate = false;
  const double notDemodulated = test::maskedRelMse(Atrous(plain).run(input), truth, ring);
  std::cout << "next to the light: relMSE noisy " << noisy << ", atrous " << denoised
            << ", not demodulated " << notDemodulated << "\n";
  // Measured: 0.095 (0.05 noisy, 0.81 not demodulated); 2.1 without the emitter guard.
  EXPECT_LT(denoised, 2 * noisy);
  EXPECT_LT(denoised * 4, notDemodulated);
}

TEST(Atrous, NonFiniteInputsGiveFiniteOutputs) {
  const test::SyntheticScene scene = scene64();
  DenoiseInput input = scene.fullInput();
  const float nan = std::numeric_limits<float>::quiet_NaN(),
              inf = std::numeric_limits<float>::infinity();
  for (int x = 0; x < 64; ++x) {
    input.whole.albedo.mean(x, 10, 1) = nan;
    input.whole.depth.mean(x, 20, 0) = inf;
    input.whole.normal.mean(x, 30, 0) = nan;
  }
  input.whole.color.mean(5, 5, 0) = nan;
  input.whole.color.mean(6, 5, 0) = inf;
  input.whole.color.varianceOfMean(6, 6, 1) = inf;
  input.whole.color.varianceOfMean(7, 6, 1) = nan;
  for (bool clamp : {false, true}) {
    AtrousParams params;
    params.clampFireflies = clamp;
    EXPECT_EQ(test::firstNonFinite(Atrous(params).run(input)), "") << "clamp " << clamp;
  }
}

TEST(Atrous, FireflyClampMeasurement) {
  // The clamp is a preview option, off by default; this records what it does with fireflies.
  test::SyntheticSceneOptions o;
  o.fireflyProbability = 0.002f;
  const test::SyntheticScene scene = scene64(o);
  AtrousParams clamped;
  clamped.clampFireflies = true;
  const double plain = relMse(Atrous().run(scene.fullInput()), scene.truth);
  const double withClamp = relMse(Atrous(clamped).run(scene.fullInput()), scene.truth);
  std::cout << "with fireflies: relMSE noisy "
            << relMse(scene.fullInput().whole.color.mean, scene.truth) << ", atrous " << plain
            << ", clamped " << withClamp << "\n";
  const test::SyntheticScene clean = scene64();
  std::cout << "without fireflies: atrous " << relMse(Atrous().run(clean.fullInput()), clean.truth)
            << ", clamped " << relMse(Atrous(clamped).run(clean.fullInput()), clean.truth) << "\n";
  EXPECT_EQ(test::firstNonFinite(Atrous(clamped).run(scene.fullInput())), "");
}

TEST(Atrous, RegistryAndParameters) {
  const auto atrous = createDenoiser("atrous:iterations=3:sigmaN=64:demodulate=false");
  EXPECT_EQ(atrous->name(), "atrous");
  EXPECT_TRUE(atrous->requirements().features);
  EXPECT_FALSE(atrous->requirements().halves);
  EXPECT_THROW(createDenoiser("atrous:sigmaN=100"), Error);
  EXPECT_THROW(createDenoiser("atrous:iterations=-1"), Error);
  EXPECT_THROW(createDenoiser("atrous:sigmaL=0"), Error);
  // Zero iterations: the input, exactly (demodulation off).
  const test::SyntheticScene scene = scene64();
  const Image out = createDenoiser("atrous:iterations=0:demodulate=false")->run(scene.fullInput());
  EXPECT_TRUE(test::bitIdentical(out, scene.fullInput().whole.color.mean));
}

TEST(Atrous, TungstenPeerBuffers) {
  CHORUS_REQUIRE_SHARED(shared);
  for (const char* name : {"room", "glossy"}) {
    const auto dir = shared / "peers/tungsten-nfor" / name;
    const DenoiseInput input = readTungstenDirectory(dir / "spp4");
    const Image reference = readExrLayer(dir / "reference.exr");
    const Image out = Atrous().run(input);
    ASSERT_EQ(test::firstNonFinite(out), "") << name;
    const double noisy = relMse(input.whole.color.mean, reference),
                 denoised = relMse(out, reference);
    AtrousParams clamped;
    clamped.clampFireflies = true;
    std::cout << name << " spp4: relMSE noisy " << noisy << ", atrous " << denoised << ", clamped "
              << relMse(Atrous(clamped).run(input), reference) << "\n";
    EXPECT_LT(denoised * 2, noisy) << name;
  }
}

}  // namespace
}  // namespace chorus
