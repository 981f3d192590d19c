#pragma once
// A knee for members that choose per pixel among candidates by a smoothed error estimate (NFOR's
// two bandwidths, SBF's filter widths). Not in the published methods: the smoothing reaches a
// dark pixel's neighbours through weights that a few bright, noisy pixels barely move (NFOR's
// patch distances; SBF's features, which do not show a highlight in a mirror), and their errors,
// in absolute units, are thousands of times the dark pixel's own, so they choose its candidate
// (a softbox seen in chrome at 4 spp: the wide candidates were chosen around it, where they
// spread the highlight; docs/members/nfor-nlm.md). Above `knee` times the image's mean |colour|
// a pixel's errors are divided by (level / that)²: relative error above the knee, absolute (the
// published methods') below it. Invariant to the unit of radiance.
#include <span>

#include "common/image/image.h"

namespace chorus {

// knee × the mean |value| of `colour` (non-finite values count as 0): the level above which a
// pixel's errors become relative. 0 when knee ≤ 0 or the image is black (the knee is off).
double kneeLevel(std::span<const float> colour, float knee);
// What a pixel at `level` divides its errors by: (level / kneeLevel)² above the knee, else 1.
double kneeDivisor(double level, double kneeLevel);

// NFOR: mse0, mse1 are the two bandwidths' MSE maps, `level` per pixel and channel the pixel's
// own level (the mean of the halves' narrow-bandwidth outputs); all the shape of `colour`.
void kneeBrightErrors(Image& mse0, Image& mse1, const Image& colour, const Image& level,
                      float knee);

}  // namespace chorus
