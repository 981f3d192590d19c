#pragma once
// Extreme denoiser inputs for the stiff-case suite (tests/stiff_cases_test.cpp), made from the
// synthetic scene (synthetic_scene.h): fireflies up to 1e38 times the mean, radiance spanning
// 1e-30 … 1e30, and the edits they are made with.
#include <cstdint>
#include <vector>

#include "common/image/image.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus::test {

// Adds one colour sample `value` (RGB) to the pixel: mean, variance of the mean and count
// updated as the film does (Welford in double; the variance kept within float's range).
void addColorSample(SubBuffer& sub, int x, int y, const double value[3]);

// A copy of `buffers` with `count` fireflies in sub-buffer `k`: at distinct pixels drawn with
// `seed`, one extra sample of `factor` times the sub-buffer's own mean there (grey: its
// luminance in every channel), at most FLT_MAX.
SampleBuffers withFireflies(const SampleBuffers& buffers, int k, int count, double factor,
                            uint32_t seed);

// Per-column-band scale factors: the image's columns in `scales.size()` equal bands, band b
// multiplied by scales[b].
Image bandScales(int width, int height, const std::vector<double>& scales);
// Colour means times the scale map (variances of the mean times its square), every sub-buffer.
SampleBuffers scaledColor(const SampleBuffers& buffers, const Image& scale);
// An RGB image times the scale map (1 channel).
Image scaledImage(const Image& image, const Image& scale);

// A copy of `buffers` whose colour mean is NaN in every sub-buffer inside the rectangle.
SampleBuffers withNanRect(const SampleBuffers& buffers, int x0, int y0, int x1, int y1);

// 1 channel: 1 outside the rectangle [x0, x1) × [y0, y1), 0 inside.
Image outsideRect(int width, int height, int x0, int y0, int x1, int y1);

}  // namespace chorus::test
