#pragma once
// The numerical safety every built-in denoiser runs inside (the registry wraps each one):
//   1. NaN/Inf colour values are filled from their neighbours (nonfinite_fill.h);
//   2. fireflies are clamped in each sub-buffer of the input (outlier_guard.h);
//   3. radiance beyond float's comfortable range is divided by a power of two
//      (radiance_scale.h) so that no squared term overflows, and multiplied back afterwards;
//   4. the output stays within kSampleSigmas standard errors of each well-measured pixel's own
//      mean (keepWithinTheSamples); with guard=0 (ceilingSigmas 0) steps 2 and 4 are off;
//   5. the output is finite and not below min(0, input) at any pixel: non-finite values become
//      the (guarded) noisy input's, and a member never makes non-negative radiance negative;
//   6. pixels whose every sample missed the scene and agreed exactly keep their input.
// Steps 1, 3 and 6 change nothing on ordinary inputs; docs/outliers.md has the reasons.
#include <memory>

#include "denoise/base/base_denoiser.h"
#include "denoise/base/outlier_guard.h"

namespace chorus {

// Steps 1–3 applied to an input: what every guarded member with these options runs on. The
// ensemble prepares each input once for all its members that share the options
// (denoise/pipeline/member_runner.h), instead of once per member: one copy of the input
// instead of one per member running at the same time.
struct PreparedInput {
  DenoiseInput input;
  int exponent = 0;  // its colour was divided by 2^exponent (radiance_scale.h)
};
PreparedInput prepareInput(const DenoiseInput& input, const OutlierGuardOptions& guard);

class GuardedDenoiser : public BaseDenoiser {
 public:
  explicit GuardedDenoiser(std::unique_ptr<BaseDenoiser> inner,
                           const OutlierGuardOptions& guard = {});

  std::string name() const override { return inner_->name(); }
  DenoiserRequirements requirements() const override { return inner_->requirements(); }
  Image run(const DenoiseInput& input) const override;

  const OutlierGuardOptions& guard() const { return guard_; }
  // run(input) with steps 1–3 already done: `prepared` is prepareInput(input, guard()).
  Image runPrepared(const PreparedInput& prepared, const DenoiseInput& input) const;

 private:
  std::unique_ptr<BaseDenoiser> inner_;
  OutlierGuardOptions guard_;
};

// In place: non-finite values of `output` become those of `noisy` (0 where that is not finite
// either), then every value is raised to at least min(0, noisy). Same shape required.
void finishOutput(Image& output, const Image& noisy);

// A member's output may stray from a pixel's own mean by this many standard errors at most,
// where the pixel has at least kMinSamplesToBound samples and a positive variance.
inline constexpr double kSampleSigmas = 10.0;
inline constexpr float kMinSamplesToBound = 16.0f;
// A pixel's samples are taken to have missed its neighbourhood's rare paths by bad luck when
// that is at least this likely (keepWithinTheSamples).
inline constexpr double kUnluckyPixel = 0.01;

// In place: every value of `output` within `sigmas` standard errors of `whole`'s mean at pixels
// with at least `minSamples` samples and a positive variance of the mean. A value that far
// from the pixel's own samples is another pixel's radiance bled in (a thin highlight or an
// emitter's edge spread onto a dark, well-measured neighbour), not an estimate of this one.
// Above, a pixel darker than its neighbours' median whose samples may all have missed the
// bright paths they found (kUnluckyPixel) is not well measured, however alike its samples are:
// up to that median, its 5x5 neighbourhood's median variance bounds it (the Cornell box's dark
// speckles at 16 spp; docs/outliers.md).
void keepWithinTheSamples(Image& output, const SubBuffer& whole, double sigmas,
                          double minSamples = kMinSamplesToBound);

// In place: where every sample of `whole` missed the scene (feature depth 0: the path tracer's
// miss) and the samples agree exactly (colour variance of the mean 0, at least 2 samples), the
// output is the input there. Such a pixel is known exactly (a constant background); members
// filled one-pixel holes in a silhouette with the object's radiance (the lamp corpus scene,
// 16 spp: RDFC 20.8 where the reference is 0, 86 % of its error). No-op without depth or counts.
void keepNoiseFreeMisses(Image& output, const SubBuffer& whole);

}  // namespace chorus
