#pragma once
// False-colour maps for scalar images (ensemble weights, error maps): dark blue at 0 through
// teal and green to yellow at 1, perceptually ordered and readable by colour-blind viewers.
#include "common/image/image.h"

namespace chorus {

// Maps channel `channel` of `image`, with values in [lo, hi], to a linear-RGB image meant to be
// written with writePng/encodePng at the default display options. NaN maps to black.
Image falseColor(const Image& image, int channel = 0, float lo = 0.0f, float hi = 1.0f);

}  // namespace chorus
