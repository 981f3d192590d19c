#include "denoise/base/filters/gram_solver.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace chorus {

int solveGramPivoted(const double* G, const double* B, int d, int C, double* beta,
                     const GramTolerances& tol) {
  if (d > kMaxGramSize || C > kMaxGramRhs || d < 0 || C < 0)
    throw std::invalid_argument("solveGramPivoted: problem too large");
  // Scaled Gram, factorised in place. Only the lower triangle (i ≥ j) is stored and read: the
  // trailing Schur complement, and left of it the columns of L.
  double a[kMaxGramSize][kMaxGramSize];
  double rhs[kMaxGramSize][kMaxGramRhs];
  double scale[kMaxGramSize];
  int perm[kMaxGramSize];

  double maxDiag = 0;
  for (int j = 0; j < d; ++j) maxDiag = std::max(maxDiag, G[j * d + j]);
  for (int j = 0; j < d; ++j) {
    const double gjj = G[j * d + j];
    // A column too small to matter (or exactly zero) is dropped from the start.
    scale[j] = gjj > tol.absoluteDiagonalTolerance * maxDiag && gjj > 0 ? 1.0 / std::sqrt(gjj) : 0;
    perm[j] = j;
  }
  for (int i = 0; i < d; ++i) {
    for (int j = 0; j <= i; ++j) a[i][j] = G[j * d + i] * scale[j] * scale[i];
    for (int c = 0; c < C; ++c) rhs[i][c] = B[i * C + c] * scale[i];
  }

  // Cholesky with diagonal pivoting: after step k, a[k..][k..] holds the Schur complement.
  int rank = 0;
  for (int k = 0; k < d; ++k) {
    int best = k;
    for (int j = k + 1; j < d; ++j)
      if (a[j][j] > a[best][best]) best = j;
    if (!(a[best][best] > tol.relativePivotTolerance)) break;
    if (best != k) {
      // Symmetric swap of k and best in lower-triangle storage.
      std::swap(perm[k], perm[best]);
      for (int j = 0; j < k; ++j) std::swap(a[k][j], a[best][j]);
      std::swap(a[k][k], a[best][best]);
      for (int i = k + 1; i < best; ++i) std::swap(a[i][k], a[best][i]);
      for (int i = best + 1; i < d; ++i) std::swap(a[i][k], a[i][best]);
      for (int c = 0; c < C; ++c) std::swap(rhs[k][c], rhs[best][c]);
    }
    const double lkk = std::sqrt(a[k][k]);
    a[k][k] = lkk;
    for (int i = k + 1; i < d; ++i) a[i][k] /= lkk;
    for (int i = k + 1; i < d; ++i)
      for (int j = k + 1; j <= i; ++j) a[i][j] -= a[i][k] * a[j][k];
    rank = k + 1;
  }

  // Solve L Lᵀ z = rhs on the first `rank` pivoted columns; the rest of z is 0.
  double z[kMaxGramSize][kMaxGramRhs] = {};
  for (int c = 0; c < C; ++c) {
    for (int i = 0; i < rank; ++i) {
      double s = rhs[i][c];
      for (int j = 0; j < i; ++j) s -= a[i][j] * z[j][c];
      z[i][c] = s / a[i][i];
    }
    for (int i = rank - 1; i >= 0; --i) {
      double s = z[i][c];
      for (int j = i + 1; j < rank; ++j) s -= a[j][i] * z[j][c];
      z[i][c] = s / a[i][i];
    }
  }
  for (int j = 0; j < d; ++j)
    for (int c = 0; c < C; ++c) beta[j * C + c] = 0;
  for (int i = 0; i < rank; ++i)
    for (int c = 0; c < C; ++c) beta[perm[i] * C + c] = z[i][c] * scale[perm[i]];
  return rank;
}

}  // namespace chorus
