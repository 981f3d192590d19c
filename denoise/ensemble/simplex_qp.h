#pragma once
// The ensemble's per-pixel weight problem (Zheng et al. 2021, eq. for w*):
//
//   w* = argmin wᵀ⟨M⟩w   subject to  Σ w_i = 1,  w_i ≥ 0,
//
// solved exactly by a primal active-set method on the small dense problem (N ≤ 16). The
// solver knows nothing about images.
//
// Properties (each one tested in tests/simplex_qp_test.cpp):
// - Tie-break. Per pixel ⟨M⟩ has rank ≤ 6, so the minimiser is not unique. A ridge
//   ρ·s·‖w‖² is added, s = the size of ⟨M⟩ on the simplex (the larger of its mean eigenvalue
//   on the tangent space {v : Σv = 0} and its linear term there, see simplex_qp.cpp); on the
//   simplex ‖w‖² = ‖w − 1/N‖² + 1/N, so the ridge selects the minimiser closest to uniform
//   weights (exactly so as ρ → 0; with ρ = 1e-8 the objective is within 1e-8·s of the optimum).
// - Only the restriction of ⟨M⟩ to the simplex matters: adding c·11ᵀ changes nothing (it adds
//   the constant c). The solver removes the mean entry first and divides by s, so it is
//   invariant to scaling ⟨M⟩ by 1e-30 … 1e30 and well conditioned for bright pixels.
// - Bases outside `valid`, or whose diagonal entry is NaN/±Inf (or whose off-diagonal entry with
//   another valid base is), get weight 0.
// - Always returns finite w ≥ 0 with |Σw − 1| < 1e-12 (uniform weights over the valid bases
//   when ⟨M⟩ is constant on the simplex, e.g. for identical outputs; uniform over all bases
//   when none is valid).
// Preconditions: ⟨M⟩ symmetric and positive semi-definite on the tangent space (true for every
// ⟨M⟩ built from data, see mse_estimate.h). For other matrices the result is still a feasible
// point, but a local rather than the global minimiser.
#include "denoise/ensemble/ensemble_types.h"

namespace chorus {

struct SimplexQpOptions {
  // ρ: the tie-breaking ridge relative to ⟨M⟩'s mean eigenvalue on the tangent space.
  double relativeRidge = 1e-8;
  // false drops w ≥ 0 and keeps only Σw = 1 (affine weights; the unconstrained oracle).
  bool nonNegative = true;
};

struct SimplexQpResult {
  WeightVector weights;
  int iterations = 0;    // active-set iterations (equality-constrained solves)
  BaseMask support = 0;  // the free set at the optimum (0 when the solver fell back to uniform)
};

// `start`: the bases that begin free (a warm start, e.g. the support of a neighbouring pixel's
// solution; all valid bases when empty). It changes how many iterations are needed, not the
// optimum: the result is the same up to rounding, and bit for bit whenever the same support is
// reached (the weights are the solution of the equality problem on that support).
SimplexQpResult solveSimplexQp(const MseMatrix& m, BaseMask valid = ~BaseMask(0),
                               const SimplexQpOptions& options = {}, BaseMask start = ~BaseMask(0));

// wᵀ M w, accumulated in a fixed order.
double quadraticForm(const MseMatrix& m, const WeightVector& w);

// The bases the solver treats as valid: in `valid`, finite diagonal, and finite entries with
// every other such base (greedily dropping the base with the most non-finite entries).
BaseMask finiteBases(const MseMatrix& m, BaseMask valid);

}  // namespace chorus
