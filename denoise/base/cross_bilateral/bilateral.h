#pragma once
// Joint cross-bilateral filter guided by normal, albedo and depth with an optional colour range
// term: a single candidate of SBF (sbf.h, cross_bilateral.h) with the colour term that Li et
// al.'s release turned off. Weight between p and q:
//   exp(−|p−q|²/(2σ_s²) − Σ_k Δf_k² / (2σ_k² max(var_k(p)+var_k(q), 0.01))
//       − Σ_c Δc_c² / (2σ_c² (V_c(p)+V_c(q)) + 1e-10))
// with per-sample feature variances var_k and the colour's variance of the mean V_c, so σ_c is
// measured in noise standard deviations (our choice; a fixed σ_c on radiance is
// scene-dependent). Window radius round(2σ_s), clipped and renormalised at the borders.
#include <string>

#include "denoise/base/base_denoiser.h"
#include "denoise/base/param_map.h"

namespace chorus {

struct BilateralParams {
  float sigmaS = 4.0f;   // spatial width, pixels (our choice by measurement, see
                         // docs/members/sbf-atrous-bilateral.md)
  float sigmaC = 3.0f;   // colour range width in noise standard deviations; 0 = no colour term
                         // (our choice by measurement, see docs/members/sbf-atrous-bilateral.md)
  float sigmaN = 0.8f;   // normal range width (SBF release default)
  float sigmaR = 0.25f;  // reflectance (albedo) range width (SBF release default)
  float sigmaD = 0.6f;   // depth range width on depth / largest finite depth (SBF release default)

  // Reads overrides sigmaS, sigmaC, sigmaN, sigmaR, sigmaD; throws chorus::Error when invalid.
  static BilateralParams fromParams(ParamMap& params);
};

class Bilateral : public BaseDenoiser {
 public:
  explicit Bilateral(BilateralParams params = {}) : params_(params) {}
  std::string name() const override { return "bilateral"; }
  DenoiserRequirements requirements() const override { return {.features = true, .halves = false}; }
  Image run(const DenoiseInput& input) const override;

 private:
  BilateralParams params_;
};

}  // namespace chorus
