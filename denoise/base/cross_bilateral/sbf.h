#pragma once
// SURE-based filtering (Li, Wu, Chuang, "SURE-based Optimization for Adaptive Sampling and
// Reconstruction", SIGGRAPH Asia 2012), reconstruction part; values as in
// ../shared/docs/base-denoisers.md §5:
//   1. one feature-guided cross-bilateral candidate per spatial width σ_s (cross_bilateral.h),
//      with per-sample feature variances and no colour range term (as in the authors' release);
//   2. SURE of every candidate per pixel, from the colour's variance of the mean (sure.h);
//   3. every SURE map smoothed by a feature-only cross-bilateral of width sigmaMse;
//   4. per pixel the candidate with the smallest smoothed SURE (hard selection, no blending).
// Deviations: no adaptive sampling (chorus renders a fixed budget), so only the final-image
// settings are used; bright pixels' SURE in relative units before step 3 (selectionKnee).
#include <string>
#include <vector>

#include "denoise/base/base_denoiser.h"
#include "denoise/base/param_map.h"

namespace chorus {

struct SbfParams {
  // Candidate spatial widths σ_s in pixels (window radius round(2σ_s); 0 = the noisy input).
  // The paper's set was not found in the indexed sources: {0, 1, 2, 4, 8} is our assumption.
  std::vector<float> sigmaS = {0, 1, 2, 4, 8};
  float sigmaN = 0.8f;   // normal range width (release / pbrt-v3 port default)
  float sigmaR = 0.25f;  // reflectance (albedo, "texture") range width (same source)
  float sigmaD = 0.6f;   // depth range width, depth divided by the largest finite depth
  // Spatial width of the SURE-map smoothing; 0 (default): sureSmoothingWidth of the buffer's
  // samples per pixel (the release uses 8 for the final image, 4 while sampling adaptively).
  float sigmaMse = 0.0f;
  // Not the release's: pixels brighter than this times the image's mean |colour| enter step 3
  // with their SURE in relative units (denoise/base/selection_knee.h); 0 = the release's.
  float selectionKnee = 16.0f;
  // Not the release's, off by default: from `calibrateFrom` samples per pixel of the render on,
  // SURE takes the colour variance calibrated to the halves over a box of this radius, capped
  // at 1 (variance_calibration.h: the recorded variance overstates the noise of stratified
  // samples, up to 2.4× at 256 spp, and SURE then prefers wide candidates that blur what the
  // samples resolve), and smooths its maps kCalibratedSureSmoothing times wider (the calibrated
  // SURE is noisier). calibrate=3 makes SBF alone better from 16 spp on, on both halves of the
  // corpus, but the ensembles with it blend worse on the tuning half
  // (docs/members/sbf-atrous-bilateral.md); 0 = the recorded variance.
  int calibrationRadius = 0;
  float calibrateFrom = 16.0f;

  // Reads overrides: sigmaS=0/1/2/4/8 (slash-separated), sigmaN, sigmaR, sigmaD, sigmaMse,
  // selectionKnee, calibrate (the radius), calibrateFrom.
  // Throws chorus::Error for a value out of range.
  static SbfParams fromParams(ParamMap& params);
};

struct SbfResult {
  Image output;     // RGB
  Image selection;  // 1 channel: index into sigmaS of the candidate chosen per pixel
};

// The SURE maps' smoothing width for a buffer with `spp` samples per pixel: 16/√spp pixels,
// within [2, 8]. A pixel's SURE is as noisy as its colour (standard deviation ∝ 1/√spp), so the
// area that averages it to a given precision shrinks as 1/spp, its width as 1/√spp; a fixed 8
// averages fine detail away at high spp, where SBF then picks a wide candidate over detail that
// its own samples resolve. Chosen on the corpus's tuning half
// (docs/members/sbf-atrous-bilateral.md).
float sureSmoothingWidth(double spp);

// How much wider the SURE maps are smoothed when SURE takes the calibrated variance.
inline constexpr float kCalibratedSureSmoothing = 1.5f;

// Runs SBF on one buffer (colour, its variance of the mean, normal, albedo, depth, sample count);
// with `sureVariance` (the calibrated one), SURE takes that variance of the colour's mean instead
// of the buffer's and smooths its maps kCalibratedSureSmoothing times wider.
SbfResult runSbf(const SubBuffer& buffer, const SbfParams& params,
                 const Image* sureVariance = nullptr);

class Sbf : public BaseDenoiser {
 public:
  explicit Sbf(SbfParams params = {}) : params_(std::move(params)) {}
  std::string name() const override { return "sbf"; }
  // The calibration compares the halves when the input has them.
  DenoiserRequirements requirements() const override {
    return {.features = true, .halves = false, .readsHalves = params_.calibrationRadius > 0};
  }
  Image run(const DenoiseInput& input) const override;

 private:
  SbfParams params_;
};

}  // namespace chorus
