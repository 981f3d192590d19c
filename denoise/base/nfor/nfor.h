#pragma once
// NFOR — nonlinearly weighted first-order regression (Bitterli, Rousselle, Moon, Iglesias-Guitián,
// Adler, Mitchell, Jarosz, Novák; Computer Graphics Forum / EGSR 2016), step by step as in the
// first author's own implementation in Tungsten (src/denoiser/denoiser.cpp), summarised in
// base-denoisers.md §2:
//   1. feature cross-prefiltering: each half's features NL-means filtered with weights from the
//      other half (§5.1);
//   2. collaborative first-order regression of each half's colour on the other half's filtered
//      features, with NL-means weights from the other half's colour, for two bandwidths k (§5.2);
//   3. a dual-buffer MSE estimate per bandwidth, NL-means smoothed; a per-channel selection map,
//      smoothed the same way, blends the two bandwidths (§5.3);
//   4. a second regression of the blended halves' mean on the re-filtered mean features (§5.4).
// Features, in Tungsten's order: depth, albedo R G B, normal x y z, visibility.
// Deviations from Tungsten (docs/members/nfor-nlm.md): a Gram-matrix solver with rank-revealing
// pivoting instead of Eigen's column-pivoted QR on the window matrix (same fitted values for
// full-rank windows), float sums in other orders, the NL-means average where a regression
// extrapolates far beyond its window's data, and very bright pixels' MSE scaled down before
// the selection's smoothing (selectionKnee).
#include "denoise/base/base_denoiser.h"
#include "denoise/base/param_map.h"

namespace chorus {

// Parameters of NFOR: the values of Tungsten's implementation. f: patch radius, r: window
// radius, k: NL-means sensitivity (bandwidth) — the symbols of base-denoisers.md §0.
struct NforParams {
  // 1. Feature cross-prefilter (per channel, guide = the other half, variance scale 2).
  int prefilterF = 3, prefilterR = 5;
  float prefilterK = 0.5f;
  // 2. Regression: patch, window and the two candidate bandwidths.
  int regressionF = 3, regressionR = 9;
  float k1 = 0.5f, k2 = 1.0f;
  // 3. MSE and selection-map smoothing (per channel, guide = the whole input's colour).
  int mseF = 1, mseR = 9;
  float mseK = 1.0f;
  // 4. Second pass: final feature filter and final regression.
  int finalFeatureF = 3, finalFeatureR = 2;
  float finalFeatureK = 0.5f;
  int finalF = 3, finalR = 9;
  float finalK = 1.0f;
  // NL-means constants of Tungsten's nlMeansWeights.
  float epsilon = 1e-7f, distanceClamp = 1e4f, minCenterWeight = 1e-4f;
  // Not Tungsten's: pixels brighter than this times the image's mean |colour| enter the MSE
  // smoothing of step 3 scaled down to that level (relative error above it); 0 = Tungsten's.
  float selectionKnee = 16.0f;
  // Not Tungsten's, off by default: above this times the image's mean |colour| a pixel's
  // colour variance is divided by (level / that)² in both passes' regression weights, so that
  // a bright pixel's noise no longer excuses its difference from dark neighbours
  // (selection_knee.h). 64 takes NFOR alone from 2.4 to 0.11 relMSE on a thin light at 4 spp
  // and 0.894 / 0.982 of its error on the corpus's halves, but the ensembles blend 1.0005×
  // worse on the validation half (docs/members/nfor-nlm.md); 0 = Tungsten's.
  float varianceKnee = 0.0f;

  // Reads overrides (keys = the field names above); unread keys stay in the map.
  static NforParams fromParams(ParamMap& map);
};

class NforDenoiser : public BaseDenoiser {
 public:
  explicit NforDenoiser(const NforParams& params = {}) : params_(params) {}
  std::string name() const override { return "nfor"; }
  DenoiserRequirements requirements() const override { return {.features = true, .halves = true}; }
  // Throws chorus::Error when the input has no halves.
  Image run(const DenoiseInput& input) const override;

 private:
  NforParams params_;
};

}  // namespace chorus
