#pragma once
// Variance estimates from two independent buffers of the same pixels, and the small filters RDFC
// applies to variances and features (../shared/docs/base-denoisers.md §0, §3). All images are
// interleaved float images of one size; every function returns finite values (non-finite inputs
// count as missing).
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "common/image/image.h"

namespace chorus {

// Variance given to a feature pixel whose statistics are missing (no sample of the feature, NaN
// variance in Tungsten's buffers): so large that a range term on that feature never separates
// the pixel from anything, i.e. the feature is neutral there.
inline constexpr float kNeutralVariance = 1e30f;

// Copy of `image` with NaN/Inf replaced by `replacement`.
Image finiteOr(const Image& image, float replacement);

// One value: itself when finite, else 0.
inline float finiteOrZero(float v) {
  return std::isfinite(v) ? v : 0.0f;
}

// Per pixel: 1 where every channel of every listed image is finite, else 0.
std::vector<uint8_t> finiteMask(std::initializer_list<const Image*> images);

// (a + b) / 2 per channel: the mean of two buffers of equal sample counts (elements in parallel).
Image meanOf(const Image& a, const Image& b);

// (a − b)² · scale per channel, 0 where a or b is not finite. With scale 1/4 this is an unbiased
// estimate of the variance of the mean of (a + b) / 2, with 1/2 of the variance of each buffer's
// mean (equal sample counts, independent samples; §0).
Image squaredDifference(const Image& a, const Image& b, float scale);

// The variance of the mean `sampleVariance` with its gaps filled by the two-buffer estimate
// `twoBuffer` of the same quantity: where it is not finite or negative, or 0 while twoBuffer > 0
// (0 is then not "noise-free" but "not measured", e.g. a single sample per sub-buffer).
Image completedVariance(const Image& sampleVariance, const Image& twoBuffer);

// RDFC's variance for correlated (low-discrepancy) samples, §3:
//   V = σ² · Box(v_buf) / (ε + Box(σ²)),  Box = (2 radius + 1)² box, ε = 1e-10:
// the spatial structure of the sample variance σ² at the level of the two-buffer estimate v_buf.
// Pixels with mask 0 (when given) are left out of both box sums and get V = 0.
Image rescaledVariance(const Image& sampleVariance, const Image& twoBuffer, int radius,
                       const std::vector<uint8_t>* mask = nullptr);

// Separable 3-tap smoothing with taps [w, 1, w], normalised by the taps used: taps outside the
// image or on pixels with mask 0 are skipped (RDFC smooths (f̃1 − f̃2)²/4 with w = e^−2).
Image smooth3Tap(const Image& image, float sideWeight, const std::vector<uint8_t>* mask = nullptr);

// RDFC's squared gradient: per axis the smaller of the two squared half-differences
// ((f(x ± 1) − f(x)) / 2)², summed over x and y. An axis contributes 0 at the border and where a
// neighbour has mask 0.
Image squaredGradient(const Image& image, const std::vector<uint8_t>* mask = nullptr);

}  // namespace chorus
