#include "denoise/ensemble/pairwise_solver.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "denoise/ensemble/simplex_qp.h"

namespace chorus {
namespace {

// SplitMix64 (Steele et al. 2014): a counter-based generator, one state per (seed, stream).
class SplitMix64 {
 public:
  SplitMix64(uint64_t seed, uint64_t stream)
      : state_(seed * 0x9E3779B97F4A7C15ull ^ (stream + 0x632BE59BD9B4E019ull)) {
    next();
  }
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  int below(int n) { return int(next() % uint64_t(n)); }

 private:
  uint64_t state_;
};

}  // namespace

PairwiseSolverResult solvePairwise(const MseMatrix& m, uint64_t seed, uint64_t stream,
                                   BaseMask valid, const PairwiseSolverOptions& options) {
  const int n = int(m.rows());
  PairwiseSolverResult result;
  const BaseMask mask = finiteBases(m, valid);
  std::array<int, kMaxDenoisers> index{};
  int count = 0;
  for (int i = 0; i < n; ++i)
    if ((mask >> i) & 1u) index[size_t(count++)] = i;
  result.weights = WeightVector::Zero(n);
  if (count == 0) {
    result.weights.setConstant(1.0 / n);
    return result;
  }
  if (count == 1) {
    result.weights[index[0]] = 1.0;
    return result;
  }

  // The valid sub-matrix, divided by its largest entry so that any magnitude works.
  MseMatrix a(count, count);
  double largest = 0.0;
  for (int r = 0; r < count; ++r)
    for (int c = 0; c < count; ++c) {
      a(r, c) = m(index[size_t(r)], index[size_t(c)]);
      largest = std::max(largest, std::abs(a(r, c)));
    }
  if (largest > 0.0 && std::isfinite(largest)) a /= largest;

  SplitMix64 rng(seed, stream);
  WeightVector w(count);
  double total = 0.0;
  for (int i = 0; i < count; ++i) total += (w[i] = rng.uniform() + 1e-12);
  w /= total;
  WeightVector mw = a * w;
  double objective = w.dot(mw);

  const double tiny = 1e-300;
  int ineffective = 0;
  const int patience = options.patience > 0 ? options.patience : 2 * count + 1;
  for (result.iterations = 0; result.iterations < options.maxIterations && ineffective < patience;
       ++result.iterations) {
    const int k = rng.below(count);
    // f(α) = (1−α)² wᵀMw + 2α(1−α)(Mw)_k + α² M_kk.
    const double curvature = objective - 2.0 * mw[k] + a(k, k);
    const double slope = objective - mw[k];
    double alpha = curvature > tiny ? slope / curvature : (slope > 0.0 ? 1.0 : 0.0);
    alpha = std::clamp(alpha, 0.0, 1.0);
    if (!std::isfinite(alpha)) alpha = 0.0;
    ineffective = alpha >= options.ineffectiveStep ? 0 : ineffective + 1;
    if (alpha == 0.0) continue;
    const double keep = 1.0 - alpha;
    objective = keep * keep * objective + 2.0 * alpha * keep * mw[k] + alpha * alpha * a(k, k);
    w *= keep;
    w[k] += alpha;
    mw = keep * mw + alpha * a.col(k);
  }

  total = 0.0;
  for (int i = 0; i < count; ++i) total += (w[i] = std::max(0.0, w[i]));
  for (int i = 0; i < count; ++i) result.weights[index[size_t(i)]] = w[i] / total;
  return result;
}

}  // namespace chorus
