#pragma once
// The firefly guard every built-in denoiser's input passes through (guarded_denoiser.h):
// colour values of a sub-buffer that stand far above their neighbourhood while the pixel's own
// samples do not support them are clamped, so that no member spreads them (docs/outliers.md).
//
// Per sub-buffer S of the input (its two halves when it has them, else the whole), per pixel p
// and colour channel, with x = S's mean at p and, over the (2 radius + 1)² neighbours q ≠ p in S:
//   L  = median of the means,  σ_N = max(median of √(variance of the mean), 1.4826 · MAD),
//   Q  = the value exceeded by only a sixth of the neighbours (4th largest of 24),
//   T  = max(L + ceilingSigmas · σ_N, Q, otherHalfRatio · (the other half's mean at p)).
// x > T is an outlier unless its own samples confirm the excess: n ≥ 2 and
// x − L > confirmSigmas · √(variance of the mean at p). A single sample V among n gives a mean
// V / n with exactly that standard error (excess / error = 1); j such samples give √j, so with
// enough samples every real excess is confirmed and nothing is clamped (consistent). Outliers
// become T, their variance of the mean min(v, max(σ_N², (T − L)²)).
// Each sub-buffer is judged on its own samples and its own neighbourhood (plus the other half of
// the same input), so runs on half A still see only half A. When the halves change, the whole is
// re-merged from them at those pixels (whole = merge(halves) keeps holding).
#include <cstddef>

#include "denoise/buffers/sample_buffers.h"

namespace chorus {

struct OutlierGuardOptions {
  int radius = 2;
  float ceilingSigmas = 8.0f;  // 0: the guard is off
  float confirmSigmas = 2.5f;
  float otherHalfRatio = 2.0f;
};

struct GuardedInput {
  DenoiseInput input;
  size_t clampedValues = 0;  // colour values of the sub-buffers that were clamped
};

GuardedInput guardOutliers(DenoiseInput input, const OutlierGuardOptions& options = {});

}  // namespace chorus
