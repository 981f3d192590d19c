#pragma once
// The iterative solver of the ensemble paper's reference code (Zheng et al. 2021), kept for
// comparison with the exact active-set solver (`--solver pairwise`).
//
// Start from random weights on the simplex; repeatedly pick a random base k and move the
// current blend towards it, w ← (1 − α) w + α e_k, with the α ∈ [0, 1] that minimises
// wᵀ⟨M⟩w along that segment:
//
//   α* = (wᵀMw − (Mw)_k) / ((w − e_k)ᵀ M (w − e_k)),
//
// i.e. an exact line search between the current blend and one base (a pair). Stop after
// 2N + 1 consecutive steps with α < 1e-10, or after 1024 steps. It only ever moves towards a
// vertex, so it converges slowly when the optimum needs a weight to shrink. Randomness comes
// from a counter-based hash of (seed, stream), so results are reproducible and independent of
// thread scheduling.
#include <cstdint>

#include "denoise/ensemble/ensemble_types.h"

namespace chorus {

struct PairwiseSolverOptions {
  int maxIterations = 1024;
  double ineffectiveStep = 1e-10;  // α below this counts as no progress
  int patience = 0;                // consecutive steps without progress before stopping; 0 = 2N + 1
};

struct PairwiseSolverResult {
  WeightVector weights;
  int iterations = 0;
};

// `stream` selects the random sequence (the caller passes e.g. pixel index × channels + c).
// Bases outside `valid` or with non-finite entries get weight 0 (as in solveSimplexQp).
PairwiseSolverResult solvePairwise(const MseMatrix& m, uint64_t seed, uint64_t stream,
                                   BaseMask valid = ~BaseMask(0),
                                   const PairwiseSolverOptions& options = {});

}  // namespace chorus
