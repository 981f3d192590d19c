#include "denoise/base/guarded_denoiser.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "denoise/base/nonfinite_fill.h"
#include "denoise/base/radiance_scale.h"

namespace chorus {

GuardedDenoiser::GuardedDenoiser(std::unique_ptr<BaseDenoiser> inner,
                                 const OutlierGuardOptions& guard)
    : inner_(std::move(inner)), guard_(guard) {
  if (!inner_) throw std::invalid_argument("GuardedDenoiser: no denoiser");
}

Image GuardedDenoiser::run(const DenoiseInput& input) const {
  DenoiseInput prepared = input;
  fillNonFiniteColor(prepared.whole);
  if (prepared.halves)
    for (SubBuffer& half : *prepared.halves) fillNonFiniteColor(half);
  // Fireflies first: left in, a firefly of 1e20 would set the scale and push the rest of the
  // image down to where the filters' ε terms dominate.
  GuardedInput guarded = guardOutliers(std::move(prepared), guard_);
  const int exponent = radianceScaleExponent(guarded.input);
  scaleColor(guarded.input, -exponent);
  Image out = inner_->run(guarded.input);
  // guard=0 leaves the member's own estimate alone (only the safety steps below remain).
  if (guard_.ceilingSigmas > 0.0f)
    keepWithinTheSamples(out, guarded.input.whole, kSampleSigmas,
                         kMinSamplesToBound * guarded.input.sampleShare);
  finishOutput(out, guarded.input.whole.color.mean);
  scaleImage(out, exponent);
  // The input as given: the guard may have spread an excess onto such a pixel.
  keepNoiseFreeMisses(out, input.whole);
  return out;
}

void finishOutput(Image& output, const Image& noisy) {
  if (!output.sameShape(noisy)) throw std::invalid_argument("finishOutput: shapes differ");
  float* out = output.data();
  const float* in = noisy.data();
  for (size_t i = 0; i < output.size(); ++i) {
    const float fallback = std::isfinite(in[i]) ? in[i] : 0.0f;
    const float value = std::isfinite(out[i]) ? out[i] : fallback;
    out[i] = std::max(value, std::min(0.0f, fallback));
  }
}

void keepWithinTheSamples(Image& output, const SubBuffer& whole, double sigmas,
                          double minSamples) {
  const Image& mean = whole.color.mean;
  const Image& variance = whole.color.varianceOfMean;
  if (!output.sameShape(mean)) throw std::invalid_argument("keepWithinTheSamples: shapes differ");
  if (!whole.sampleCount.sameSize(mean)) return;
  for (int y = 0; y < mean.height(); ++y)
    for (int x = 0; x < mean.width(); ++x) {
      if (!(whole.sampleCount(x, y, 0) >= minSamples)) continue;
      for (int c = 0; c < 3; ++c) {
        const double m = mean(x, y, c), v = variance(x, y, c);
        if (!(v > 0.0 && std::isfinite(v) && std::isfinite(m))) continue;
        const double reach = sigmas * std::sqrt(v);
        float& o = output(x, y, c);
        if (std::isfinite(o)) o = float(std::clamp(double(o), m - reach, m + reach));
      }
    }
}

void keepNoiseFreeMisses(Image& output, const SubBuffer& whole) {
  const Image& color = whole.color.mean;
  if (!output.sameShape(color)) throw std::invalid_argument("keepNoiseFreeMisses: shapes differ");
  const Image& depth = whole.depth.mean;
  if (!depth.sameSize(color) || !whole.sampleCount.sameSize(color)) return;
  for (int y = 0; y < color.height(); ++y)
    for (int x = 0; x < color.width(); ++x) {
      if (!(whole.sampleCount(x, y, 0) >= 2.0f) || depth(x, y, 0) != 0.0f) continue;
      bool exact = true;
      for (int c = 0; c < 3; ++c)
        exact = exact && whole.color.varianceOfMean(x, y, c) == 0.0f &&
                std::isfinite(color(x, y, c)) && color(x, y, c) >= 0.0f;
      if (!exact) continue;
      for (int c = 0; c < 3; ++c) output(x, y, c) = color(x, y, c);
    }
}

}  // namespace chorus
