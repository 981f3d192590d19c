#pragma once
// Helpers for testing base denoisers (any BaseDenoiser): running with a fixed thread count,
// finiteness, and a feature-blind blur to compare edge preservation against.
#include <string>

#include "denoise/base/base_denoiser.h"
#include "denoise/image/image.h"

namespace chorus::test {

// Runs the denoiser with at most `threads` TBB threads.
Image runWithThreads(const BaseDenoiser& denoiser, const DenoiseInput& input, int threads);

// "" when every value is finite, else a description of the first non-finite value.
std::string firstNonFinite(const Image& image);

// True when both images have the same shape and bit-identical values.
bool bitIdentical(const Image& a, const Image& b);

// Gaussian blur of standard deviation sigma (window radius ⌈3σ⌉, clipped and renormalised at
// the borders), blind to features: what a denoiser that ignores edges would produce.
Image gaussianBlur(const Image& image, float sigma);

// Largest |value − expected[c]| over all pixels, per channel c of an RGB image.
float maxDeviationFrom(const Image& image, const float expected[3]);

}  // namespace chorus::test
