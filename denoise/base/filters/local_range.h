#pragma once
// Per channel, the least and the largest finite value over the (2 radius + 1)² window around each
// pixel (clipped to the image; separable). Pixels whose window holds no finite value get
// lo = +inf, hi = −inf. Used to recognise a regression's prediction that leaves the range of the
// data it was fitted to.
#include "common/image/image.h"

namespace chorus {

struct LocalRange {
  Image lo, hi;
};

LocalRange localRange(const Image& image, int radius);

}  // namespace chorus
