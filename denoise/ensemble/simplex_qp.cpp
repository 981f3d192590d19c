#include "denoise/ensemble/simplex_qp.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace chorus {
namespace {

constexpr int kMaxKkt = kMaxDenoisers + 1;

// Entries below this fraction of the largest |⟨M⟩| entry are rounding noise.
constexpr double kNegligibleTangent = 1e-13;
// Optimality tolerances in normalised units (tangent eigenvalues average 1, weights in [0, 1]).
constexpr double kMultiplierTolerance = 1e-11;
// A warm-started solution is kept when every bound weight's multiplier exceeds this: far above
// both the tolerance and what the ridge (ρ = 1e-8 by default) can decide.
constexpr double kClearMultiplier = 1e-6;
// The largest ridge (relative to the mean tangent eigenvalue) that restores convexity.
constexpr double kLargestRidge = 1e-3;

// The equality-constrained sub-problem on the free set F (other weights fixed at 0):
//   min ½ w_Fᵀ Q_FF w_F  s.t.  Σ w_F = 1   ⇔   [Q_FF −1; 1ᵀ 0] [w_F; λ] = [0; 1],
// solved by Gaussian elimination with partial pivoting on the bordered (KKT) matrix of size
// n = |F| + 1 ≤ kN (a stack array; with n == kN the loops have constant bounds and unroll).
// Returns false when the KKT matrix is numerically singular.
template <int kN>
bool solveKkt(const MseMatrix& q, const std::array<int, kMaxDenoisers>& free, int n,
              WeightVector& target, double& lambda) {
  const int freeCount = n - 1;
  std::array<std::array<double, kN + 1>, kN> a;
  for (int r = 0; r < freeCount; ++r) {
    for (int c = 0; c < freeCount; ++c) a[r][c] = q(free[size_t(r)], free[size_t(c)]);
    a[r][freeCount] = -1.0;
    a[r][n] = 0.0;
  }
  for (int c = 0; c < freeCount; ++c) a[freeCount][c] = 1.0;
  a[freeCount][freeCount] = 0.0;
  a[freeCount][n] = 1.0;

  double largest = 0.0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) largest = std::max(largest, std::abs(a[r][c]));
  const double singular = largest * 1e-15;
  for (int k = 0; k < n; ++k) {
    int pivot = k;
    for (int r = k + 1; r < n; ++r)
      if (std::abs(a[r][k]) > std::abs(a[pivot][k])) pivot = r;
    if (!(std::abs(a[pivot][k]) > singular)) return false;
    if (pivot != k)
      for (int c = k; c <= n; ++c) std::swap(a[k][c], a[pivot][c]);
    const double inverse = 1.0 / a[k][k];
    for (int r = k + 1; r < n; ++r) {
      const double factor = a[r][k] * inverse;
      if (factor == 0.0) continue;
      for (int c = k + 1; c <= n; ++c) a[r][c] -= factor * a[k][c];
    }
  }
  std::array<double, kN> x{};
  for (int r = n - 1; r >= 0; --r) {
    double sum = a[r][n];
    for (int c = r + 1; c < n; ++c) sum -= a[r][c] * x[size_t(c)];
    x[size_t(r)] = sum / a[r][r];
  }
  for (int r = 0; r < freeCount; ++r) target[free[size_t(r)]] = x[size_t(r)];
  lambda = x[size_t(freeCount)];
  return std::isfinite(lambda);
}

bool solveEqualityProblem(const MseMatrix& q, const std::array<int, kMaxDenoisers>& free,
                          int freeCount, WeightVector& target, double& lambda) {
  // Sizes of the usual few bases get their own unrolled copy (same arithmetic).
  switch (freeCount + 1) {
    case 2:
      return solveKkt<2>(q, free, 2, target, lambda);
    case 3:
      return solveKkt<3>(q, free, 3, target, lambda);
    case 4:
      return solveKkt<4>(q, free, 4, target, lambda);
    case 5:
      return solveKkt<5>(q, free, 5, target, lambda);
    default:
      return solveKkt<kMaxKkt>(q, free, freeCount + 1, target, lambda);
  }
}

WeightVector uniformOver(int n, BaseMask mask) {
  WeightVector w = WeightVector::Zero(n);
  int count = 0;
  for (int i = 0; i < n; ++i) count += (mask >> i) & 1u;
  if (count == 0) {
    w.setConstant(1.0 / n);
    return w;
  }
  for (int i = 0; i < n; ++i)
    if ((mask >> i) & 1u) w[i] = 1.0 / count;
  return w;
}

// Primal active-set method (Nocedal & Wright, Numerical Optimization, §16.5) for
// min ½ wᵀQw on the simplex, started from uniform weights over the bases `isFree` (feasible; all
// bases when the caller has no better guess). Q is the normalised, ridged matrix of the valid
// bases. Each step solves the equality-constrained problem on the free set, walks towards its
// solution until a weight hits 0 (which then becomes bound), and at a sub-problem optimum
// releases the bound weight with the most negative multiplier. On return isFree holds the free
// set at the optimum and smallestMultiplier the least multiplier of a bound weight (+∞ if none).
WeightVector activeSet(const MseMatrix& q, bool nonNegative,
                       std::array<bool, kMaxDenoisers>& isFree, int& iterations,
                       double& smallestMultiplier) {
  const int m = int(q.rows());
  int startCount = 0;
  for (int i = 0; i < m; ++i) startCount += isFree[size_t(i)];
  if (startCount == 0 || !nonNegative) {
    for (int i = 0; i < m; ++i) isFree[size_t(i)] = true;
    startCount = m;
  }
  smallestMultiplier = std::numeric_limits<double>::infinity();
  WeightVector w = WeightVector::Zero(m);
  for (int i = 0; i < m; ++i)
    if (isFree[size_t(i)]) w[i] = 1.0 / startCount;
  WeightVector target = WeightVector::Zero(m);
  double lambda = 0.0;
  bool atSubspaceOptimum = false;
  const int maxIterations = 8 * (m + 2);
  for (iterations = 0; iterations < maxIterations;) {
    if (!atSubspaceOptimum) {
      std::array<int, kMaxDenoisers> free{};
      int freeCount = 0;
      for (int i = 0; i < m; ++i)
        if (isFree[size_t(i)]) free[size_t(freeCount++)] = i;
      ++iterations;
      if (!solveEqualityProblem(q, free, freeCount, target, lambda)) break;
      if (!nonNegative) {
        for (int k = 0; k < freeCount; ++k) w[free[k]] = target[free[k]];
        break;
      }
      // Step length: the largest α ≤ 1 keeping w + α(target − w) ≥ 0.
      double alpha = 1.0;
      int blocking = -1;
      for (int k = 0; k < freeCount; ++k) {
        const int i = free[size_t(k)];
        const double step = target[i] - w[i];
        if (step < 0.0 && w[i] + step < 0.0) {
          const double ratio = w[i] / -step;
          if (ratio < alpha) alpha = ratio, blocking = i;
        }
      }
      if (blocking < 0) {
        for (int k = 0; k < freeCount; ++k) w[free[k]] = target[free[k]];
        atSubspaceOptimum = true;
      } else {
        for (int k = 0; k < freeCount; ++k) {
          const int i = free[size_t(k)];
          w[i] = std::max(0.0, w[i] + alpha * (target[i] - w[i]));
        }
        w[blocking] = 0.0;
        isFree[size_t(blocking)] = false;
        continue;
      }
    }
    // KKT multipliers of the bound weights: μ_i = (Qw)_i − λ must be ≥ 0.
    int release = -1;
    double mostNegative = -kMultiplierTolerance;
    smallestMultiplier = std::numeric_limits<double>::infinity();
    for (int i = 0; i < m; ++i) {
      if (isFree[size_t(i)]) continue;
      const double mu = q.row(i).dot(w) - lambda;
      smallestMultiplier = std::min(smallestMultiplier, mu);
      if (mu < mostNegative) mostNegative = mu, release = i;
    }
    if (release < 0) break;
    isFree[size_t(release)] = true;
    atSubspaceOptimum = false;
  }
  return w;
}

// Whether vᵀAv > 0 for every v ≠ 0 with Σv = 0: a Cholesky factorisation of A in the basis
// e_i − e_last of the tangent space. Only then is the minimiser on the simplex unique.
bool positiveOnTangent(const MseMatrix& a) {
  const int m = int(a.rows()) - 1;
  std::array<std::array<double, kMaxDenoisers>, kMaxDenoisers> b;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j <= i; ++j) b[size_t(i)][size_t(j)] = a(i, j) - a(i, m) - a(m, j) + a(m, m);
  for (int k = 0; k < m; ++k) {
    double d = b[size_t(k)][size_t(k)];
    for (int p = 0; p < k; ++p) d -= b[size_t(k)][size_t(p)] * b[size_t(k)][size_t(p)];
    if (!(d > 0.0)) return false;
    d = std::sqrt(d);
    b[size_t(k)][size_t(k)] = d;
    for (int i = k + 1; i < m; ++i) {
      double v = b[size_t(i)][size_t(k)];
      for (int p = 0; p < k; ++p) v -= b[size_t(i)][size_t(p)] * b[size_t(k)][size_t(p)];
      b[size_t(i)][size_t(k)] = v / d;
    }
  }
  return true;
}

}  // namespace

double quadraticForm(const MseMatrix& m, const WeightVector& w) {
  double sum = 0.0;
  for (int i = 0; i < m.rows(); ++i) {
    double row = 0.0;
    for (int j = 0; j < m.cols(); ++j) row += m(i, j) * w[j];
    sum += w[i] * row;
  }
  return sum;
}

BaseMask finiteBases(const MseMatrix& m, BaseMask valid) {
  const int n = int(m.rows());
  BaseMask mask = valid & allBases(n);
  if (m.allFinite()) return mask;  // the common case, in one pass
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(m(i, i))) mask &= ~(BaseMask(1) << i);
  for (;;) {
    int worst = -1, worstCount = 0;
    for (int i = 0; i < n; ++i) {
      if (!((mask >> i) & 1u)) continue;
      int count = 0;
      for (int j = 0; j < n; ++j)
        if (((mask >> j) & 1u) && !(std::isfinite(m(i, j)) && std::isfinite(m(j, i)))) ++count;
      if (count > worstCount) worst = i, worstCount = count;
    }
    if (worst < 0) return mask;
    mask &= ~(BaseMask(1) << worst);
  }
}

SimplexQpResult solveSimplexQp(const MseMatrix& m, BaseMask valid, const SimplexQpOptions& options,
                               BaseMask start) {
  const int n = int(m.rows());
  SimplexQpResult result;
  const BaseMask mask = finiteBases(m, valid);
  std::array<int, kMaxDenoisers> index{};
  int count = 0;
  for (int i = 0; i < n; ++i)
    if ((mask >> i) & 1u) index[size_t(count++)] = i;
  if (count <= 1) {
    result.weights = uniformOver(n, mask);
    return result;
  }

  // Normalise: remove the mean entry (a multiple of 11ᵀ, constant on the simplex), then divide
  // by the size of what is left on the simplex: f(u + v) = f(u) + 2uᵀAv + vᵀAv around the
  // uniform weights u, v in the tangent space {Σv = 0}. The quadratic part's mean eigenvalue is
  // trace(P A P)/(m − 1), P = I − 11ᵀ/m, = trace(A)/(m − 1) after the shift (1ᵀA1 = 0); the
  // linear part is P A u. Both matter: nearly identical outputs with a common bias have a
  // negligible quadratic part, but the linear part still says which base is least biased.
  MseMatrix a(count, count);
  double largest = 0.0, sum = 0.0;
  for (int r = 0; r < count; ++r)
    for (int c = 0; c < count; ++c) {
      a(r, c) =
          0.5 * (m(index[size_t(r)], index[size_t(c)]) + m(index[size_t(c)], index[size_t(r)]));
      largest = std::max(largest, std::abs(a(r, c)));
    }
  if (!std::isfinite(largest)) {
    result.weights = uniformOver(n, mask);
    return result;
  }
  for (int r = 0; r < count; ++r)
    for (int c = 0; c < count; ++c) sum += a(r, c) / largest;
  a.array() -= sum / (double(count) * count) * largest;
  double linear = 0.0, rowMean = 0.0;
  WeightVector rowSums(count);
  for (int r = 0; r < count; ++r) rowMean += (rowSums[r] = a.row(r).sum() / count);
  rowMean /= count;
  for (int r = 0; r < count; ++r) linear = std::max(linear, std::abs(rowSums[r] - rowMean));
  const double scale = std::max(a.trace() / (count - 1), linear);
  if (!(scale > kNegligibleTangent * largest)) {
    result.weights = uniformOver(n, mask);
    return result;
  }
  a /= scale;
  a.diagonal().array() += options.relativeRidge;
  // Float-stored estimates of nearly identical outputs can be slightly indefinite on the
  // tangent space, where the active set may cycle to its iteration cap without reaching an
  // optimum. Raising the ridge tenfold at a time (ρ, 10ρ, 100ρ, … up to 1e-3 of the mean
  // eigenvalue) until the problem is convex again restores the exact method; the weights move
  // by about as much as the indefiniteness that rounding put there.
  bool convex = positiveOnTangent(a);
  for (double ridge = options.relativeRidge; !convex && ridge < kLargestRidge; ridge *= 10.0) {
    a.diagonal().array() += 9.0 * ridge;  // the diagonal's ridge becomes 10 × ridge
    convex = positiveOnTangent(a);
  }

  // A warm start must not change the result, so it is taken only where the minimiser is unique
  // (the problem is convex, see above), and kept only if every bound weight's multiplier is
  // clearly positive: a multiplier within the solver's tolerance (as for a duplicated base,
  // whose share the ridge decides by only ρ·w) could have gone either way, and the cold start
  // is what decides it.
  std::array<bool, kMaxDenoisers> isFree{};
  double smallestMultiplier = 0.0;
  WeightVector w;
  if ((start & mask) != mask && convex) {
    for (int k = 0; k < count; ++k) isFree[size_t(k)] = (start >> index[size_t(k)]) & 1u;
    int vertex = -1;
    for (int k = 0; k < count; ++k)
      if (isFree[size_t(k)]) vertex = vertex < 0 ? k : -2;
    // One free base v: w = e_v is the optimum if every μ_j = a_jv − a_vv is clearly positive
    // (an equality solve on {v} gives the same up to rounding, and the weights become exactly
    // e_v either way); otherwise the active set continues from there.
    if (vertex >= 0 && options.nonNegative) {
      smallestMultiplier = std::numeric_limits<double>::infinity();
      for (int k = 0; k < count; ++k)
        if (k != vertex)
          smallestMultiplier = std::min(smallestMultiplier, a(k, vertex) - a(vertex, vertex));
    }
    if (vertex >= 0 && options.nonNegative && smallestMultiplier > kClearMultiplier) {
      w = WeightVector::Zero(count);
      w[vertex] = 1.0;
      result.iterations = 1;
    } else {
      w = activeSet(a, options.nonNegative, isFree, result.iterations, smallestMultiplier);
    }
  }
  if (!(smallestMultiplier > kClearMultiplier)) {
    const int warmIterations = result.iterations;
    for (int k = 0; k < count; ++k) isFree[size_t(k)] = true;
    w = activeSet(a, options.nonNegative, isFree, result.iterations, smallestMultiplier);
    result.iterations += warmIterations;
  }

  // Back to all n bases, exactly on the simplex.
  result.weights = WeightVector::Zero(n);
  double total = 0.0;
  for (int k = 0; k < count; ++k) {
    double v = w[k];
    if (options.nonNegative) v = std::max(0.0, v);
    if (!std::isfinite(v)) {
      result.weights = uniformOver(n, mask);
      return result;
    }
    result.weights[index[size_t(k)]] = v;
    if (isFree[size_t(k)]) result.support |= BaseMask(1) << index[size_t(k)];
    total += v;
  }
  if (!(std::abs(total) > 0.0)) {
    result.weights = uniformOver(n, mask);
    return result;
  }
  result.weights /= total;
  return result;
}

}  // namespace chorus
