#pragma once
// Joint NL-means: Rousselle's NL-means on colour (patch distance with variance cancellation,
// base-denoisers.md §0) whose weights are additionally limited by pixel-wise range terms on
// albedo, normal and depth (each with its variance, RDFC-style normalisation), the weight being
// the minimum over the terms (feature_nlmeans.h). With two halves of its input it cross-filters:
// half A with the colour weights of half B and vice versa (RKZ12, §4), so the data never choose
// their own weights, and returns the mean of both; without halves it filters the whole buffer
// with its own weights. A strong, simple member of the ensemble.
//
// Colour variance of a half: its variance of the mean, or where it holds a single sample the
// box-smoothed two-buffer estimate (A − B)²/2 (variance_estimates.h, shared with `nlm`), brought
// to the halves' level (variance_calibration.h: the sampler stratifies, so a recorded variance
// overestimates the noise; k 0.6 rather than Rousselle's 0.45 with it, docs/members/); features
// are the whole input's (mapped as in RDFC: normal (n + 1)/2, albedo / max(1, largest channel)),
// normalised by Vn = max(Var, max(G, τ)) with G the squared gradient and τ · maxDepth² for depth;
// features without statistics (NaN variance) are neutral there. Centre weight: the largest
// neighbour weight (at least 1e-3).
#include <string>

#include "denoise/base/base_denoiser.h"
#include "denoise/base/param_map.h"

namespace chorus {

struct JointNlMeansParams {
  int r =
      4;  // window radius: (2r+1)² neighbours (the speed target decides, docs/members/rdfc-jnlm.md)
  int f = 2;           // colour patch radius
  float k = 0.6f;      // colour sensitivity (Rousselle et al.'s NL-means k, there 0.45)
  float alpha = 1.0f;  // strength of the variance cancellation
  float kf = 0.6f;     // feature sensitivity (RDFC's k_f)
  float tau = 1e-3f;  // feature variance floor (depth: τ · maxDepth²), RDFC's FIRST/SECOND value
  bool refineFeatures = false;  // symmetric refinement of the feature terms (RDFC: on)
  // The colour variance of a pixel whose level exceeds varianceKnee × the image's mean |colour|
  // divided by (level / that)² in the patch distances (selection_knee.h). 0: Rousselle's.
  float varianceKnee = 64.0f;
  // The box radius of the colour variance's calibration to the halves (0: the recorded variance
  // as is; inputs without halves keep it too).
  int calibrationRadius = 3;

  // Overrides: r, f, k, alpha, kf, tau, refineFeatures, varianceKnee, calibrate (the calibration
  // radius). Throws chorus::Error for a value out of range.
  static JointNlMeansParams fromParams(ParamMap& params);
};

// Runs joint NL-means on any input (cross-filtered when it has halves). Every output finite.
Image runJointNlMeans(const DenoiseInput& input, const JointNlMeansParams& params);

class JointNlMeans : public BaseDenoiser {
 public:
  explicit JointNlMeans(JointNlMeansParams params = {}) : params_(params) {}
  std::string name() const override { return "jnlm"; }
  // Uses halves when present but does not need them.
  DenoiserRequirements requirements() const override {
    return {.features = true, .halves = false, .readsHalves = true};
  }
  Image run(const DenoiseInput& input) const override { return runJointNlMeans(input, params_); }

 private:
  JointNlMeansParams params_;
};

}  // namespace chorus
