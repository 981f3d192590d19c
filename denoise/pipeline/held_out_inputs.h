#pragma once
// The inputs of the leave-one-quarter-out estimate (issue 25): with K = 4 independent
// sub-buffers q0 … q3, the run that leaves quarter k out denoises the other three, and its
// output y^(−k) is independent of x_k, the mean of quarter k. Members that need two halves of
// their own input get the two quarters of the intact half as one half and the remaining
// quarter as the other (k = 0: q1 | q2 q3, k = 1: q0 | q2 q3, k = 2: q0 q1 | q3, k = 3: q0 q1 |
// q2): unequal halves, the only split of three quarters that keeps the halves independent.
// Where that single quarter holds no samples (3 spp), the intact pair's quarters are the halves.
#include <vector>

#include "common/image/image.h"
#include "denoise/buffers/sample_buffers.h"
#include "denoise/pipeline/ensemble_sources.h"

namespace chorus {

inline constexpr int kHeldOutQuarters = 4;

// Whether `sources` carry the four quarters (K = 4: both half inputs have halves of their own).
bool hasQuarters(const EnsembleSources& sources);

// The input y^(−k) is computed from (three sub-buffers of every plane: at 4K, 2.3 GB), and all
// four. Throw chorus::Error unless hasQuarters (or for k outside 0 … 3).
DenoiseInput heldOutInput(const EnsembleSources& sources, int k);
std::vector<DenoiseInput> heldOutInputs(const EnsembleSources& sources);

}  // namespace chorus
