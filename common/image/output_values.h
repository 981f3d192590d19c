#pragma once
// Values an output image may hold: NaN and ±Inf never reach a file, and radiance is never
// negative. Applied by the writers to every image they write, whatever produced it (built-in
// members are finite and non-negative already; external members and noisy inputs need not be).
#include <cstddef>

#include "common/image/image.h"

namespace chorus {

struct OutputRepairs {
  size_t nonFinite = 0;  // NaN → 0, +Inf → FLT_MAX, −Inf → 0 (−FLT_MAX for signed images)
  size_t negative = 0;   // finite negatives → 0 (radiance only)
  size_t total() const { return nonFinite + negative; }
};

// Repairs `image` in place: radiance (`signedValues` false) also loses its negatives.
OutputRepairs repairForOutput(Image& image, bool signedValues = false);

}  // namespace chorus
