#include "denoise/base/dual_buffer_nlm.h"

#include <algorithm>
#include <cmath>

#include "denoise/base/filters/nlmeans_filter.h"
#include "denoise/base/variance_estimates.h"
#include "denoise/util/error.h"

namespace chorus {

DualBufferNlMeansParams DualBufferNlMeansParams::fromParams(ParamMap& map) {
  DualBufferNlMeansParams p;
  p.r = map.getInt("r", p.r);
  p.f = map.getInt("f", p.f);
  p.k = map.getFloat("k", p.k);
  p.alpha = map.getFloat("alpha", p.alpha);
  p.weightThreshold = map.getFloat("weightThreshold", p.weightThreshold);
  p.varianceR = map.getInt("varianceR", p.varianceR);
  p.varianceF = map.getInt("varianceF", p.varianceF);
  p.varianceK = map.getFloat("varianceK", p.varianceK);
  p.varianceAlpha = map.getFloat("varianceAlpha", p.varianceAlpha);
  for (int v : {p.r, p.f, p.varianceR, p.varianceF})
    if (v < 0 || v > 32) throw Error("nlm: patch and window radii must be in [0, 32]");
  if (!(p.k > 0) || !(p.varianceK > 0)) throw Error("nlm: k must be positive");
  return p;
}

namespace {

// Radiance beyond this is treated as this, so that squared differences stay finite in float.
constexpr float kMaxMagnitude = 1e12f;

Image sanitized(const Image& image) {
  Image out = image;
  for (float& v : out.values())
    v = std::isfinite(v) ? std::clamp(v, -kMaxMagnitude, kMaxMagnitude) : 0.0f;
  return out;
}

// Per-sample variance s = v · n (v where the count is unknown).
Image perSampleVariance(const Image& varianceOfMean, const Image& count) {
  Image out = varianceOfMean;
  if (!count.sameSize(out)) return out;
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) {
      const float n = count(x, y, 0);
      if (n > 0)
        for (int c = 0; c < out.channels(); ++c) out(x, y, c) *= n;
    }
  return out;
}

}  // namespace

Image DualBufferNlMeans::run(const DenoiseInput& input) const {
  if (!input.halves)
    throw Error("nlm: needs two independent halves of its input (render with 2 or 4 sub-buffers)");
  const DualBufferNlMeansParams& p = params_;
  const auto& halves = *input.halves;
  const Image a = sanitized(halves[0].color.mean), b = sanitized(halves[1].color.mean);
  const int w = a.width(), h = a.height(), channels = a.channels();

  // Variance of each half's mean; the two-buffer fallback where a half has a single sample.
  Image vA = sanitized(halfVarianceOfMean(input, 0, Quantity::Color));
  Image vB = sanitized(halfVarianceOfMean(input, 1, Quantity::Color));

  // 1–2. Δ = (A − B)² / 2, smoothed with weights from A's per-sample variance.
  Image delta(w, h, channels), sVar(w, h, channels);
  const Image sA = perSampleVariance(vA, halves[0].sampleCount);
  const Image sB = perSampleVariance(vB, halves[1].sampleCount);
  for (size_t i = 0; i < delta.size(); ++i) {
    const float d = a.data()[i] - b.data()[i], ds = sA.data()[i] - sB.data()[i];
    delta.data()[i] = 0.5f * d * d;
    sVar.data()[i] = 0.5f * ds * ds;
  }
  const Image deltaSmoothed = nlMeans(
      delta,
      NlMeansTerm{.guide = &sA, .variance = &sVar, .f = p.varianceF, .k = p.varianceK,
                  .alpha = p.varianceAlpha, .symmetricRefinement = true},
      NlMeansParams{.r = p.varianceR, .weightBoxRadius = p.varianceF,
                    .weightThreshold = p.weightThreshold, .center = CenterWeight::One});

  // 3. V = min(Δ̃, max(v_A, v_B)).
  Image variance(w, h, channels);
  for (size_t i = 0; i < variance.size(); ++i)
    variance.data()[i] =
        std::min(deltaSmoothed.data()[i], std::max(vA.data()[i], vB.data()[i]));

  // 4. Cross filtering: each half with the weights of the other.
  const NlMeansParams window{.r = p.r, .weightBoxRadius = p.f,
                             .weightThreshold = p.weightThreshold, .center = CenterWeight::One};
  auto crossTerm = [&](const Image& guide) {
    return NlMeansTerm{.guide = &guide, .variance = &variance, .f = p.f, .k = p.k,
                       .alpha = p.alpha, .symmetricRefinement = true};
  };
  const Image aFiltered = nlMeans(a, crossTerm(b), window);
  const Image bFiltered = nlMeans(b, crossTerm(a), window);

  // 5. Count-weighted mean of the two filtered halves.
  Image out(w, h, channels);
  const Image& nA = halves[0].sampleCount;
  const Image& nB = halves[1].sampleCount;
  const bool counts = nA.sameSize(a) && nB.sameSize(b);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float wa = 0.5f, wb = 0.5f;
      if (counts && nA(x, y, 0) + nB(x, y, 0) > 0) {
        wa = nA(x, y, 0) / (nA(x, y, 0) + nB(x, y, 0));
        wb = 1.0f - wa;
      }
      for (int c = 0; c < channels; ++c) {
        const float v = wa * aFiltered(x, y, c) + wb * bFiltered(x, y, c);
        out(x, y, c) = std::isfinite(v) ? v : 0.5f * (a(x, y, c) + b(x, y, c));
      }
    }
  return out;
}

}  // namespace chorus
