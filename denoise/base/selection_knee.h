#pragma once
// A knee for members whose smoothing or patch distances let a few bright, noisy pixels reach
// their dark neighbours. Not in the published methods. Errors chosen between (NFOR's bandwidths,
// SBF's filter widths, RDFC's candidates) are smoothed through weights that such pixels barely
// move, and their errors, in absolute units, are thousands of times the dark pixel's own, so they
// choose its candidate (a softbox seen in chrome at 4 spp: the wide candidates were chosen around
// it, where they spread the highlight; docs/members/nfor-nlm.md). Variances (RDFC's second pass,
// JNLM's patch distances, à-trous's blur) let a highlight's noise excuse its difference from the
// pixels beside it. Above `knee` times the image's mean |colour| a pixel's errors or variance are
// divided by (level / that)²: relative units above the knee, absolute (the published methods')
// below it. Invariant to the unit of radiance.
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "common/image/image.h"

namespace chorus {

// A knee parameter is 0 (off) or a finite positive multiple of the image's mean |colour|.
inline bool validKnee(float knee) {
  return knee >= 0 && knee <= std::numeric_limits<float>::max();
}

// knee × the mean |value| of `colour` (non-finite values count as 0): the level above which a
// pixel's errors become relative. 0 when knee ≤ 0 or the image is black (the knee is off).
double kneeLevel(std::span<const float> colour, float knee);
// What a pixel at `level` divides its errors by: (level / kneeLevel)² above the knee, else 1.
double kneeDivisor(double level, double kneeLevel);
// A pixel's level in an interleaved RGB image: the mean of its three channels.
inline double rgbLevel(const Image& rgb, size_t pixel) {
  const float* p = rgb.data() + 3 * pixel;
  return (double(p[0]) + p[1] + p[2]) / 3.0;
}
// kneeDivisor of every pixel of an RGB image at its rgbLevel.
std::vector<float> kneeDivisors(const Image& rgb, double kneeLevel);
// Every value of an RGB image divided by its pixel's divisor.
void divideByPixel(Image& rgb, std::span<const float> divisors);
// A colour variance (RGB) with every pixel above the knee divided by its divisor at `guide`'s
// level: its noise no longer excuses its difference from a dark neighbour in patch distances or
// weights. Returned as it is when kneeLevel ≤ 0 (the knee is off).
Image kneedVariance(Image variance, const Image& guide, double kneeLevel);

// Every error map's element e divided by kneeDivisor(level(e), kneeLevel), for e < count; an
// element at FLT_MAX (a member's mark for "unusable") stays. NFOR: its two bandwidths' MSE maps,
// e per pixel and channel; SBF and RDFC: their candidates' SURE planes, e per pixel.
template <typename Level>
void kneeBrightErrors(std::span<float* const> maps, size_t count, Level&& level, double kneeLevel) {
  if (!(kneeLevel > 0)) return;
  for (size_t e = 0; e < count; ++e) {
    const double d = kneeDivisor(level(e), kneeLevel);
    if (d == 1.0) continue;
    for (float* map : maps)
      if (map[e] < std::numeric_limits<float>::max()) map[e] = float(double(map[e]) / d);
  }
}

}  // namespace chorus
