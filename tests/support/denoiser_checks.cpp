#include "tests/support/denoiser_checks.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <cmath>
#include <cstring>
#include <iostream>
#include <vector>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "denoise/base/registry.h"
#include "denoise/buffers/tungsten_dir.h"
#include "denoise/metrics/metrics.h"

namespace chorus::test {

Image runWithThreads(const BaseDenoiser& denoiser, const DenoiseInput& input, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  return denoiser.run(input);
}

std::string firstNonFinite(const Image& image) {
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < image.channels(); ++c)
        if (!std::isfinite(image(x, y, c)))
          return "value " + std::to_string(image(x, y, c)) + " at (" + std::to_string(x) + ", " +
                 std::to_string(y) + ") channel " + std::to_string(c);
  return "";
}

bool bitIdentical(const Image& a, const Image& b) {
  return a.sameShape(b) && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

Image gaussianBlur(const Image& image, float sigma) {
  const int radius = int(std::ceil(3.0f * sigma));
  std::vector<double> taps(size_t(2 * radius + 1));
  for (int i = -radius; i <= radius; ++i)
    taps[size_t(i + radius)] = std::exp(-double(i * i) / (2.0 * sigma * sigma));
  Image out(image.width(), image.height(), image.channels());
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < image.channels(); ++c) {
        double sum = 0, weight = 0;
        for (int dy = -radius; dy <= radius; ++dy)
          for (int dx = -radius; dx <= radius; ++dx) {
            const int qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= image.width() || qy >= image.height()) continue;
            const double w = taps[size_t(dx + radius)] * taps[size_t(dy + radius)];
            sum += w * image(qx, qy, c);
            weight += w;
          }
        out(x, y, c) = float(sum / weight);
      }
  return out;
}

float maxDeviationFrom(const Image& image, const float expected[3]) {
  float worst = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(image(x, y, c) - expected[c]));
  return worst;
}

SyntheticScene syntheticScene(int size, SyntheticSceneOptions extra) {
  return syntheticScene(size, size, extra);
}

SyntheticScene syntheticScene(int width, int height, SyntheticSceneOptions extra) {
  extra.width = width;
  extra.height = height;
  return makeSyntheticScene(extra);
}

void expectReducesRelMse(const BaseDenoiser& denoiser, double minImprovement) {
  const SyntheticScene scene = syntheticScene(64);
  const DenoiseInput input = scene.fullInput();
  const Image out = denoiser.run(input);
  ASSERT_EQ(firstNonFinite(out), "") << denoiser.name();
  const double noisy = relMse(input.whole.color.mean, scene.truth);
  const double denoised = relMse(out, scene.truth);
  std::cout << "relMSE noisy " << noisy << ", " << denoiser.name() << " " << denoised << "\n";
  EXPECT_LT(denoised * minImprovement, noisy) << denoiser.name();
}

void expectKeepsFeatureEdgesSharp(const BaseDenoiser& denoiser, double vsNoisy, float blurSigma,
                                  double vsBlur) {
  const SyntheticScene scene = syntheticScene(64);
  const DenoiseInput input = scene.fullInput();
  const Image& noisy = input.whole.color.mean;
  const double noisyEdges = maskedRelMse(noisy, scene.truth, scene.edgeMask);
  const double edges = maskedRelMse(denoiser.run(input), scene.truth, scene.edgeMask);
  const double blurEdges =
      vsBlur > 0 ? maskedRelMse(gaussianBlur(noisy, blurSigma), scene.truth, scene.edgeMask) : 0;
  std::cout << "edge relMSE noisy " << noisyEdges << ", " << denoiser.name() << " " << edges;
  if (vsBlur > 0) std::cout << ", blur (σ " << blurSigma << ") " << blurEdges;
  std::cout << " over " << scene.edgePixelCount << " pixels\n";
  EXPECT_LT(edges * vsNoisy, noisyEdges) << denoiser.name() << " vs noisy";
  if (vsBlur > 0) {
    EXPECT_LT(edges * vsBlur, blurEdges) << denoiser.name() << " vs blur σ " << blurSigma;
  }
}

namespace {

// Deviation of the output from a noise-free constant colour.
float deviationOnConstant(const DenoiseFn& run, const std::array<float, 3>& value) {
  SyntheticSceneOptions o;
  o.constantColor = value;
  return maxDeviationFrom(run(syntheticScene(64, o).fullInput()), value.data());
}

DenoiseFn runOf(const BaseDenoiser& denoiser) {
  return [&denoiser](const DenoiseInput& input) { return denoiser.run(input); };
}

}  // namespace

void expectConstantStaysConstant(const std::string& name, const DenoiseFn& run,
                                 float relTolerance) {
  const std::array<float, 3> value{0.3f, 1.5f, 7.0f};
  EXPECT_LE(deviationOnConstant(run, value), relTolerance * value[2])
      << name << " on the constant (0.3, 1.5, 7)";
}

void expectConstantStaysConstant(const BaseDenoiser& denoiser, float relTolerance) {
  expectConstantStaysConstant(denoiser.name(), runOf(denoiser), relTolerance);
}

void expectBlackStaysBlack(const std::string& name, const DenoiseFn& run) {
  EXPECT_LE(deviationOnConstant(run, {0.0f, 0.0f, 0.0f}), 0.0f) << name << " on black";
}

void expectBlackStaysBlack(const BaseDenoiser& denoiser) {
  expectBlackStaysBlack(denoiser.name(), runOf(denoiser));
}

void expectRunsOnEveryBufferPart(const BaseDenoiser& denoiser, bool withHalves,
                                 double minImprovement) {
  const SyntheticScene scene = syntheticScene(64);
  for (BufferPart part : {BufferPart::HalfA, BufferPart::HalfB, BufferPart::Full}) {
    DenoiseInput input = scene.buffers.input(part);
    ASSERT_TRUE(input.halves) << partName(part);  // K = 4: every part has halves to drop or keep
    if (!withHalves) input.halves.reset();
    const std::string what = denoiser.name() + " on " + std::string(partName(part)) +
                             (withHalves ? " with halves" : " without halves");
    const Image out = denoiser.run(input);
    ASSERT_EQ(out.width(), 64) << what;
    ASSERT_EQ(out.channels(), 3) << what;
    EXPECT_EQ(firstNonFinite(out), "") << what;
    EXPECT_LT(relMse(out, scene.truth) * minImprovement,
              relMse(input.whole.color.mean, scene.truth))
        << what;
  }
}

void expectReducesRelMseOnEveryBufferPart(const BaseDenoiser& denoiser,
                                          double minImprovementOneSample,
                                          double minImprovementFourSamples) {
  for (int samples : {1, 4}) {
    SyntheticSceneOptions o;
    o.samplesPerSubBuffer = samples;
    const SyntheticScene scene = syntheticScene(64, o);
    const double minImprovement =
        samples == 1 ? minImprovementOneSample : minImprovementFourSamples;
    for (BufferPart part : {BufferPart::HalfA, BufferPart::HalfB, BufferPart::Full}) {
      const DenoiseInput input = scene.buffers.input(part);
      const std::string what = denoiser.name() + " on " + std::string(partName(part)) + ", " +
                               std::to_string(samples) + " sample(s) per quarter";
      const Image out = denoiser.run(input);
      ASSERT_EQ(firstNonFinite(out), "") << what;
      const double noisy = relMse(input.whole.color.mean, scene.truth);
      const double denoised = relMse(out, scene.truth);
      std::cout << what << ": relMSE noisy " << noisy << ", denoised " << denoised << "\n";
      EXPECT_LT(denoised * minImprovement, noisy) << what;
    }
  }
}

void expectDeterministicAcrossThreads(const BaseDenoiser& denoiser, const SyntheticScene& scene) {
  EXPECT_TRUE(bitIdentical(runWithThreads(denoiser, scene.fullInput(), 1),
                           runWithThreads(denoiser, scene.fullInput(), 2)))
      << denoiser.name() << ": one thread and two threads differ";
}

void expectFiniteOnNonFiniteInputs(const BaseDenoiser& denoiser, const SyntheticScene& scene,
                                   const std::function<void(DenoiseInput&)>& corrupt) {
  DenoiseInput input = scene.fullInput();
  corrupt(input);
  EXPECT_EQ(firstNonFinite(denoiser.run(input)), "") << denoiser.name();
}

std::unique_ptr<BaseDenoiser> expectCreates(const std::string& spec, const std::string& name,
                                            DenoiserRequirements requirements) {
  std::unique_ptr<BaseDenoiser> denoiser = createDenoiser(spec);
  EXPECT_EQ(denoiser->name(), name) << spec;
  EXPECT_EQ(denoiser->requirements().features, requirements.features) << spec;
  EXPECT_EQ(denoiser->requirements().halves, requirements.halves) << spec;
  return denoiser;
}

void expectRejected(std::initializer_list<const char*> specs) {
  for (const char* spec : specs) EXPECT_THROW(createDenoiser(spec), Error) << spec;
}

void expectIdentity(const std::string& spec) {
  const SyntheticScene scene = syntheticScene(64);
  EXPECT_TRUE(bitIdentical(createDenoiser(spec)->run(scene.fullInput()),
                           scene.fullInput().whole.color.mean))
      << spec << " should return its input";
}

void expectNeedsHalves(const BaseDenoiser& denoiser) {
  DenoiseInput input = syntheticScene(64).fullInput();
  input.halves.reset();
  EXPECT_THROW(denoiser.run(input), Error) << denoiser.name() << " without halves";
}

void expectHalvesTungstenPeerRelMse(
    const BaseDenoiser& denoiser, const std::filesystem::path& shared,
    const std::function<void(const std::string& scene, const DenoiseInput&,
                             const Image& reference)>& report) {
  for (const std::string name : {"room", "glossy"}) {
    const auto dir = shared / "peers/tungsten-nfor" / name;
    const DenoiseInput input = readTungstenDirectory(dir / "spp4");
    const Image reference = readExrLayer(dir / "reference.exr");
    const Image out = denoiser.run(input);
    ASSERT_EQ(firstNonFinite(out), "") << denoiser.name() << " on " << name;
    const double noisy = relMse(input.whole.color.mean, reference),
                 denoised = relMse(out, reference);
    std::cout << name << " spp4: relMSE noisy " << noisy << ", " << denoiser.name() << " "
              << denoised << "\n";
    if (report) report(name, input, reference);
    EXPECT_LT(denoised * 2, noisy) << denoiser.name() << " on " << name;
  }
}

}  // namespace chorus::test
