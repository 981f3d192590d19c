#pragma once
// Smoothing of the per-pixel ensemble weights (Zheng et al. 2021, §4.3): a joint
// (cross-)bilateral filter guided by the normal, the albedo and the blended colour with its
// A/B variance (or the held-out blends' spread), then renormalisation onto the simplex. Values
// follow the reference code (radius 7, spatial σ 3, colour σ 2 on the variance-normalised distance,
// normal/albedo terms).
//
// For a pixel p and neighbour q (|q − p|∞ ≤ radius, inside the image):
//   k(p,q) = exp(− |p−q|²/(2σ_s²)
//                − Σ_c (z_c(p) − z_c(q))² / (V_c(p) + V_c(q) + ε) / (2σ_z²)
//                − |n(p) − n(q)|²/(2σ_n²) − |a(p) − a(q)|²/(2σ_a²)),
//   w'_i(p) = Σ_q k(p,q) w_i(q) / Σ_q k(p,q).
// z is the blend made with the unfiltered weights, divided by its mean |z| over the image (so
// that the filter is scale invariant), V the Gaussian-blurred ½(z^A − z^B)² (the variance of
// a half blend), ε = 1e-6 (in the normalised units).
#include <span>
#include <vector>

#include "common/image/image.h"
#include "denoise/ensemble/ensemble_types.h"

namespace chorus {

struct WeightFilterOptions {
  bool enabled = true;
  int radius = 7;              // window (2r+1)², pixels
  float sigmaSpatial = 3.0f;   // σ_s, pixels
  float sigmaColor = 2.0f;     // σ_z, on the variance-normalised colour distance
  float sigmaNormal = 0.2f;    // σ_n, on unit normals
  float sigmaAlbedo = 0.5f;    // σ_a
  int varianceBlurRadius = 4;  // Gaussian blur of ½(z^A − z^B)²: 9×9, σ = 1.7 (as OpenCV's
  float varianceBlurSigma = 1.7f;  // GaussianBlur with ksize 9 in the reference code)
  // Added to the guide's V as (tolerance · z)² after the blur: differences within that fraction
  // of z never separate two pixels (0 here; the MSE window's colour term uses 0.05).
  double relativeTolerance = 0.0;
};

// The colour guide of the filter: z / s and V / s², s = mean |z| over the finite values,
// clamped to |z/s| ≤ 1e6 and V/s² ≤ 1e12 (differences beyond that are all "very different";
// the bounds keep the kernel's products finite in float).
struct ColorGuide {
  Image color;     // RGB
  Image variance;  // RGB
};
ColorGuide makeColorGuide(const Image& blend, const Image& blendA, const Image& blendB,
                          const WeightFilterOptions& options);
// The same without half runs: V from the four leave-one-quarter-out blends z^(−k),
// 1.5 Σ_k (z^(−k) − z̄)², which has the expectation of ½(z^A − z^B)² for a linear blend (the
// folds differ by a third of a quarter's noise each).
ColorGuide makeColorGuide(const Image& blend, std::span<const Image> heldOutBlends,
                          const WeightFilterOptions& options);

// Filters every channel of every map with the same kernel k(p,q) (maps: same size, any number
// of channels each). Deterministic for any thread count. Non-finite map values count as 0.
std::vector<Image> crossBilateralFilter(std::span<const Image> maps, const ColorGuide& guide,
                                        const Image& normal, const Image& albedo,
                                        const WeightFilterOptions& options);

// Projects filtered weights back onto the simplex, per pixel and weight channel: bases not in
// valid[p] get 0; with `nonNegative` negatives are clipped to 0; the rest is divided by its
// sum. Where nothing is left (sum 0 or not finite) the `fallback` weights are used.
std::vector<Image> renormalizeWeights(std::span<const Image> weights,
                                      std::span<const BaseMask> valid,
                                      std::span<const Image> fallback, bool nonNegative);

}  // namespace chorus
