#pragma once
// Images whose values feed metrics or serve as ground truth must be finite: one NaN makes every
// metric NaN (printed as null), so such inputs are refused with the place of the first bad pixel.
#include <cstddef>
#include <filesystem>

#include "common/image/image.h"

namespace chorus {

// Pixels with at least one NaN or infinite channel.
size_t nonFinitePixelCount(const Image& image);

// Throws chorus::Error "FILE: N pixel(s) are NaN or infinite (the first at x,y)" unless every
// value of `image` (read from `file`) is finite.
void requireFinitePixels(const Image& image, const std::filesystem::path& file);

}  // namespace chorus
