#include "denoise/base/nlm/dual_buffer_nlm.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/error.h"
#include "denoise/base/filters/nlmeans_filter.h"
#include "denoise/base/input_planes.h"
#include "denoise/base/variance_estimates.h"

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
  p.sampling = map.getString("sampling", p.sampling);
  if (p.sampling != "ld" && p.sampling != "random")
    throw Error("nlm: sampling must be 'ld' or 'random', not '" + p.sampling + "'");
  for (int v : {p.r, p.f, p.varianceR, p.varianceF})
    if (v < 0 || v > 32) throw Error("nlm: patch and window radii must be in [0, 32]");
  if (!(p.k > 0) || !(p.varianceK > 0)) throw Error("nlm: k must be positive");
  return p;
}

namespace {

// A variance this many times the guide's square makes every weight 1 (a guide that says
// nothing: the smoothing of Δ becomes a plain patchwise box).
constexpr float kUninformativeScale = 1e6f;

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
  const Image a = clampedFinite(halves[0].color.mean), b = clampedFinite(halves[1].color.mean);
  const int w = a.width(), h = a.height(), channels = a.channels();

  // Variance of each half's mean; the two-buffer fallback where a half has a single sample.
  const Image vA = clampedFinite(halfVarianceOfMean(input, 0, Quantity::Color));
  const Image vB = clampedFinite(halfVarianceOfMean(input, 1, Quantity::Color));
  const Image& nA = halves[0].sampleCount;
  const Image& nB = halves[1].sampleCount;
  const bool counts = nA.sameSize(a) && nB.sameSize(b);
  auto ownVariances = [&](int x, int y) {
    return !counts || (nA(x, y, 0) >= 2 && nB(x, y, 0) >= 2);
  };
  // Tungsten's buffers store one variance for both halves: they are then no independent
  // estimates, and (sA − sB)² below is identically 0.
  const bool independent = !std::equal(vA.values().begin(), vA.values().end(), vB.values().begin());

  // 1–2. Δ = (A − B)² / 2, smoothed with weights from A's per-sample variance sA, whose own
  // variance is (sA − sB)² / 2 for independent estimates, else the Gaussian 2 sA² / (n − 1)
  // (and uninformative — weights 1 — where a half has a single sample).
  Image delta(w, h, channels), sVar(w, h, channels);
  const Image sA = perSampleVariance(vA, nA);
  const Image sB = perSampleVariance(vB, nB);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) {
        const float d = a(x, y, c) - b(x, y, c), s = sA(x, y, c), ds = s - sB(x, y, c);
        delta(x, y, c) = 0.5f * d * d;
        if (independent)
          sVar(x, y, c) = 0.5f * ds * ds;
        else if (ownVariances(x, y) && counts)
          sVar(x, y, c) = 2.0f * s * s / (nA(x, y, 0) - 1.0f);
        else
          sVar(x, y, c) = kUninformativeScale * s * s;
      }
  const Image deltaSmoothed = nlMeans(delta,
                                      NlMeansTerm{.guide = &sA,
                                                  .variance = &sVar,
                                                  .f = p.varianceF,
                                                  .k = p.varianceK,
                                                  .alpha = p.varianceAlpha,
                                                  .symmetricRefinement = true},
                                      NlMeansParams{.r = p.varianceR,
                                                    .weightBoxRadius = p.varianceF,
                                                    .weightThreshold = p.weightThreshold,
                                                    .center = CenterWeight::One});

  // 3. The variance of the guide's mean for filtering A (guide B) and B (guide A):
  //  - low-discrepancy sampling, independent per-half estimates (the reference code's path):
  //    V = min(Δ̃, max(v_A, v_B)) — the sample variance over-estimates an LD mean's error and
  //    bounds the dual-buffer estimate Δ̃;
  //  - random sampling, or halves without independent estimates: v_B for A and v_A for B (the
  //    reference's non-LD path; measured far better on Tungsten's buffers: room 4 spp relMSE
  //    0.0025 instead of 0.033);
  //  - a half with a single sample has no variance of its own: V = Δ̃ (the min of two
  //    two-buffer estimates of the same quantity would be biased low).
  Image varianceForA(w, h, channels), varianceForB(w, h, channels);
  const bool lowDiscrepancy = p.sampling == "ld" && independent;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool own = ownVariances(x, y);
      for (int c = 0; c < channels; ++c) {
        const float smoothed = deltaSmoothed(x, y, c);
        if (!own) {
          varianceForA(x, y, c) = varianceForB(x, y, c) = smoothed;
        } else if (lowDiscrepancy) {
          varianceForA(x, y, c) = varianceForB(x, y, c) =
              std::min(smoothed, std::max(vA(x, y, c), vB(x, y, c)));
        } else {
          varianceForA(x, y, c) = vB(x, y, c);
          varianceForB(x, y, c) = vA(x, y, c);
        }
      }
    }

  // 4. Cross filtering: each half with the weights of the other.
  const NlMeansParams window{.r = p.r,
                             .weightBoxRadius = p.f,
                             .weightThreshold = p.weightThreshold,
                             .center = CenterWeight::One};
  auto crossTerm = [&](const Image& guide, const Image& variance) {
    return NlMeansTerm{.guide = &guide,
                       .variance = &variance,
                       .f = p.f,
                       .k = p.k,
                       .alpha = p.alpha,
                       .symmetricRefinement = true};
  };
  const Image aFiltered = nlMeans(a, crossTerm(b, varianceForA), window);
  const Image bFiltered = nlMeans(b, crossTerm(a, varianceForB), window);

  // 5. Count-weighted mean of the two filtered halves.
  Image out(w, h, channels);
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
