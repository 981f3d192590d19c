#pragma once
// A knee for members that choose per pixel among candidates by a smoothed error estimate (NFOR's
// two bandwidths, SBF's filter widths, RDFC's three candidates). Not in the published methods:
// the smoothing reaches a dark pixel's neighbours through weights that a few bright, noisy pixels
// barely move (NFOR's patch distances; SBF's features, which do not show a highlight in a mirror;
// RDFC's colour patches at a light's edge at few samples), and their errors, in absolute units,
// are thousands of times the dark pixel's own, so they choose its candidate (a softbox seen in
// chrome at 4 spp: the wide candidates were chosen around it, where they spread the highlight;
// docs/members/nfor-nlm.md). Above `knee` times the image's mean |colour| a pixel's errors are
// divided by (level / that)²: relative error above the knee, absolute (the published methods')
// below it. Invariant to the unit of radiance.
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "common/image/image.h"

namespace chorus {

// knee × the mean |value| of `colour` (non-finite values count as 0): the level above which a
// pixel's errors become relative. 0 when knee ≤ 0 or the image is black (the knee is off).
double kneeLevel(std::span<const float> colour, float knee);
// What a pixel at `level` divides its errors by: (level / kneeLevel)² above the knee, else 1.
double kneeDivisor(double level, double kneeLevel);
// kneeDivisor of every pixel of an RGB image whose level is the mean of its three channels.
std::vector<float> kneeDivisors(const Image& rgb, double kneeLevel);

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
