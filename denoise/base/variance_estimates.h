#pragma once
// Per-pixel variances of the mean that the dual-buffer denoisers feed into their NL-means
// distances, with the two-buffer fallback where a buffer's own estimate does not exist.
//
// A buffer's variance of the mean is M2 / (n (n − 1)): with n = 1 (a quarter at 4 spp) it is 0
// by convention but actually unknown, and a zero variance would make every NL-means distance to
// that pixel huge. There we fall back to the dual-buffer identity (base-denoisers.md §0): for
// halves X1, X2 of equal counts, (X1 − X2)² / 2 estimates each half's variance of the mean and
// (X1 − X2)² / 4 that of their average; the estimate is box-smoothed (5×5) because a single
// squared difference is very noisy. NaN (no sample of a feature in another renderer's buffers)
// is passed through: the NL-means machinery treats it as "matches nothing".
#include "common/image/image.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus {

inline constexpr int kVarianceFallbackRadius = 2;

// The two-buffer estimate ((X1 − X2)² · scale), box-smoothed; finite wherever X1, X2 are.
Image twoBufferVariance(const Image& x1, const Image& x2, float scale);

// Variance of the mean of input.whole's quantity q; where the whole has fewer than 2 samples,
// the smoothed (h1 − h2)² / 4 (needs input.halves).
Image wholeVarianceOfMean(const DenoiseInput& input, Quantity q);

// Variance of the mean of half `which` (0 or 1); where that half has fewer than 2 samples, the
// smoothed (h1 − h2)² / 2.
Image halfVarianceOfMean(const DenoiseInput& input, int which, Quantity q);

}  // namespace chorus
