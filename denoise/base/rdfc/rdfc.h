#pragma once
// RDFC — "Robust Denoising using Feature and Color Information", Rousselle, Manzi, Zwicker,
// Pacific Graphics 2013; values as in ../shared/docs/base-denoisers.md §3 (the authors' release,
// multifilm.cpp / featurefilter.cu). Runs on the two halves b1, b2 of its input:
//   1. colour variance V: the sample variance of the mean rescaled to the two-buffer level with
//      21×21 boxes (correlated, low-discrepancy samples); gaps in the sample variance (NaN, or 0
//      with one sample per buffer) are filled with the two-buffer estimate (b1 − b2)²/4;
//   2. feature prefiltering (rdfc_features.h);
//   3. the candidates FIRST / SECOND / THIRD with their SURE maps (rdfc_candidates.h);
//   4. selection: every SURE map smoothed by colour-guided NL-means (r = 1, f = 3, k = 1,
//      weights boxed with radius 2), per pixel the argmin (ties go to the later candidate; FIRST
//      only where its mean derivative ≤ SECOND's at the same pixel — the release compares with
//      the wrong pixel there), the three binary maps smoothed the same way with r = 5 → soft
//      weights W_s; first pass Σ W_s F_s / Σ W_s for each buffer;
//   5. second pass on the first-pass buffers: guide their mean, variance (b1' − b2')²/4 smoothed
//      by [e⁻², 1, e⁻²]; r = 5, f = 3, k_c = 0.45, k_f = 0.6, τ = 1e-4, denominators from the
//      centre pixel only (2 k² V(p)), colour weights boxed with radius 2, feature weights not.
//      Output: the mean of the two filtered buffers.
// Deviations (documented in README.md): depth instead of world position; the derivative
// perturbs one channel at a time and counts every role of the perturbed pixel (see
// rdfc_candidates.h); borders are clipped (true counts) instead of mirrored; the symmetric
// refinement of the patchwise colour weights comes before their box filter.
#include <array>
#include <string>

#include "denoise/base/base_denoiser.h"
#include "denoise/base/param_map.h"
#include "denoise/base/rdfc/rdfc_candidates.h"
#include "denoise/base/rdfc/rdfc_features.h"

namespace chorus {

struct RdfcParams {
  RdfcPrefilterParams prefilter;   // feature prefilter (r = 5, f = 3, k = 1, box 2)
  RdfcCandidateParams candidates;  // r = 10; k_c = 0.45; f = 1 / 3; k_f = 0.6; τ = 1e-3 / 1e-4
  bool rescaleVariance = true;     // Box21 rescaling of the colour (and feature) variance
  // Selection: colour-guided NL-means without features.
  int sureR = 1;            // window radius for smoothing the SURE maps
  int selectionR = 5;       // window radius for smoothing the binary selection maps
  int selectionF = 3;       // patch radius
  float selectionK = 1.0f;  // k
  int selectionBoxRadius = 2;
  // Bright pixels' SURE in relative units before its smoothing (selection_knee.h): above
  // selectionKnee × the image's mean |colour|, FIRST's output as the level. 0: the release's.
  float selectionKnee = 4.0f;
  // Second pass.
  int secondR = 5;
  int secondF = 3;
  float secondKc = 0.45f;
  float secondKf = 0.6f;
  float secondTau = 1e-4f;
  int secondBoxRadius = 2;
  // Bright pixels' variance smoothed in relative units above varianceKnee × the image's mean
  // |colour| (the first pass's output as the level). 0: the release's smoothing.
  float varianceKnee = 4.0f;

  // Overrides (CLI names): r, kc, kf, fFirst, fSecond, tau, tauThird, rescale, sureR,
  // selectionR, selectionKnee, varianceKnee, secondR, secondF, secondKc, secondKf, secondTau.
  // Throws chorus::Error for a value out of range.
  static RdfcParams fromParams(ParamMap& params);
};

struct RdfcResult {
  Image output;         // RGB
  Image firstPass;      // RGB: Σ W_s F_s / Σ W_s (mean of both buffers)
  Image colorVariance;  // V used by the candidates and SURE
  std::array<RdfcCandidate, 3> candidates;
  std::array<Image, 3> smoothedSure;      // SURE maps after smoothing (1 channel each)
  Image selection;                        // 1 channel: argmin index (0 FIRST … 2 THIRD)
  std::array<Image, 3> selectionWeights;  // soft weights W_s (1 channel each)
};

// Runs RDFC; the input must have halves (throws chorus::Error otherwise). Every output finite.
RdfcResult runRdfc(const DenoiseInput& input, const RdfcParams& params);

// The second pass's colour variance: the first-pass buffers' (b1 − b2)²/4 smoothed by
// smooth3Tap (w = e^−2), where a pixel whose |level| (the mean over RGB of `guide`, b1 and b2's
// mean) exceeds knee × the image's mean |colour| has its value divided by (level / that)² before
// the smoothing and multiplied back after: relative units for bright pixels (selection_knee.h).
Image rdfcSecondPassVariance(const Image& first1, const Image& first2, const Image& guide,
                             float knee);

class Rdfc : public BaseDenoiser {
 public:
  explicit Rdfc(RdfcParams params = {}) : params_(params) {}
  std::string name() const override { return "rdfc"; }
  DenoiserRequirements requirements() const override { return {.features = true, .halves = true}; }
  Image run(const DenoiseInput& input) const override { return runRdfc(input, params_).output; }

 private:
  RdfcParams params_;
};

}  // namespace chorus
