#pragma once
// The firefly guard every built-in denoiser's input passes through (guarded_denoiser.h):
// colour values of a sub-buffer that stand far above their neighbourhood while the pixel's own
// samples do not support them are clamped, so that no member spreads them (docs/outliers.md).
//
// Per sub-buffer S of the input (its two halves when it has them, else the whole), per pixel p
// and colour channel, with x = S's mean at p and, over the (2 radius + 1)² neighbours q ≠ p in S:
//   L  = median of the means,  σ_N = max(median of √(variance of the mean), 1.4826 · MAD),
//   Q  = the value exceeded by only a twelfth of the neighbours (the 3rd largest of 24),
//   T  = max(L + ceilingSigmas · σ_N, highFactor · Q)  (Q itself when Q ≤ 0).
// (Q keeps sparse but ordinary samples — a dim region lit by a few paths, where L and σ_N are
// 0 — from counting as outliers: a firefly stands far above even the brightest neighbours.)
// x > T is an outlier unless the pixel's samples confirm the excess: pooled with the other half
// at p when there is one (else S's own), n ≥ 2 samples whose mean m has
// m − L > confirmSigmas · √(variance of the mean). A single sample V among n gives a mean V / n
// with exactly that standard error (excess / error = 1); j such samples give √j, so with enough
// samples every real excess is confirmed and nothing is clamped (consistent). An outlier
// becomes S's mean without its largest sample (see withoutLargestSample; L for a single
// sample), kept within [min(0, L), T]; its variance of the mean min(v, max(σ_N², (x' − L)²)).
// What it had above that is dropped when the outlier is alone, but spread over the
// (2 R + 1)² window around it (Gaussian weights, σ = R / 2, times Gaussians in the relative
// depth and albedo differences and in the normals' difference: what the outlier's pixel sees
// only; what would fall elsewhere is dropped) when it has peers: x − L ≤ peerSigmas × the RMS
// deviation of the neighbours from L, i.e. a few neighbours deviate as much, or when the
// (2 R + 1)² window holds, on what the outlier's pixel sees, values at least a quarter as far
// above L that together stand as far above it as the outlier does and fill an area, not a line
// (a wall lit by rare paths at a few samples, whose 5 × 5 neighbourhoods seldom hold two; a
// light's edge or a glint is a line, whose excess spread beside it became a halo). Such
// outliers are the samples of a heavy-tailed distribution that is really there: dropping
// them would darken the caustic at any sample count the guard still acts at; spread, they keep
// its energy in the window and lose only their variance. R = spreadRadius, or where L > 0
// and the blob would peak above spreadPeak × (L + σ_N), the radius at which it does not (at
// most kMaxGuardSpread): a rare path's excess in a dark neighbourhood is spread thin.
// Each sub-buffer is judged on its own neighbourhood and the samples of the input it belongs
// to, so runs on half A still see only half A. When the halves change, the whole is re-merged
// from them at those pixels (whole = merge(halves) keeps holding).
#include <cstddef>

#include "denoise/buffers/sample_buffers.h"

namespace chorus {

inline constexpr int kMaxGuardSpread = 32;

struct OutlierGuardOptions {
  int radius = 2;
  float ceilingSigmas = 8.0f;  // 0: the guard is off
  float highFactor = 4.0f;
  float confirmSigmas = 2.5f;
  float peerSigmas = 6.0f;
  int spreadRadius = 6;     // a member spec's spread=R (1 … kMaxGuardSpread)
  float spreadPeak = 1.0f;  // wider where the blob would peak above this × (L + σ_N); 0: never
  bool operator==(const OutlierGuardOptions&) const = default;
};

struct GuardedInput {
  DenoiseInput input;
  size_t clampedValues = 0;  // colour values of the sub-buffers that were clamped
};

GuardedInput guardOutliers(DenoiseInput input, const OutlierGuardOptions& options = {});

}  // namespace chorus
