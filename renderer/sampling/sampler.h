#pragma once
// Per-pixel sample generator: an Owen-scrambled Sobol (0,2)-sequence (Burley 2020,
// "Practical hash-based Owen scrambling"), one independent scramble per (seed, pixel,
// sub-buffer, dimension), so that sub-buffers are statistically independent estimates
// (see ../shared/docs/base-denoisers.md §1: splitting one sequence would correlate them).
//
// Usage (pbrt-v4 style): startPixelSample(), then get1D()/get2D()/getPixel2D() in a fixed
// order; each call advances an internal dimension counter. Dimension order used by the
// integrator: getPixel2D (film position), then per bounce: get1D (lobe), get2D (BSDF direction),
// get1D (light choice), get2D (light position), get1D (Russian roulette).
#include <cstdint>

#include "renderer/math/vec.h"

namespace chorus::render {

class Sampler {
 public:
  explicit Sampler(uint64_t seed) : seed_(seed) {}

  // `indexInSubBuffer` counts the samples of this pixel that go to `subBuffer`
  // (pixel sample i goes to sub-buffer i mod K with index i / K).
  void startPixelSample(int px, int py, uint32_t indexInSubBuffer, int subBuffer);

  float get1D();
  Vec2f get2D();
  Vec2f getPixel2D();  // position inside the pixel, [0,1)²

 private:
  uint64_t seed_;
  uint64_t pixelHash_ = 0;  // hash of (seed, pixel, sub-buffer)
  uint32_t reversedIndex_ = 0;  // the sample's index in its sub-buffer, bits reversed
  uint32_t dimension_ = 0;
};

}  // namespace chorus::render
