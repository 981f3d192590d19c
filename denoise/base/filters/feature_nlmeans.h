#pragma once
// NL-means whose weight is the minimum of a patch term and pixel-wise feature terms — the filter
// behind joint NL-means and RDFC's prefilter, selection and second pass (base-denoisers.md §0,
// §3). Between p and q = p + δ (δ in the (2r+1)² window):
//   patch term   — Rousselle's distance on a guide g with variance V, averaged over channels and
//                  over the (2f+1)² patch (true count at the borders), optionally "patchwise"
//                  (the term's weights box-filtered over weightBoxRadius, before the minimum);
//   feature term — the same distance pixel-wise (f = 0) on a feature with variance Var and a
//                  normalising variance Vn in the denominator (RDFC; Vn = Var if absent);
//   d_c = [(g_c(p) − g_c(q))² − α (V_c(p) + min(V_c(p), V_c(q)))] / (ε + k² (Vd_c(p) + Vd_c(q)))
// clamped to 1e4, or with the denominator ε + 2 k² Vd_c(p) ("centre only"). Every term has
// Rousselle's symmetric-pair refinement (distance limit 25; optional for the feature terms);
// weight exp(−max(0, D)); the centre
// weight is the largest neighbour weight, at least minCenterWeight. out(p) = Σ w u(q) / Σ w.
//
// Images must be finite (callers sanitise; a NaN guide or variance makes a pixel match nothing,
// as in nlmeans_weights.h, but NaN data would propagate). Tiles run in parallel (TBB); every
// pixel is summed by one task in a fixed order, so results do not depend on the thread count.
#include <span>
#include <vector>

#include "common/image/image.h"

namespace chorus {

struct PatchTerm {
  const Image* guide = nullptr;     // g
  const Image* variance = nullptr;  // V, the variance of the mean of g (same shape)
  int f = 3;                        // patch radius
  float k = 0.45f;
  float alpha = 1.0f;
  bool centerOnlyDenominator = false;
  int weightBoxRadius = 0;  // "patchwise" NL-means: this term's weights box-filtered
};

struct FeatureTerm {
  const Image* value = nullptr;                // f (any channel count)
  const Image* variance = nullptr;             // Var, in the numerator
  const Image* normalizingVariance = nullptr;  // Vn, in the denominator; null: Var
  float k = 0.6f;
  float alpha = 1.0f;
  bool centerOnlyDenominator = false;
};

struct FeatureNlMeansParams {
  int r = 10;                    // window radius
  float minCenterWeight = 1e-3;  // floor of the centre weight (RDFC's WEIGHT_EPSILON)
  // Symmetric-pair refinement of every feature term (RDFC). Off: the feature weight is
  // exp(−max(0, max over terms of D)) — the same minimum without refinement, at a third of the
  // exponentials.
  bool refineFeatures = true;
};

// Filters every data image (any channel count, the size of the terms' images) with the same
// weights. `patch` may be null (feature terms only); with neither, every weight is 1 (a box).
// Throws std::invalid_argument on mismatched sizes or shapes.
std::vector<Image> featureNlMeans(std::span<const Image* const> data, const PatchTerm* patch,
                                  std::span<const FeatureTerm> features,
                                  const FeatureNlMeansParams& params);

}  // namespace chorus
