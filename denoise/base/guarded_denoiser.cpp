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

PreparedInput prepareInput(const DenoiseInput& input, const OutlierGuardOptions& guard) {
  DenoiseInput filled = input;
  fillNonFiniteColor(filled.whole);
  if (filled.halves)
    for (SubBuffer& half : *filled.halves) fillNonFiniteColor(half);
  // Fireflies first: left in, a firefly of 1e20 would set the scale and push the rest of the
  // image down to where the filters' ε terms dominate.
  PreparedInput prepared{guardOutliers(std::move(filled), guard).input, 0};
  prepared.exponent = radianceScaleExponent(prepared.input);
  scaleColor(prepared.input, -prepared.exponent);
  return prepared;
}

Image GuardedDenoiser::run(const DenoiseInput& input) const {
  return runPrepared(prepareInput(input, guard_), input);
}

Image GuardedDenoiser::runPrepared(const PreparedInput& prepared, const DenoiseInput& input) const {
  Image out = inner_->run(prepared.input);
  // guard=0 leaves the member's own estimate alone (only the safety steps below remain).
  if (guard_.ceilingSigmas > 0.0f)
    keepWithinTheSamples(out, prepared.input.whole, kSampleSigmas,
                         kMinSamplesToBound * prepared.input.sampleShare);
  finishOutput(out, prepared.input.whole.color.mean);
  scaleImage(out, prepared.exponent);
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

void keepWithinTheSamples(Image& output, const SubBuffer& whole, double sigmas, double minSamples) {
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
