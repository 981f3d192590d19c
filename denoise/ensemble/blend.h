#pragma once
// Applying ensemble weights: z = Σ_i w_i y_i per pixel and channel (Zheng et al. 2021), and the
// dual-buffer estimate of the blend's error.
#include <span>
#include <vector>

#include "common/image/image.h"

namespace chorus {

// z(p,c) = Σ_i w_i(p,c) y_i(p,c). Weight maps have 3 channels (one weight per colour channel)
// or 1 (shared by the channels); outputs are RGB. Terms with w_i = 0 are skipped, so a base
// that is NaN/Inf where its weight is 0 does not matter. Where the sum is still not finite,
// the fallback value is used (the noisy colour), or 0 if that is not finite either: no NaN/Inf
// reaches the result.
Image blend(std::span<const Image> weights, std::span<const Image* const> outputs,
            const Image& fallback);

// The estimated per-pixel, per-channel MSE of a blend, from the blends of the half-buffer
// outputs z^A, z^B and the noisy halves x^A, x^B:
//   ½[(z^A − x^B)² + (z^B − x^A)²] − ½(x^A − x^B)² = wᵀ⟨M⟩w.
// Unbiased for the mean of the half blends' squared errors when w does not depend on the noise
// (it does, slightly, through the solve); it estimates the error of a half-buffer blend, an
// upper bound for the full-buffer blend. May be negative where the noise dominates; non-finite
// values are written as 0.
Image estimatedBlendMse(const Image& blendA, const Image& blendB, const Image& colorA,
                        const Image& colorB);

// The same from the leave-one-quarter-out blends z^(−k) (the weights applied to the runs
// without quarter k) and the noisy quarters x_k, k = 0 … 3:
//   mean_k (z^(−k) − x_k)² − s²,  s² = (1/3) Σ_k (x_k − x̄)²  (the variance of a quarter mean).
// Unbiased for the mean of the three-quarter blends' squared errors under the same condition;
// may be negative; non-finite values are written as 0. Quarters that are 0 everywhere (no
// samples, below 4 spp) are left out while two or more remain: the means over the F others,
// s² with F − 1.
Image heldOutBlendMse(std::span<const Image> heldOutBlends, std::span<const Image> quarters);

}  // namespace chorus
