#pragma once
// Small fixed-capacity types for the per-pixel algebra of the ensemble (Zheng et al. 2021):
// dynamic size up to kMaxDenoisers, storage inline (no heap in per-pixel loops), double
// precision so that values from 1e-30 to 1e30 and their squares stay representable.
#include <Eigen/Core>

#include <cstdint>

namespace chorus {

// The ensemble blends at most this many base denoisers.
inline constexpr int kMaxDenoisers = 16;

// ⟨M⟩: the N × N matrix of estimated (cross-)errors of the base outputs at one pixel.
using MseMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxDenoisers, kMaxDenoisers>;
// One weight (or one value) per base denoiser.
using WeightVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxDenoisers, 1>;

// Bit i set = base denoiser i may receive weight at this pixel.
using BaseMask = uint32_t;
inline constexpr BaseMask allBases(int n) {
  return n >= 32 ? ~BaseMask(0) : (BaseMask(1) << n) - 1;
}

}  // namespace chorus
