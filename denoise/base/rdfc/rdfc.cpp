#include "denoise/base/rdfc/rdfc.h"

#include <cmath>
#include <span>
#include <string>

#include "common/error.h"
#include "denoise/base/buffer_variance.h"
#include "denoise/base/filters/feature_nlmeans.h"
#include "denoise/base/selection_knee.h"
#include "denoise/util/parallel_rows.h"

namespace chorus {
namespace {

void requireRange(bool ok, const std::string& what) {
  if (!ok) throw Error("rdfc: " + what);
}

// Colour-guided NL-means without features (RDFC's selection smoothing): patch radius f, k,
// weights boxed over boxRadius, window r.
std::vector<Image> colorNlMeans(std::span<const Image* const> data, const Image& guide,
                                const Image& variance, const RdfcParams& params, int r) {
  const PatchTerm patch{.guide = &guide,
                        .variance = &variance,
                        .f = params.selectionF,
                        .k = params.selectionK,
                        .weightBoxRadius = params.selectionBoxRadius};
  return featureNlMeans(data, &patch, {}, {.r = r, .minCenterWeight = kRdfcMinCenterWeight});
}

// Step 4: smoothed SURE maps, argmin with RDFC's rules, smoothed binary maps. Before the
// smoothing a bright pixel's SURE goes to the relative scale (selection_knee.h): the colour
// patches of a light's edge at few samples are so noisy that the light's pixels enter a dark
// neighbour's sum, where their errors in absolute units chose THIRD, which spreads the light.
void selectCandidates(const Image& guide, const Image& variance, const RdfcParams& params,
                      RdfcResult& result) {
  const int w = guide.width(), h = guide.height();
  float* const sureMaps[] = {result.candidates[0].sure.data(), result.candidates[1].sure.data(),
                             result.candidates[2].sure.data()};
  const Image& narrowest = result.candidates[0].mean;
  kneeBrightErrors(
      sureMaps, size_t(w) * size_t(h), [&](size_t i) { return rgbLevel(narrowest, i); },
      kneeLevel({guide.data(), guide.size()}, params.selectionKnee));
  const Image* sure[] = {&result.candidates[0].sure, &result.candidates[1].sure,
                         &result.candidates[2].sure};
  std::vector<Image> smoothed = colorNlMeans(sure, guide, variance, params, params.sureR);
  for (int s = 0; s < 3; ++s) result.smoothedSure[size_t(s)] = std::move(smoothed[size_t(s)]);

  result.selection = Image(w, h, 1);
  std::array<Image, 3> binary = {Image(w, h, 1), Image(w, h, 1), Image(w, h, 1)};
  parallelRows(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      auto meanDerivative = [&](int s) {
        const Image& d = result.candidates[size_t(s)].derivative;
        return (d(x, y, 0) + d(x, y, 1) + d(x, y, 2)) / 3.0f;
      };
      int best = 2;
      float bestError = result.smoothedSure[2](x, y, 0);
      if (result.smoothedSure[1](x, y, 0) < bestError) {
        best = 1;
        bestError = result.smoothedSure[1](x, y, 0);
      }
      // FIRST (the narrowest patch) only where it is also at most as smooth as SECOND.
      if (result.smoothedSure[0](x, y, 0) < bestError && meanDerivative(0) <= meanDerivative(1))
        best = 0;
      result.selection(x, y, 0) = float(best);
      binary[size_t(best)](x, y, 0) = 1.0f;
    }
  });

  const Image* maps[] = {&binary[0], &binary[1], &binary[2]};
  std::vector<Image> soft = colorNlMeans(maps, guide, variance, params, params.selectionR);
  for (int s = 0; s < 3; ++s) result.selectionWeights[size_t(s)] = std::move(soft[size_t(s)]);
}

// Σ W_s F_s / Σ W_s for one buffer (the selected candidate where the weights vanish).
Image blendCandidates(const RdfcResult& result, Image RdfcCandidate::*buffer) {
  const Image& first = result.candidates[0].*buffer;
  Image out(first.width(), first.height(), 3);
  parallelRows(0, out.height(), [&](int y) {
    for (int x = 0; x < out.width(); ++x) {
      float total = 0.0f;
      for (int s = 0; s < 3; ++s) total += result.selectionWeights[size_t(s)](x, y, 0);
      for (int c = 0; c < 3; ++c) {
        float sum = 0.0f;
        for (int s = 0; s < 3; ++s)
          sum += result.selectionWeights[size_t(s)](x, y, 0) *
                 (result.candidates[size_t(s)].*buffer)(x, y, c);
        const int chosen = int(result.selection(x, y, 0));
        out(x, y, c) =
            total > 0.0f ? sum / total : (result.candidates[size_t(chosen)].*buffer)(x, y, c);
      }
    }
  });
  return out;
}

// Step 5: the second pass on the first-pass buffers.
Image secondPass(const Image& first1, const Image& first2, const std::vector<RdfcFeature>& features,
                 const RdfcParams& params) {
  const Image guide = meanOf(first1, first2);
  const Image variance = rdfcSecondPassVariance(first1, first2, guide, params.varianceKnee);
  const PatchTerm patch{.guide = &guide,
                        .variance = &variance,
                        .f = params.secondF,
                        .k = params.secondKc,
                        .centerOnlyDenominator = true,
                        .weightBoxRadius = params.secondBoxRadius};
  std::vector<Image> normalizing;
  normalizing.reserve(features.size());
  std::vector<FeatureTerm> featureTerms;
  for (const RdfcFeature& f : features) {
    normalizing.push_back(f.normalizingVariance(params.secondTau));
    featureTerms.push_back({.value = &f.value,
                            .variance = &f.variance,
                            .normalizingVariance = &normalizing.back(),
                            .k = params.secondKf,
                            .centerOnlyDenominator = true});
  }
  const Image* data[] = {&first1, &first2};
  const std::vector<Image> filtered = featureNlMeans(
      data, &patch, featureTerms, {.r = params.secondR, .minCenterWeight = kRdfcMinCenterWeight});
  return meanOf(filtered[0], filtered[1]);
}

}  // namespace

// Smoothed as is (knee 0), a highlight's variance at few samples became its dark neighbours'
// (orders of magnitude above their own), which made their patch distances to the highlight
// small, and the second pass spread it into them (a softbox seen in chrome at 4 spp).
Image rdfcSecondPassVariance(const Image& first1, const Image& first2, const Image& guide,
                             float knee) {
  Image raw = squaredDifference(first1, first2, 0.25f);
  const std::vector<float> divisor =
      kneeDivisors(guide, kneeLevel({guide.data(), guide.size()}, knee));
  divideByPixel(raw, divisor);
  Image variance = smooth3Tap(raw, std::exp(-2.0f));
  for (size_t k = 0; k < variance.size(); ++k) variance.data()[k] *= divisor[k / 3];
  return variance;
}

RdfcParams RdfcParams::fromParams(ParamMap& map) {
  RdfcParams p;
  RdfcCandidateParams& c = p.candidates;
  c.r = map.getInt("r", c.r);
  c.kc = map.getFloat("kc", c.kc);
  c.kf = map.getFloat("kf", c.kf);
  c.fFirst = map.getInt("fFirst", c.fFirst);
  c.fSecond = map.getInt("fSecond", c.fSecond);
  c.tauFirstSecond = map.getFloat("tau", c.tauFirstSecond);
  c.tauThird = map.getFloat("tauThird", c.tauThird);
  p.rescaleVariance = map.getBool("rescale", p.rescaleVariance);
  p.prefilter.rescaleVariance = p.rescaleVariance;
  p.sureR = map.getInt("sureR", p.sureR);
  p.selectionR = map.getInt("selectionR", p.selectionR);
  p.selectionKnee = map.getFloat("selectionKnee", p.selectionKnee);
  p.varianceKnee = map.getFloat("varianceKnee", p.varianceKnee);
  p.secondR = map.getInt("secondR", p.secondR);
  p.secondF = map.getInt("secondF", p.secondF);
  p.secondKc = map.getFloat("secondKc", p.secondKc);
  p.secondKf = map.getFloat("secondKf", p.secondKf);
  p.secondTau = map.getFloat("secondTau", p.secondTau);
  auto radius = [](int v) { return v >= 0 && v <= 32; };
  auto positive = [](float v) { return std::isfinite(v) && v > 0.0f; };
  requireRange(c.r >= 1 && c.r <= 32, "r must be in [1, 32]");
  requireRange(radius(c.fFirst) && radius(c.fSecond) && radius(p.secondF),
               "patch radii must be in [0, 32]");
  requireRange(radius(p.sureR) && radius(p.selectionR) && radius(p.secondR),
               "window radii must be in [0, 32]");
  requireRange(positive(c.kc) && positive(c.kf) && positive(p.secondKc) && positive(p.secondKf),
               "kc, kf, secondKc, secondKf must be > 0");
  requireRange(std::isfinite(c.tauFirstSecond) && c.tauFirstSecond >= 0 &&
                   std::isfinite(c.tauThird) && c.tauThird >= 0 && std::isfinite(p.secondTau) &&
                   p.secondTau >= 0,
               "tau, tauThird, secondTau must be ≥ 0");
  requireRange(validKnee(p.selectionKnee) && validKnee(p.varianceKnee),
               "selectionKnee and varianceKnee must be 0 (off) or positive");
  return p;
}

RdfcResult runRdfc(const DenoiseInput& input, const RdfcParams& params) {
  if (!input.halves)
    throw Error("rdfc: needs two independent halves of its input (at least 2 sub-buffers)");
  const SubBuffer& whole = input.whole;
  const Image b1 = finiteOr((*input.halves)[0].color.mean, 0.0f);
  const Image b2 = finiteOr((*input.halves)[1].color.mean, 0.0f);

  RdfcResult result;
  // 1. Colour variance.
  const Image twoBuffer = squaredDifference(b1, b2, 0.25f);
  const Image sample = completedVariance(whole.color.varianceOfMean, twoBuffer);
  result.colorVariance = params.rescaleVariance ? rescaledVariance(sample, twoBuffer, 10) : sample;

  // 2.–3. Features and candidates.
  RdfcPrefilterParams prefilter = params.prefilter;
  prefilter.rescaleVariance = params.rescaleVariance;
  const std::vector<RdfcFeature> features = prefilterRdfcFeatures(input, prefilter);
  result.candidates = rdfcCandidates(b1, b2, result.colorVariance, features, params.candidates);

  // 4. Selection and first-pass output.
  const Image guide = meanOf(b1, b2);
  selectCandidates(guide, result.colorVariance, params, result);
  const Image first1 = blendCandidates(result, &RdfcCandidate::buffer1);
  const Image first2 = blendCandidates(result, &RdfcCandidate::buffer2);
  result.firstPass = meanOf(first1, first2);

  // 5. Second pass.
  result.output = secondPass(first1, first2, features, params);
  parallelChunks(result.output.size(), [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k)
      if (!std::isfinite(result.output.data()[k])) result.output.data()[k] = guide.data()[k];
  });
  return result;
}

}  // namespace chorus
