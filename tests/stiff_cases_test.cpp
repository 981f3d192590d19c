// The stiff-case suite (issue 26, docs/outliers.md): every registered base denoiser and the
// ensemble on inputs that break naive arithmetic — fireflies of 1e3 … 1e38 times the mean in one
// sub-buffer, radiance spanning 1e-30 … 1e30, huge radiance, constant and black images, NaN
// regions, identical members, 1×1 and 1×N images. For every member and the ensemble the outputs
// are finite and non-negative; each member's relMSE is at most the noisy input's and the
// ensemble's at most 1.1 × its best member's; where an extreme part was added to an ordinary
// input, the relMSE is within 1.1 × of the same input without it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "common/image/exr_io.h"
#include "denoise/base/registry.h"
#include "denoise/buffers/buffers_exr.h"
#include "denoise/ensemble/combiners.h"
#include "denoise/ensemble/outputs_directory.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/ensemble.h"
#include "tests/support/stiff_inputs.h"
#include "tests/support/synthetic_cases.h"
#include "tests/support/synthetic_scene.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

constexpr int kSize = 48;
// The ensemble may exceed its best member by this factor; an extreme input may cost this much
// over the same input without the extreme part.
constexpr double kEnsembleSlack = 1.1, kExtremeSlack = 1.1;

std::vector<std::string> allMemberNames() {
  std::vector<std::string> names;
  for (const DenoiserEntry& entry : builtinDenoisers()) names.push_back(entry.name);
  return names;
}

struct Outcome {
  Image noisy;
  std::vector<BaseOutputs> bases;
  CombineResult combined;
};

Outcome denoiseAll(const SampleBuffers& buffers, const std::vector<std::string>& names) {
  const std::vector<EnsembleMember> members = membersFromSpecs(names);
  const EnsembleSources sources = sourcesFromBuffers(buffers);
  Outcome o;
  o.noisy = sources.full.whole.color.mean;
  o.bases = runBaseDenoisers(sources, members);
  o.combined = combine(guidesFromSources(sources), pointersTo(o.bases), CombineOptions{});
  return o;
}

// Where the first NaN, Inf or negative value is, or "".
std::string firstBadValue(const Image& image) {
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < image.channels(); ++c) {
        const float v = image(x, y, c);
        if (!std::isfinite(v) || v < 0.0f)
          return std::to_string(v) + " at (" + std::to_string(x) + ", " + std::to_string(y) + ", " +
                 std::to_string(c) + ")";
      }
  return "";
}

// How errors are measured: relMSE over the pixels where mask > 0.5 (every pixel without a mask),
// of image / scale against truth (scale: a 1-channel map; none = 1).
struct Measure {
  const Image& truth;
  const Image* mask = nullptr;
  const Image* scale = nullptr;

  double operator()(const Image& image) const {
    Image unscaled = image;
    if (scale)
      for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x)
          for (int c = 0; c < image.channels(); ++c)
            unscaled(x, y, c) = float(double(image(x, y, c)) / (*scale)(x, y, 0));
    return mask ? test::maskedRelMse(unscaled, truth, *mask) : relMse(unscaled, truth);
  }
};

struct Errors {
  std::vector<double> members;
  double ensemble = 0;
};

// The checks every case makes; returns the errors for comparisons between cases.
Errors expectStiffProperties(const std::string& name, const Outcome& o, const Measure& error) {
  Errors errors;
  const double noisy = error(o.noisy);
  // Float rounding: noise-free inputs have error 0, and a member that returns its input may
  // differ from it in the last bits.
  auto noWorse = [](double a, double b) { return a <= b * (1.0 + 1e-5) + 1e-10; };
  double best = std::numeric_limits<double>::infinity();
  for (const BaseOutputs& base : o.bases) {
    for (const Image* out : {&base.full, &base.a, &base.b})
      EXPECT_EQ(firstBadValue(*out), "") << name << ": " << base.name;
    const double e = error(base.full);
    EXPECT_PRED2(noWorse, e, noisy) << name << ": " << base.name << " is worse than its input";
    errors.members.push_back(e);
    best = std::min(best, e);
  }
  EXPECT_EQ(firstBadValue(o.combined.image), "") << name << ": ensemble";
  errors.ensemble = error(o.combined.image);
  EXPECT_PRED2(noWorse, errors.ensemble, kEnsembleSlack * best)
      << name << ": ensemble vs best member";
  std::printf("%-24s noisy %9.4g  ensemble %9.4g ", name.c_str(), noisy, errors.ensemble);
  for (size_t i = 0; i < o.bases.size(); ++i)
    std::printf(" %s %.4g", o.bases[i].name.c_str(), errors.members[i]);
  std::printf("\n");
  return errors;
}

// Each member within memberSlack × and the ensemble within ensembleSlack × of the same input
// without the extreme part.
void expectCloseToBaseline(const std::string& name, const Outcome& o, const Errors& extreme,
                           const Errors& baseline, double memberSlack = kExtremeSlack,
                           double ensembleSlack = kExtremeSlack) {
  for (size_t i = 0; i < extreme.members.size(); ++i)
    EXPECT_LE(extreme.members[i], memberSlack * baseline.members[i])
        << name << ": " << o.bases[i].name << " vs the same input without the extreme part";
  EXPECT_LE(extreme.ensemble, ensembleSlack * baseline.ensemble)
      << name << ": ensemble vs the same input without the extreme part";
}

test::SyntheticScene scene(int width, int height, test::SyntheticSceneOptions extra = {}) {
  extra.width = width;
  extra.height = height;
  return test::makeSyntheticScene(extra);
}

TEST(StiffCases, FirefliesInOneSubBuffer) {
  const test::SyntheticScene s = scene(kSize, kSize);
  const auto names = allMemberNames();
  const Errors baseline =
      expectStiffProperties("no fireflies", denoiseAll(s.buffers, names), {s.truth});
  for (double factor : {1e3, 1e6, 1e12, 1e20, 1e38}) {
    const std::string name = "fireflies x" + std::to_string(int(std::log10(factor)));
    const Outcome o = denoiseAll(test::withFireflies(s.buffers, 0, 6, factor, 7), names);
    expectCloseToBaseline(name, o, expectStiffProperties(name, o, {s.truth}), baseline);
  }
}

TEST(StiffCases, GlobalScales) {
  // The whole image at 1e-30 … 1e30. Above ~1e19 squares overflow float and the variances of
  // the mean saturate at FLT_MAX (as the film clamps them); below ~1e-19 they underflow to 0.
  const test::SyntheticScene s = scene(kSize, kSize);
  const auto names = allMemberNames();
  const Errors baseline = expectStiffProperties("scale 1", denoiseAll(s.buffers, names), {s.truth});
  for (double factor : {1e-30, 1e-10, 1e10, 1e30}) {
    const std::string name = "scale 1e" + std::to_string(int(std::lround(std::log10(factor))));
    const Image scale = test::bandScales(kSize, kSize, {factor});
    const Outcome o = denoiseAll(test::scaledColor(s.buffers, scale), names);
    const Errors scaled = expectStiffProperties(name, o, {s.truth, nullptr, &scale});
    // At 1e±30 the variances of the mean are lost to float (saturated or underflowed) and the
    // members run on a two-buffer estimate instead (radiance_scale.h): measured up to 1.4×
    // (dual-buffer NL-means, whose halves then share one variance).
    const bool variancesLost = factor < 1e-19 || factor > 1e19;
    expectCloseToBaseline(name, o, scaled, baseline, variancesLost ? 2.5 : kExtremeSlack);
  }
}

TEST(StiffCases, RadianceSpanningSixtyDecades) {
  // Column bands at 1e-30, 1e-10, 1e10 and 1e30 with no feature edge between them: the
  // feature-guided filters mix the bands (a 1e30 neighbour outweighs a 1e10 pixel), so only
  // finiteness and the sign are required of the members here.
  const test::SyntheticScene s = scene(kSize, kSize);
  const Image scale = test::bandScales(kSize, kSize, {1e-30, 1e-10, 1e10, 1e30});
  const Outcome o = denoiseAll(test::scaledColor(s.buffers, scale), allMemberNames());
  for (const BaseOutputs& base : o.bases)
    for (const Image* out : {&base.full, &base.a, &base.b})
      EXPECT_EQ(firstBadValue(*out), "") << base.name;
  EXPECT_EQ(firstBadValue(o.combined.image), "");
}

TEST(StiffCases, CombinationHoldsAcrossSixtyDecades) {
  // The members' outputs and the noisy guides of one input, then the same images times column
  // bands at 1e-30, 1e-10, 1e10 and 1e30 (the members are not rerun: only the combination sees
  // the range). Scaled back, the blend must be within 1.1x of the unscaled one (measured:
  // 0.00234 against 0.00239; the weights inside a band are not the unscaled ones, since the
  // terms, the outlier cap and the allowances are relative to the image's mean |x|, which the
  // brightest band sets: docs/outliers.md).
  const int width = 128, height = 48;
  const test::SyntheticScene s = scene(width, height);
  const EnsembleSources sources = sourcesFromBuffers(s.buffers);
  const std::vector<std::string> names = {"nfor", "rdfc", "atrous"};
  const std::vector<BaseOutputs> bases = runBaseDenoisers(
      sources, membersFromSpecs(names), nullptr, {.full = true, .halves = true, .heldOut = true});
  const EnsembleGuides guides = guidesFromSources(sources, true);
  const Image scale = test::bandScales(width, height, {1e-30, 1e-10, 1e10, 1e30});
  EnsembleGuides scaledGuides = guides;
  for (Image* image : {&scaledGuides.color, &scaledGuides.colorA, &scaledGuides.colorB})
    *image = test::scaledImage(*image, scale);
  for (Image& quarter : scaledGuides.quarters) quarter = test::scaledImage(quarter, scale);
  std::vector<BaseOutputs> scaledBases = bases;
  for (BaseOutputs& base : scaledBases) {
    for (Image* image : {&base.a, &base.b, &base.full}) *image = test::scaledImage(*image, scale);
    for (Image& run : base.heldOut) run = test::scaledImage(run, scale);
  }
  const Measure plain{s.truth}, banded{s.truth, nullptr, &scale};
  const CombineResult reference = combine(guides, pointersTo(bases), CombineOptions{});
  const CombineResult result = combine(scaledGuides, pointersTo(scaledBases), CombineOptions{});
  EXPECT_EQ(firstBadValue(result.image), "");
  const double unscaled = plain(reference.image), scaled = banded(result.image);
  std::printf("ensemble relMSE: unscaled %.4g, bands 1e-30 ... 1e30 %.4g\n", unscaled, scaled);
  EXPECT_LE(scaled, kExtremeSlack * unscaled);
}

TEST(StiffCases, ConstantAndBlackImages) {
  for (const std::array<float, 3>& color :
       {std::array<float, 3>{0.3f, 1.5f, 7.0f}, std::array<float, 3>{0, 0, 0}}) {
    test::SyntheticSceneOptions options;
    options.constantColor = color;
    const test::SyntheticScene s = scene(kSize, kSize, options);
    const Outcome o = denoiseAll(s.buffers, allMemberNames());
    expectStiffProperties(color[0] > 0 ? "constant" : "black", o, {s.truth});
  }
}

TEST(StiffCases, NanRegion) {
  const test::SyntheticScene s = scene(kSize, kSize);
  const auto names = allMemberNames();
  // The noisy input is NaN inside the rectangle: errors are measured outside it and its 3-pixel
  // border, whose neighbourhoods lack data (there every member and the ensemble lose 1.5–3×
  // against the same input without the hole: measured).
  const Image outside = test::outsideRect(kSize, kSize, 10 - 3, 12 - 3, 22 + 3, 20 + 3);
  const Errors baseline =
      expectStiffProperties("no NaN (outside)", denoiseAll(s.buffers, names), {s.truth, &outside});
  const Outcome o = denoiseAll(test::withNanRect(s.buffers, 10, 12, 22, 20), names);
  expectCloseToBaseline(
      "NaN rect", o, expectStiffProperties("NaN rect (outside)", o, {s.truth, &outside}), baseline);
}

TEST(StiffCases, IdenticalMembers) {
  const test::SyntheticScene s = scene(kSize, kSize);
  // guard=8 is the default: the same denoiser under a second label.
  const Outcome o = denoiseAll(s.buffers, {"atrous", "atrous:guard=8"});
  ASSERT_EQ(o.bases.size(), 2u);
  EXPECT_EQ(relMse(o.bases[0].full, o.bases[1].full), 0.0);
  expectStiffProperties("identical members", o, {s.truth});
}

TEST(StiffCases, TinyImages) {
  for (const auto& [w, h] : {std::pair{1, 1}, std::pair{1, 17}, std::pair{17, 1}}) {
    const test::SyntheticScene s = scene(w, h);
    const Outcome o = denoiseAll(s.buffers, allMemberNames());
    expectStiffProperties(std::to_string(w) + "x" + std::to_string(h), o, {s.truth});
  }
}

TEST(StiffCases, MergeKeepsHugeVariancesFinite) {
  // Two sub-buffers at 3e38 that disagree: the merged variance of the mean is clamped, not Inf.
  SubBuffer a = SubBuffer::zeros(1, 1), b = SubBuffer::zeros(1, 1);
  for (int c = 0; c < 3; ++c) {
    a.color.mean(0, 0, c) = 3e38f;
    a.color.varianceOfMean(0, 0, c) = std::numeric_limits<float>::max();
    b.color.mean(0, 0, c) = 1.0f;
  }
  a.sampleCount(0, 0, 0) = b.sampleCount(0, 0, 0) = 2;
  const SubBuffer merged = merge({&a, &b});
  for (int c = 0; c < 3; ++c) {
    EXPECT_FLOAT_EQ(merged.color.mean(0, 0, c), 1.5e38f);
    EXPECT_EQ(merged.color.varianceOfMean(0, 0, c), std::numeric_limits<float>::max());
  }
}

// `chorus denoise render.exr --reference truth.exr` on a render.exr written from `buffers`;
// returns the relMSE of the written ensemble.exr divided by `scale` (every output layer is
// checked for NaN, Inf and negatives on the way).
double denoiseRenderExr(const SampleBuffers& buffers, const Image& truth, double scale,
                        const std::string& tag) {
  const test::TempDir dir("chorus_stiff_" + tag);
  const std::filesystem::path renderExr = dir / "render.exr", out = dir / "out";
  writeExr(renderExr, sampleBuffersToLayers(buffers));
  const auto r = test::runChorus({"denoise", renderExr.string(), "--methods", "nfor,rdfc,atrous",
                                  "--keep", "members", "--out", out.string()});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  if (r.exitCode != 0) return std::numeric_limits<double>::quiet_NaN();
  // The full-buffer variance the file holds is the merge of the sub-buffers': finite.
  const SampleBuffers read = sampleBuffersFromLayers(readExr(renderExr), renderExr);
  EXPECT_EQ(firstBadValue(read.part(BufferPart::Full).color.varianceOfMean), "") << tag;
  for (const char* file : {"ensemble.exr", "nfor.exr", "rdfc.exr", "atrous.exr"})
    for (const ExrLayer& layer : readExr(out / file)) {
      if (layer.name == "mseEstimate") continue;  // an error estimate: signed
      EXPECT_EQ(firstBadValue(layer.image), "") << tag << " " << file;
    }
  Image result = readExrLayer(out / "ensemble.exr");
  for (float& v : result.values()) v = float(double(v) / scale);
  return relMse(result, truth);
}

TEST(StiffCases, RenderExrAtTheLargestFloat) {
  // A render.exr whose radiance reaches 3e38 (squares overflow float; the sub-buffers' variances
  // of the mean saturate at FLT_MAX as the film clamps them). chorus's own renders no longer get
  // there (scene radiance is capped at 1e9, renderer/scene/scene_limits.h); another renderer's
  // file can. What `chorus denoise` writes is finite and non-negative, and its ensemble is
  // within 1.1x of the same file at scale 1.
  const test::SyntheticScene s = scene(24, 24);
  float largest = 0;
  for (int k = 0; k < s.buffers.splitCount(); ++k)
    for (float v : s.buffers.sub(k).color.mean.values()) largest = std::max(largest, v);
  const double factor = 3e38 / double(largest);
  const Image scale = test::bandScales(24, 24, {factor});
  const double plain = denoiseRenderExr(s.buffers, s.truth, 1.0, "render1");
  const double huge =
      denoiseRenderExr(test::scaledColor(s.buffers, scale), s.truth, factor, "render3e38");
  std::printf("render.exr: ensemble relMSE %.4g at scale 1, %.4g at 3e38\n", plain, huge);
  EXPECT_LE(huge, kExtremeSlack * plain);
}

TEST(StiffCases, DenoiseRepairsExternalMembers) {
  // An outputs directory whose member "bad" is NaN over a block and negative in a column:
  // DIR/bad.exr is written finite and non-negative, with one warning line counting the values.
  const test::TempDir dir("chorus_stiff_outputs");
  synthetic::Case c = synthetic::standardCases()[3];
  c.members = {"box1", "guided"};
  synthetic::PreparedCase prepared = synthetic::prepareCase(c, 24, 16);
  BaseOutputs bad = prepared.bases[0];
  bad.name = "bad";
  size_t nan = 0, negative = 0;  // (the synthetic members have a few negatives of their own)
  for (Image* image : {&bad.full, &bad.a, &bad.b})
    for (int y = 0; y < image->height(); ++y)
      for (int x = 0; x < image->width(); ++x)
        for (int ch = 0; ch < 3; ++ch) {
          float& v = (*image)(x, y, ch);
          if (x < 6 && y < 5) v = std::numeric_limits<float>::quiet_NaN();
          if (x == 20) v = -1.0f;
          nan += std::isnan(v);
          negative += v < 0.0f;
        }
  prepared.bases.push_back(bad);
  writeOutputsDirectory(dir / "in", prepared.guides, prepared.bases);
  const std::filesystem::path out = dir / "out";
  const auto r = test::runChorus({"denoise", (dir / "in").string(), "--methods", "box1,guided,bad",
                                  "--keep", "members", "--out", out.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const ExrLayer& layer : readExr(out / "bad.exr"))
    EXPECT_EQ(firstBadValue(layer.image), "") << "bad.exr layer '" << layer.name << "'";
  EXPECT_EQ(firstBadValue(readExrLayer(out / "ensemble.exr")), "");
  const std::string expected = (out / "bad.exr").string() + ": " + std::to_string(nan) +
                               " NaN/Inf values written as 0 (+Inf as the largest float), " +
                               std::to_string(negative) + " negative radiance values as 0\n";
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("bad.exr"), r.err.rfind("bad.exr")) << "one line per file\n" << r.err;
}

}  // namespace
}  // namespace chorus
