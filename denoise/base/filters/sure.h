#pragma once
// Stein's unbiased risk estimate (Stein 1981) of a denoiser's per-pixel squared error, as used
// for selecting filters by Li, Wu, Chuang 2012 (SBF) and Rousselle, Manzi, Zwicker 2013 (RDFC).
// For a noisy value y = μ + n with n ~ N(0, σ²) and an output F(y) that is weakly
// differentiable in y,
//
//   E[(F − μ)²] = E[ (F − y)² + 2σ² ∂F/∂y − σ² ].
//
// The derivative is the caller's: each filter knows it (e.g. w_centre / Σw for a filter whose
// weights do not depend on y). Inputs that are not finite count as 0.
#include "common/image/image.h"

namespace chorus {

// SURE of one value: (F − y)² + 2σ² ∂F/∂y − σ², σ² = variance (of the noisy value y).
inline float sureTerm(float filtered, float noisy, float variance, float derivative) {
  const float d = filtered - noisy;
  return d * d + variance * (2.0f * derivative - 1.0f);
}

// Per-pixel SURE averaged over the channels of `filtered` (1-channel result). `noisy` and
// `variance` have the same shape as `filtered`; `derivative` too, or 1 channel shared by all
// channels. Throws std::invalid_argument on mismatched shapes. NaN/Inf inputs are taken as 0
// and an overflowing estimate saturates at the largest float, so the result is always finite.
Image sureMap(const Image& filtered, const Image& noisy, const Image& variance,
              const Image& derivative);

}  // namespace chorus
