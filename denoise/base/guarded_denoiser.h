#pragma once
// The numerical safety every built-in denoiser runs inside (the registry wraps each one):
//   1. NaN/Inf colour values are filled from their neighbours (nonfinite_fill.h);
//   2. fireflies are clamped in each sub-buffer of the input (outlier_guard.h);
//   3. radiance beyond float's comfortable range is divided by a power of two
//      (radiance_scale.h) so that no squared term overflows, and multiplied back afterwards;
//   4. the output is finite and not below min(0, input) at any pixel: non-finite values become
//      the (guarded) noisy input's, and a member never makes non-negative radiance negative.
// Steps 1–3 change nothing on ordinary inputs; docs/outliers.md has the reasons.
#include <memory>

#include "denoise/base/base_denoiser.h"
#include "denoise/base/outlier_guard.h"

namespace chorus {

class GuardedDenoiser : public BaseDenoiser {
 public:
  explicit GuardedDenoiser(std::unique_ptr<BaseDenoiser> inner,
                           const OutlierGuardOptions& guard = {});

  std::string name() const override { return inner_->name(); }
  DenoiserRequirements requirements() const override { return inner_->requirements(); }
  Image run(const DenoiseInput& input) const override;

 private:
  std::unique_ptr<BaseDenoiser> inner_;
  OutlierGuardOptions guard_;
};

// In place: non-finite values of `output` become those of `noisy` (0 where that is not finite
// either), then every value is raised to at least min(0, noisy). Same shape required.
void finishOutput(Image& output, const Image& noisy);

}  // namespace chorus
