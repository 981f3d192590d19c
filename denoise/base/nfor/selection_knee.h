#pragma once
// NFOR's bandwidth selection (step 3) smooths each bandwidth's per-pixel MSE estimate with
// NL-means weights and picks the smaller. Not in Tungsten: the smoothing reaches a dark pixel's
// neighbours through patch distances that a few bright, noisy pixels barely move, and their
// errors, in absolute units, are thousands of times the dark pixel's own, so they choose its
// bandwidth (a softbox seen in chrome at 4 spp: the wide bandwidth was chosen around it, where
// it spreads the highlight; docs/members/nfor-nlm.md). The knee puts such pixels on the dark
// pixels' scale: above `knee` times the image's mean |colour| a pixel's errors are divided by
// (level / that)², i.e. relative error above the knee, absolute (Tungsten's) below it.
#include "common/image/image.h"

namespace chorus {

// mse0, mse1: the two bandwidths' MSE maps; colour: the whole input's colour (its mean |value|
// over every channel sets the unit); level: per pixel and channel, the pixel's own level
// (NFOR: the mean of the halves' narrow-bandwidth outputs). All the same shape. Invariant to
// scaling colour and level by s and the MSE maps by s². knee ≤ 0 (or a black image): unchanged.
void kneeBrightErrors(Image& mse0, Image& mse1, const Image& colour, const Image& level,
                      float knee);

}  // namespace chorus
