#include "denoise/base/jnlm/joint_nlmeans.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/error.h"
#include "denoise/base/buffer_variance.h"
#include "denoise/base/filters/feature_nlmeans.h"
#include "denoise/base/selection_knee.h"
#include "denoise/base/variance_calibration.h"
#include "denoise/base/variance_estimates.h"

namespace chorus {
namespace {

// A feature ready for a range term: value, variance and normalising variance.
struct RangeFeature {
  Image value, variance, normalizing;
};

RangeFeature rangeFeature(const MeanVariance& feature, float floor, int mapping) {
  RangeFeature out{feature.mean, feature.varianceOfMean, Image()};
  const int channels = out.value.channels();
  for (size_t i = 0; i < out.value.pixelCount(); ++i) {
    float* v = out.value.data() + i * size_t(channels);
    float* var = out.variance.data() + i * size_t(channels);
    float scale = 1.0f;
    if (mapping == 1) scale = 0.5f;                                       // normal: (n + 1) / 2
    if (mapping == 2) scale = 1.0f / std::max({1.0f, v[0], v[1], v[2]});  // albedo
    for (int c = 0; c < channels; ++c) {
      v[c] = mapping == 1 ? 0.5f * (v[c] + 1.0f) : v[c] * scale;
      var[c] *= scale * scale;
    }
  }
  const std::vector<uint8_t> known = finiteMask({&out.value, &out.variance});
  out.value = finiteOr(out.value, 0.0f);
  out.variance = finiteOr(out.variance, 0.0f);
  const Image gradient = squaredGradient(out.value, &known);
  out.normalizing = Image(out.value.width(), out.value.height(), channels);
  for (size_t k = 0; k < out.value.size(); ++k) {
    const bool ok = known[k / size_t(channels)] != 0;
    out.variance.data()[k] = ok ? std::max(out.variance.data()[k], 0.0f) : kNeutralVariance;
    out.normalizing.data()[k] =
        ok ? std::max(out.variance.data()[k], std::max(gradient.data()[k], floor))
           : kNeutralVariance;
  }
  return out;
}

float largestFiniteValue(const Image& image) {
  float largest = 0.0f;
  for (float v : image.values())
    if (std::isfinite(v)) largest = std::max(largest, v);
  return largest > 0.0f ? largest : 1.0f;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw Error("jnlm: " + what);
}

}  // namespace

JointNlMeansParams JointNlMeansParams::fromParams(ParamMap& map) {
  JointNlMeansParams p;
  p.r = map.getInt("r", p.r);
  p.f = map.getInt("f", p.f);
  p.k = map.getFloat("k", p.k);
  p.alpha = map.getFloat("alpha", p.alpha);
  p.kf = map.getFloat("kf", p.kf);
  p.tau = map.getFloat("tau", p.tau);
  p.refineFeatures = map.getBool("refineFeatures", p.refineFeatures);
  p.varianceKnee = map.getFloat("varianceKnee", p.varianceKnee);
  p.calibrationRadius = map.getInt("calibrate", p.calibrationRadius);
  require(p.r >= 1 && p.r <= 32, "r must be in [1, 32]");
  require(p.f >= 0 && p.f <= 16, "f must be in [0, 16]");
  require(std::isfinite(p.k) && p.k > 0 && std::isfinite(p.kf) && p.kf > 0, "k and kf must be > 0");
  require(p.calibrationRadius >= 0 && p.calibrationRadius <= kMaxCalibrationRadius,
          "calibrate must be in [0, " + std::to_string(kMaxCalibrationRadius) + "]");
  require(std::isfinite(p.alpha) && p.alpha >= 0, "alpha must be ≥ 0");
  require(std::isfinite(p.tau) && p.tau >= 0, "tau must be ≥ 0");
  require(validKnee(p.varianceKnee), "varianceKnee must be 0 (off) or positive");
  return p;
}

Image runJointNlMeans(const DenoiseInput& input, const JointNlMeansParams& params) {
  const SubBuffer& whole = input.whole;
  const float maxDepth = largestFiniteValue(whole.depth.mean);
  const RangeFeature albedo = rangeFeature(whole.albedo, params.tau, 2);
  const RangeFeature normal = rangeFeature(whole.normal, params.tau, 1);
  const RangeFeature depth = rangeFeature(whole.depth, params.tau * maxDepth * maxDepth, 0);
  std::vector<FeatureTerm> features;
  for (const RangeFeature* f : {&albedo, &normal, &depth})
    features.push_back({.value = &f->value,
                        .variance = &f->variance,
                        .normalizingVariance = &f->normalizing,
                        .k = params.kf});
  const FeatureNlMeansParams window{.r = params.r, .refineFeatures = params.refineFeatures};
  auto filter = [&](const Image& data, const Image& guide, const Image& variance) {
    const PatchTerm patch{.guide = &guide,
                          .variance = &variance,
                          .f = params.f,
                          .k = params.k,
                          .alpha = params.alpha};
    const Image* images[] = {&data};
    return std::move(featureNlMeans(images, &patch, features, window)[0]);
  };

  // The variance the patch distances divide by, kneed (selection_knee.h): cross-filtered at few
  // samples, a highlight's pixels looked like the dark pixels beside them to the other half's
  // weights, which then averaged this half's highlight into them.
  const double knee =
      kneeLevel({whole.color.mean.data(), whole.color.mean.size()}, params.varianceKnee);
  Image out;
  if (input.halves) {
    const Image a = finiteOr((*input.halves)[0].color.mean, 0.0f);
    const Image b = finiteOr((*input.halves)[1].color.mean, 0.0f);
    // Each half's own variance of the mean, the smoothed two-buffer estimate where a half holds
    // a single sample.
    const Image factor = colorVarianceCalibration(input, params.calibrationRadius);
    auto halfVariance = [&](int which, const Image& guide) {
      return kneedVariance(
          calibratedVariance(halfVarianceOfMean(input, which, Quantity::Color), factor), guide,
          knee);
    };
    const Image varianceA = halfVariance(0, a), varianceB = halfVariance(1, b);
    const Image filteredA = filter(a, b, varianceB);  // A's data, B's colour weights
    const Image filteredB = filter(b, a, varianceA);
    out = meanOf(filteredA, filteredB);
  } else {
    const Image color = finiteOr(whole.color.mean, 0.0f);
    const Image variance = kneedVariance(
        completedVariance(whole.color.varianceOfMean, Image(color.width(), color.height(), 3)),
        color, knee);
    out = filter(color, color, variance);
  }
  const Image noisy = finiteOr(whole.color.mean, 0.0f);
  for (size_t k = 0; k < out.size(); ++k)
    if (!std::isfinite(out.data()[k])) out.data()[k] = noisy.data()[k];
  return out;
}

}  // namespace chorus
