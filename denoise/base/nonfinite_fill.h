#pragma once
// Colour values that are NaN or ±Inf in a sub-buffer (a corrupt sample, a hole in another
// renderer's buffer) are filled from their neighbours before a denoiser runs: left as they are,
// each filter replaces them with 0 (sanitizedMean), a black blot whose edge the feature-guided
// filters smear into the finite pixels around it. Each missing value becomes the median of its
// finite 8-neighbours, region by region from the border inwards; its variance of the mean the
// mean of theirs. An image with no finite value of a channel gets 0 there.
#include <cstddef>

#include "denoise/buffers/sample_buffers.h"

namespace chorus {

// Fills the colour of `buffer` in place; returns how many values were filled.
size_t fillNonFiniteColor(SubBuffer& buffer);

}  // namespace chorus
