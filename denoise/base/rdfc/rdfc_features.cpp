#include "denoise/base/rdfc/rdfc_features.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "denoise/base/buffer_variance.h"
#include "denoise/base/filters/feature_nlmeans.h"
#include "denoise/util/parallel_rows.h"

namespace chorus {
namespace {

// A feature of one buffer after RDFC's mapping (mean and variance of the mean).
struct MappedFeature {
  Image mean, variance;
};

MappedFeature mapNormal(const MeanVariance& normal) {
  MappedFeature out{normal.mean, normal.varianceOfMean};
  for (float& v : out.mean.values()) v = 0.5f * (v + 1.0f);
  for (float& v : out.variance.values()) v *= 0.25f;
  return out;
}

MappedFeature mapAlbedo(const MeanVariance& albedo) {
  MappedFeature out{albedo.mean, albedo.varianceOfMean};
  for (size_t i = 0; i < out.mean.pixelCount(); ++i) {
    float* a = out.mean.data() + i * 3;
    const float m = std::max({1.0f, a[0], a[1], a[2]});  // NaN compares false: stays 1
    for (int c = 0; c < 3; ++c) {
      a[c] /= m;
      out.variance.data()[i * 3 + size_t(c)] /= m * m;
    }
  }
  return out;
}

float largestFiniteValue(const Image& image) {
  float largest = 0.0f;
  for (float v : image.values())
    if (std::isfinite(v)) largest = std::max(largest, v);
  return largest > 0.0f ? largest : 1.0f;
}

RdfcFeature prefilter(const std::string& name, const MappedFeature& whole,
                      const MappedFeature& half1, const MappedFeature& half2, float tauScale,
                      const RdfcPrefilterParams& params) {
  RdfcFeature feature;
  feature.name = name;
  feature.tauScale = tauScale;
  feature.known = finiteMask({&whole.mean, &whole.variance, &half1.mean, &half2.mean});
  const std::vector<uint8_t>& known = feature.known;
  const Image f1 = finiteOr(half1.mean, 0.0f), f2 = finiteOr(half2.mean, 0.0f);
  const int channels = f1.channels();

  // Guide: the mean of the buffers with the (rescaled) variance of that mean; unknown pixels get
  // a NaN variance, so they match nothing and are not mixed into their neighbours.
  const Image guide = meanOf(f1, f2);
  const Image twoBuffer = squaredDifference(f1, f2, 0.25f);
  const Image sample = completedVariance(whole.variance, twoBuffer);
  Image variance =
      params.rescaleVariance ? rescaledVariance(sample, twoBuffer, 10, &known) : sample;
  for (size_t i = 0; i < known.size(); ++i)
    if (!known[i])
      for (int c = 0; c < channels; ++c)
        variance.data()[i * size_t(channels) + size_t(c)] = std::nanf("");

  const PatchTerm patch{.guide = &guide,
                        .variance = &variance,
                        .f = params.f,
                        .k = params.k,
                        .weightBoxRadius = params.weightBoxRadius};
  const Image* data[] = {&f1, &f2};
  const std::vector<Image> filtered =
      featureNlMeans(data, &patch, {}, {.r = params.r, .minCenterWeight = 1e-3f});
  const Image& g1 = filtered[0];
  const Image& g2 = filtered[1];

  feature.value = meanOf(g1, g2);
  feature.variance = smooth3Tap(squaredDifference(g1, g2, 0.25f), std::exp(-2.0f), &known);
  feature.gradient = squaredGradient(feature.value, &known);
  for (size_t i = 0; i < known.size(); ++i) {
    if (known[i]) continue;
    for (int c = 0; c < channels; ++c) {
      const size_t k = i * size_t(channels) + size_t(c);
      feature.value.data()[k] = 0.0f;
      feature.variance.data()[k] = kNeutralVariance;
      feature.gradient.data()[k] = 0.0f;
    }
  }
  return feature;
}

}  // namespace

Image RdfcFeature::normalizingVariance(float tau) const {
  Image out(variance.width(), variance.height(), variance.channels());
  const float floor = tau * tauScale;
  const size_t channels = size_t(variance.channels());
  parallelChunks(out.size(), [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k)
      out.data()[k] = known[k / channels]
                          ? std::max(variance.data()[k], std::max(gradient.data()[k], floor))
                          : kNeutralVariance;
  });
  return out;
}

std::vector<RdfcFeature> prefilterRdfcFeatures(const DenoiseInput& input,
                                               const RdfcPrefilterParams& params) {
  if (!input.halves) throw std::invalid_argument("prefilterRdfcFeatures: input has no halves");
  const SubBuffer& whole = input.whole;
  const SubBuffer& h1 = (*input.halves)[0];
  const SubBuffer& h2 = (*input.halves)[1];
  const float maxDepth = largestFiniteValue(whole.depth.mean);

  // The four features side by side: each one's serial steps (mapping, variance rescaling,
  // gradients) overlap the others' parallel filtering. Each is computed alone, in the caller's
  // floating-point state (parallelRows), so the results do not change.
  std::vector<RdfcFeature> features(4);
  auto plain = [](const MeanVariance& q) { return MappedFeature{q.mean, q.varianceOfMean}; };
  parallelRows(0, 4, [&](int j) {
    switch (j) {
      case 0:
        features[0] = prefilter("normal", mapNormal(whole.normal), mapNormal(h1.normal),
                                mapNormal(h2.normal), 1.0f, params);
        break;
      case 1:
        features[1] = prefilter("albedo", mapAlbedo(whole.albedo), mapAlbedo(h1.albedo),
                                mapAlbedo(h2.albedo), 1.0f, params);
        break;
      case 2:
        features[2] = prefilter("depth", plain(whole.depth), plain(h1.depth), plain(h2.depth),
                                maxDepth * maxDepth, params);
        break;
      default:
        features[3] = prefilter("visibility", plain(whole.visibility), plain(h1.visibility),
                                plain(h2.visibility), 1.0f, params);
        break;
    }
  });
  return features;
}

}  // namespace chorus
