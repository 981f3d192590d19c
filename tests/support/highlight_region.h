#pragma once
// The pixels around highlights of a reference image, and the share of a relMSE they hold: the
// peers README's definition (../shared/peers/tungsten-nfor, "highlights"), used to compare
// denoisers where specular highlights dominate the error. No GoogleTest dependency (the
// benchmarks use it too).
#include <vector>

#include "common/image/image.h"

namespace chorus::test {

inline constexpr int kHighlightRadius = 4;      // square neighbourhood, in pixels
inline constexpr float kHighlightLevel = 0.6f;  // a reference value above this, any channel

// mask[y · width + x]: within kHighlightRadius of a pixel brighter than kHighlightLevel.
std::vector<bool> highlightMask(const Image& reference);

// relMSE summed over the pixels where mask == inside, divided by all pixels: the part of the
// whole image's relMSE that those pixels hold (the two parts add up to relMse()).
double relMsePart(const Image& image, const Image& reference, const std::vector<bool>& mask,
                  bool inside);

}  // namespace chorus::test
