#pragma once
// Per-pixel sample generator: an Owen-scrambled Sobol (0,2)-sequence (Burley 2020,
// "Practical hash-based Owen scrambling"), one independent scramble per (seed, pixel,
// sub-buffer, dimension), so that sub-buffers are statistically independent estimates
// (see ../shared/docs/base-denoisers.md §1: splitting one sequence would correlate them).
//
// Usage (pbrt-v4 style): startPixelSample(), then get1D()/get2D()/getPixel2D() in a fixed
// order; each call advances an internal dimension counter. Dimension order used by the
// integrator: getPixel2D (film position), get2D (lens position: thin-lens cameras only), then
// per bounce: get1D (lobe), get2D (BSDF direction),
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

  float get1D() { return get1DAt(dimension_++); }
  Vec2f get2D();
  Vec2f getPixel2D();  // position inside the pixel, [0,1)²

  // Reserves the next `count` dimensions and returns the first, for draws taken later with
  // get1DAt / get2DAt, or never: a path skips the draws it does not need (a bounce that escapes,
  // roulette before it starts) without shifting the dimensions of those it does. A get2D takes
  // two dimensions, so reserve(3) then get1DAt(d), get2DAt(d + 1) equals get1D(), get2D().
  uint32_t reserve(uint32_t count) {
    const uint32_t first = dimension_;
    dimension_ += count;
    return first;
  }
  float get1DAt(uint32_t dimension);
  Vec2f get2DAt(uint32_t dimension);

  // Every draw of one path vertex, from the kBounceDimensions dimensions starting at `first`
  // (reserved), in the integrator's order above: equal to get1DAt(first), get2DAt(first + 1),
  // get1DAt(first + 3), get2DAt(first + 4), get1DAt(first + 6), bit for bit, but with their
  // hashes side by side in SIMD lanes (drawn one by one, the sampler took a tenth of the render
  // time). Draws a vertex does not use cost little this way.
  static constexpr uint32_t kBounceDimensions = 7;
  struct BounceDraws {
    float lobe;
    Vec2f direction;
    float light;
    Vec2f lightPoint;
    float roulette;
  };
  BounceDraws getBounce(uint32_t first);

 private:
  // The scramble seeds of a (pixel, sub-buffer, dimension) do not depend on the sample index,
  // so they are hashed once per pixel and reused by its other samples (the hashes were a
  // quarter of the sampler's time). Values never depend on what was cached before.
  static constexpr uint32_t kCachedDimensions = 64;
  struct DimensionSeeds {
    uint64_t first;   // hash of (pixel hash, dimension): index shuffle and first coordinate
    uint64_t second;  // mix64 of it: the second coordinate of a 2D draw
  };
  struct SubBufferSeeds {
    int subBuffer = -1;      // whose seeds these are (−1: none yet for this pixel)
    uint64_t pixelHash = 0;  // hash of (seed, pixel, sub-buffer)
    uint64_t filled = 0;     // bit d: seeds[d] is set
    DimensionSeeds seeds[kCachedDimensions];
  };
  static constexpr uint32_t kSeedSlots = 4;
  DimensionSeeds seeds(uint32_t dimension);
  [[gnu::noinline]] DimensionSeeds computeSeeds(uint32_t dimension);

  uint64_t seed_;
  int pixelX_ = -1, pixelY_ = -1;  // the pixel the seeds belong to
  SubBufferSeeds seeds_[kSeedSlots];
  SubBufferSeeds* current_ = &seeds_[0];
  uint32_t reversedIndex_ = 0;  // the sample's index in its sub-buffer, bits reversed
  uint32_t dimension_ = 0;
};

}  // namespace chorus::render
