#pragma once
// Box filter that averages over the pixels that exist: at a border the (2r+1)² box is clipped
// to the buffer and the sum is divided by the true count in both axes (separable: a row pass,
// then a column pass). Small radii sum the taps directly (exact, vectorised, the same result
// for a pixel whatever rectangle it is computed in); larger radii use double-precision running
// sums.
#include <vector>

#include "denoise/image/image.h"

namespace chorus {

// dst = box(src) over a width × height plane (row-major, contiguous rows). src and dst may be
// the same buffer. `tmp` is scratch, resized as needed.
void boxFilterPlane(const float* src, float* dst, int width, int height, int radius,
                    std::vector<float>& tmp);

// Every channel of `image` box-filtered with the given radius.
Image boxFilter(const Image& image, int radius);

}  // namespace chorus
