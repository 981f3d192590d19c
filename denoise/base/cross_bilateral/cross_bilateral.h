#pragma once
// Joint (cross) bilateral filtering guided by features, the building block of SBF (Li, Wu,
// Chuang 2012) and of the `bilateral` denoiser. Between pixels p and q, with δ = q − p:
//
//   w(p,q) = exp( −|δ|²/(2σ_s²)
//                 − Σ_k (f_k(p) − f_k(q))² / (2σ_k² max(var_k(p) + var_k(q), 0.01))
//                 − Σ_c (c_c(p) − c_c(q))² / (2σ_c² (V_c(p) + V_c(q)) + 1e-10) )
//
// f_k: feature channels, var_k: their per-sample variances (Li et al.'s Mahalanobis-like
// distance, floor 0.01 as in their release); the last (colour range) term is optional (σ_c = 0
// turns it off, as in SBF's release) and uses the colour's variance of the mean V, so σ_c is a
// number of noise standard deviations (our choice: a fixed σ_c on radiance is scene-dependent).
// Window: radius round(2σ_s) (σ_s = 0: the pixel itself), clipped at the image borders; the
// output is Σ_q w c(q) / Σ_q w, so clipped windows are renormalised by the weights used.
#include <span>
#include <vector>

#include "denoise/buffers/sample_buffers.h"
#include "denoise/planes/planar_image.h"

namespace chorus {

// Feature range widths σ_k (Li et al. 2012 release / pbrt-v3 port defaults); ≤ 0 drops a feature.
struct FeatureSigmas {
  float normal = 0.8f;   // σ for each normal component (world-space, unit length)
  float albedo = 0.25f;  // σ for each albedo (texture) channel
  float depth = 0.6f;    // σ for depth divided by the buffer's largest finite depth
};

// The guide of a cross-bilateral filter: feature planes pre-scaled by 1/(√2 σ_k) and their
// per-sample variances (unscaled: the floor 0.01 applies to the variance itself).
struct FeatureGuide {
  PlanarImage value;
  PlanarImage variance;
};

// Normal (3), albedo (3) and normalised depth (1) of `buffer`, sanitised (see input_planes.h).
FeatureGuide makeFeatureGuide(const SubBuffer& buffer, const FeatureSigmas& sigmas);

// One candidate of crossBilateralCandidates: the filtered colour and, per channel, the exact
// derivative ∂F_c(p)/∂c_c(p) of the output with respect to its own input pixel (for SURE).
struct BilateralCandidate {
  PlanarImage filtered;
  PlanarImage derivative;
};

// Filters `color` once per spatial σ in `sigmaS` (any order; outputs in the same order), all in
// one pass over the largest window: the feature term is shared by every σ. sigmaC = 0 turns the
// colour range term off; then the derivative is exactly 1/Σw (the centre weight is 1).
// Deterministic for any thread count.
std::vector<BilateralCandidate> crossBilateralCandidates(const PlanarImage& color,
                                                         const PlanarImage& colorVariance,
                                                         const FeatureGuide& guide,
                                                         std::span<const float> sigmaS,
                                                         float sigmaC);

// Smooths every plane of `maps` with the same feature-only weights of spatial width σ_s.
PlanarImage crossBilateralSmooth(const PlanarImage& maps, const FeatureGuide& guide, float sigmaS);

}  // namespace chorus
