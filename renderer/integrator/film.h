#pragma once
// The film: per pixel and per sub-buffer, the running mean and M2 (Welford 1962, in double) of
// colour and every feature, and the number of samples kept. A pixel's samples are accumulated by
// one task in sample order, so the result does not depend on the thread count. Samples with any
// non-finite value are dropped (and counted), so NaN/Inf never reach the output.
#include <array>
#include <cstdint>

#include "denoise/buffers/sample_buffers.h"
#include "renderer/math/vec.h"

namespace chorus::render {

// What one camera path contributes to its pixel.
struct PathSample {
  Rgb L;       // radiance
  Rgb albedo;  // features at the first non-specular vertex (see path_tracer.h)
  Vec3f normal;
  float depth = 0;
  float visibility = 0;
  Rgb emitted;  // the part of L seen directly or in mirrors (path_tracer.h)

  bool isFinite() const;
};

inline constexpr int kMaxSplits = 4;
inline constexpr int kPathSampleChannels = 11;  // colour 3, albedo 3, normal 3, depth, visibility

// Welford accumulators of one pixel for up to kMaxSplits sub-buffers.
class PixelAccumulator {
 public:
  // With separateEmission, a sample's colour is accumulated without its `emitted` part, which is
  // kept apart (emitted()).
  explicit PixelAccumulator(bool separateEmission = false) : separateEmission_(separateEmission) {}

  // Adds a sample to sub-buffer k; returns false (and keeps nothing) when it is not finite.
  bool add(int k, const PathSample& sample);

  // With separateEmission (else 0 and false): the mean `emitted` part of the samples kept (0
  // without one), and whether some sample's differs from the first's: where none does, it is
  // the pixel's emission. (A tolerance of 2 % saved a third of the emission pass on sky scenes
  // but multiplied by 2 to 19 the pass's error there: docs/emission.md.)
  Rgb emitted() const;
  bool emittedVaries() const { return emittedVaries_; }

  struct Stats {
    uint32_t count = 0;
    std::array<double, kPathSampleChannels> mean{}, m2{};
  };
  const Stats& stats(int k) const { return stats_[size_t(k)]; }

 private:
  std::array<Stats, kMaxSplits> stats_{};
  bool separateEmission_;
  uint32_t kept_ = 0;
  bool emittedVaries_ = false;
  Rgb firstEmitted_;
  std::array<double, 3> emittedSum_{};
};

class Film {
 public:
  // splits ∈ {1, 2, 4}; the sub-buffers hold `planes` (colour always; a feature only when a
  // denoiser will read it: less to allocate, store and write). With separateEmission the
  // colour leaves out what the camera sees emitted, which goes to the emission plane.
  Film(int width, int height, int splits, BufferPlanes planes = BufferPlanes::all(),
       bool separateEmission = false);

  // Writes a finished pixel: mean, variance of the mean = M2 / (n (n − 1)) (0 when n < 2) and
  // the sample count of every sub-buffer, for the planes held. Distinct pixels may be stored
  // concurrently.
  void store(int x, int y, const PixelAccumulator& pixel);

  int width() const { return width_; }
  int height() const { return height_; }
  int splits() const { return int(subBuffers_.size()); }
  bool separatesEmission() const { return separateEmission_; }
  // With separateEmission: per pixel, the mean emission of its samples; where they disagree
  // (emittedVaries) the emission pass (render.cpp) replaces it.
  Image& emission() { return emission_; }
  bool emittedVaries(int x, int y) const {
    return emittedVaries_[size_t(y) * size_t(width_) + size_t(x)] != 0;
  }
  // The samples kept at a pixel, over all sub-buffers.
  double samplesKept(int x, int y) const;

  // The K independent sub-buffers and the emission plane (moves them out of the film).
  SampleBuffers release();

 private:
  int width_, height_;
  BufferPlanes planes_;
  bool separateEmission_;
  std::vector<SubBuffer> subBuffers_;
  Image emission_;
  std::vector<uint8_t> emittedVaries_;
};

}  // namespace chorus::render
