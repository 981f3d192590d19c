#pragma once
// Box filter that averages over the pixels that exist: at a border the (2r+1)² box is clipped
// to the buffer and the sum is divided by the true count in both axes (separable: a row pass,
// then a column pass). Small radii sum the taps directly (exact, vectorised, the same result
// for a pixel whatever rectangle it is computed in); larger radii use double-precision running
// sums.
#include <vector>

#include "denoise/base/filters/pixel_rect.h"
#include "denoise/image/image.h"

namespace chorus {

// dst = box(src) over a width × height plane (row-major, contiguous rows). src and dst may be
// the same buffer. `tmp` is scratch, resized as needed.
void boxFilterPlane(const float* src, float* dst, int width, int height, int radius,
                    std::vector<float>& tmp);

// The box filter of a width × height plane evaluated only on `crop` (a rectangle inside the
// plane, in its coordinates), written as a crop.width() × crop.height() plane to dst; the
// clipping and counts are those of the whole plane. dst must not overlap src.
void boxFilterCrop(const float* src, int width, int height, int radius, const PixelRect& crop,
                   float* dst, std::vector<float>& tmp);

// Every channel of `image` box-filtered with the given radius.
Image boxFilter(const Image& image, int radius);

}  // namespace chorus
