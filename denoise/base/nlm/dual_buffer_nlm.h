#pragma once
// NL-means with dual-buffer variance (Rousselle, Knaus, Zwicker, "Adaptive Sampling and
// Reconstruction using Greedy Error Minimization"/"Robust Denoising using Feature and Color
// Information" line of work; SIGGRAPH Asia 2012 `nlmkernel.cu`), as in base-denoisers.md §4:
//   1. Δ = (A − B)² / 2, an unbiased but noisy estimate of each half's variance of the mean;
//   2. Δ smoothed by NL-means guided by the per-sample variance of A (r = 1, α = 4);
//   3. V = min(Δ̃, max(v_A, v_B)) (the buffers' own variance estimates bound it; see
//      DualBufferNlMeansParams::sampling for random sampling and buffers without them);
//   4. A filtered with weights computed on B (cross filtering: the data never chooses its own
//      weights), B with weights on A — colour distances averaged over RGB, symmetric-pair
//      refinement, patchwise weights, weights below 0.05 dropped, centre weight 1;
//   5. output = count-weighted mean of the two filtered halves.
// Where a half holds a single sample its own variance does not exist; it falls back to the
// smoothed two-buffer estimate (variance_estimates.h).
#include <string>

#include "denoise/base/base_denoiser.h"
#include "denoise/base/param_map.h"

namespace chorus {

// Values of the reference code's final (non-adaptive) pass and its scene files.
struct DualBufferNlMeansParams {
  int r = 10;          // search window radius
  int f = 3;           // patch radius (also the patchwise weight box radius)
  float k = 0.45f;     // distance sensitivity
  float alpha = 1.0f;  // variance cancellation strength
  float weightThreshold = 0.05f;
  // Smoothing of the variance estimate Δ (step 2).
  int varianceR = 1, varianceF = 3;
  float varianceK = 0.45f, varianceAlpha = 4.0f;
  // "ld": the buffers were sampled with a low-discrepancy sequence (chorus's renderer), whose
  // per-buffer sample variance over-estimates the error of the mean: steps 1–3 as in the
  // reference. "random": independent random samples: each half is filtered with the other
  // half's own variance of the mean. Inputs whose halves carry no independent variances
  // (Tungsten's buffers) always take the random path.
  std::string sampling = "ld";

  // Reads overrides (keys = the field names); unread keys stay in the map.
  static DualBufferNlMeansParams fromParams(ParamMap& map);
};

class DualBufferNlMeans : public BaseDenoiser {
 public:
  explicit DualBufferNlMeans(const DualBufferNlMeansParams& params = {}) : params_(params) {}
  std::string name() const override { return "nlm"; }
  DenoiserRequirements requirements() const override { return {.features = false, .halves = true}; }
  // Throws chorus::Error when the input has no halves.
  Image run(const DenoiseInput& input) const override;

 private:
  DualBufferNlMeansParams params_;
};

}  // namespace chorus
