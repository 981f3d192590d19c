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
  finishOutput(out, guarded.input.whole.color.mean);
  scaleImage(out, exponent);
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

}  // namespace chorus
