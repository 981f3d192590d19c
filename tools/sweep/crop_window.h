#pragma once
// The crop the sweep report shows per case: the square window where the noisy input's relMSE
// is largest, i.e. where the denoisers have the most to do and differ the most.
#include "common/image/image.h"

namespace chorus::sweep {

struct CropWindow {
  int x = 0, y = 0, width = 0, height = 0;
};

// The size × size window (clipped to the image) with the largest summed per-pixel relMSE of
// `noisy` against `reference`; ties go to the first in row-major order (deterministic).
CropWindow worstWindow(const Image& noisy, const Image& reference, int size);

Image cropImage(const Image& image, const CropWindow& window);

}  // namespace chorus::sweep
