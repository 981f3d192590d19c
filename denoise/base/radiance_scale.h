#pragma once
// A power-of-two scale for a denoiser's input radiance. The filters compute squared
// differences, variance sums and window sums in float, and their ε terms (1e-10) assume
// radiance of order one: finite radiance above ~1.8e19 (or a variance above ~1e36) would
// overflow them, radiance of 1e-10 would drown in ε. Such inputs are divided by 2^e before
// filtering and the output multiplied back; a power of two changes no bits of the values that
// stay normal floats, and ordinary radiance (largest value within 2^±20) gets e = 0: nothing
// changes at all.
#include "common/image/image.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus {

// Largest colour magnitude (2^20 ≈ 1e6) and variance of the mean (2^40 ≈ 1.1e12) a filter
// sees: the filters square differences of means and sum them over patches and windows, and
// some bound variances at 1e12 (dual-buffer NL-means).
inline constexpr int kMaxRadianceExponent = 20;

// Over the whole and its halves: the least e ≥ 0 with every finite |colour mean| ≤ 2^20 and
// every finite colour variance of the mean ≤ 2^40 after dividing by 2^e (variances by 2^2e);
// when that is 0 but the largest |mean| is below 2^-20, the e < 0 that brings it to [½, 1)
// (as far as the variances allow).
int radianceScaleExponent(const DenoiseInput& input);

// Colour means (whole and halves) times 2^exponent, variances of the mean times 2^(2 exponent).
// Saturated variances (FLT_MAX or +Inf: the film's clamp) and, when scaling up, underflowed ones
// (below FLT_MIN with a non-zero mean) become at least the two-buffer estimate from the scaled
// halves when the input has halves.
void scaleColor(DenoiseInput& input, int exponent);

// Every value times 2^exponent, kept within ±FLT_MAX.
void scaleImage(Image& image, int exponent);

}  // namespace chorus
