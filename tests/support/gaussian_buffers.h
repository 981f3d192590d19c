#pragma once
// Denoiser inputs whose colour noise satisfies SURE's assumptions exactly: a known truth plus
// independent Gaussian noise of known variance in each of two halves. Features are copied from
// another buffer (e.g. the synthetic scene's), identical in both halves.
#include <cstdint>

#include "common/image/image.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus::test {

// whole.color = (half1 + half2) / 2 with half_k = truth + N(0, 2 σ²) per pixel and channel, so the
// whole mean has variance σ² = (sigma(x, y, c))², which is stored as its varianceOfMean (halves:
// 2 σ²). Features (means and variances) and sample counts come from `features` for all three.
DenoiseInput gaussianHalves(const Image& truth, const Image& sigma, const SubBuffer& features,
                            uint32_t seed);

}  // namespace chorus::test
