#pragma once
// Rank-revealing solve of a small weighted least-squares problem from its Gram matrix:
//   min_β Σ_i w_i |x_iᵀ β − y_i|²   given   G = Σ w x xᵀ (d × d)   and   B = Σ w x yᵀ (d × C).
// Columns are Jacobi-scaled (unit diagonal), then a Cholesky factorisation with diagonal
// pivoting takes the most independent remaining column first and stops when the remaining
// pivot — the fraction of that column not explained by the columns already taken — falls
// below `relativePivotTolerance`, or when a column's own norm is negligible next to the
// largest (`absoluteDiagonalTolerance`, relative to max G_jj). Dropped columns get β = 0: the
// basic solution that a column-pivoted QR returns on rank-deficient data (constant or
// duplicated features never blow up), and the fitted values X β are those of the full problem
// whenever it has full rank.
#include <cstddef>

namespace chorus {

inline constexpr int kMaxGramSize = 24;  // d ≤ 24 columns (3 + up to 21 features)
inline constexpr int kMaxGramRhs = 4;    // C ≤ 4 right-hand sides

// The default pivot tolerance suits Gram sums formed in double: a column is dropped when less
// than ~3e-6 of its norm is independent of the others, close to where Eigen's float
// column-pivoted QR (threshold d · ε_float relative to the largest pivot) stops in Tungsten.
struct GramTolerances {
  double relativePivotTolerance = 1e-11;
  double absoluteDiagonalTolerance = 1e-13;
};

// G: d × d row-major (only the upper triangle is read), B: d × C row-major, beta: d × C out.
// Returns the numerical rank. Scratch lives on the stack; no allocation.
int solveGramPivoted(const double* G, const double* B, int d, int C, double* beta,
                     const GramTolerances& tol = {});

}  // namespace chorus
