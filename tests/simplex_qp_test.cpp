// The exact simplex QP solver against independent brute force: a dense grid over the simplex
// for N = 2, 3; many random starts of accelerated projected gradient descent plus a KKT check
// for N up to 8 and N = 16; degenerate, extreme and non-finite matrices.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "denoise/ensemble/simplex_qp.h"

namespace chorus {
namespace {

using Dense = Eigen::MatrixXd;
using DenseVector = Eigen::VectorXd;

// ---- instances -----------------------------------------------------------------------------

enum class Shape { FullRank, RankOne, RankTwo, NearlyCollinear, Duplicated, DataLike };

// ⟨M⟩-like matrices: sums of outer products of residual vectors (PSD), plus c·11ᵀ with c of
// either sign (PSD on the simplex's tangent space, like the dual-buffer estimate).
MseMatrix randomInstance(int n, Shape shape, std::mt19937_64& rng) {
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  MseMatrix m = MseMatrix::Zero(n, n);
  WeightVector v(n);
  const auto addOuter = [&](const WeightVector& e) { m += e * e.transpose(); };
  switch (shape) {
    case Shape::FullRank:
      for (int k = 0; k < n + 2; ++k) {
        for (int i = 0; i < n; ++i) v[i] = gauss(rng);
        addOuter(v);
      }
      break;
    case Shape::RankOne:
    case Shape::RankTwo:
      for (int k = 0; k < (shape == Shape::RankOne ? 1 : 2); ++k) {
        for (int i = 0; i < n; ++i) v[i] = gauss(rng);
        addOuter(v);
      }
      break;
    case Shape::NearlyCollinear: {
      // Base outputs that differ by 1e-6 of their size.
      const double common = gauss(rng);
      for (int k = 0; k < 3; ++k) {
        for (int i = 0; i < n; ++i) v[i] = common + 1e-6 * gauss(rng);
        addOuter(v);
      }
      break;
    }
    case Shape::Duplicated:
      // Bases 0 and 1 have identical outputs (identical residuals).
      for (int k = 0; k < 4; ++k) {
        for (int i = 0; i < n; ++i) v[i] = gauss(rng);
        if (n > 1) v[1] = v[0];
        addOuter(v);
      }
      break;
    case Shape::DataLike: {
      // ½(e^A e^Aᵀ + e^B e^Bᵀ) − ½(x^A − x^B)² 11ᵀ over a few pixels of a 3×3 window.
      for (int tap = 0; tap < 9; ++tap) {
        const double mu = 1.0 + gauss(rng), xA = mu + 0.3 * gauss(rng), xB = mu + 0.3 * gauss(rng);
        WeightVector eA(n), eB(n);
        for (int i = 0; i < n; ++i) {
          const double bias = 0.2 * gauss(rng);
          eA[i] = mu + bias + 0.1 * gauss(rng) - xB;
          eB[i] = mu + bias + 0.1 * gauss(rng) - xA;
        }
        m += 0.5 * (eA * eA.transpose() + eB * eB.transpose());
        m.array() -= 0.5 * (xA - xB) * (xA - xB);
      }
      return m;
    }
  }
  m.array() += uniform(rng) * m.cwiseAbs().maxCoeff();
  return m;
}

// The size of wᵀMw's variation over the simplex, the unit of the tolerances: the mean
// eigenvalue of M on the tangent space plus the largest tangent component of M's gradient at
// the uniform weights.
double tangentScale(const MseMatrix& m) {
  const int n = int(m.rows());
  if (n < 2) return std::abs(m(0, 0));
  const Dense p = Dense::Identity(n, n) - Dense::Constant(n, n, 1.0 / n);
  const DenseVector gradient = p * (Dense(m) * DenseVector::Constant(n, 1.0 / n));
  return (m.trace() - m.sum() / n) / (n - 1) + gradient.cwiseAbs().maxCoeff();
}

// ---- independent references ----------------------------------------------------------------

double objective(const MseMatrix& m, const DenseVector& w) {
  return w.dot(Dense(m) * w);
}

// Best value of wᵀMw over the grid {k/steps} ∩ simplex (N = 2 or 3).
double gridMinimum(const MseMatrix& m, int steps) {
  const int n = int(m.rows());
  double a[3][3] = {};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a[i][j] = m(i, j);
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= steps; ++i)
    for (int j = n == 2 ? steps - i : 0; i + j <= steps; ++j) {
      const double w[3] = {double(i) / steps, double(j) / steps, double(steps - i - j) / steps};
      double f = 0;
      for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) f += w[r] * a[r][c] * w[c];
      best = std::min(best, f);
    }
  return best;
}

// Euclidean projection onto the simplex (sort-based, Held et al. 1974).
DenseVector projectToSimplex(const DenseVector& v) {
  std::vector<double> sorted(v.data(), v.data() + v.size());
  std::sort(sorted.begin(), sorted.end(), std::greater<>());
  double cumulative = 0, theta = 0;
  for (size_t k = 0; k < sorted.size(); ++k) {
    cumulative += sorted[k];
    const double candidate = (cumulative - 1.0) / double(k + 1);
    if (sorted[k] - candidate > 0) theta = candidate;
  }
  return (v.array() - theta).max(0.0).matrix();
}

// FISTA (accelerated projected gradient) from `starts` random points; the best value found.
double projectedGradientMinimum(const MseMatrix& m, int starts, int iterations,
                                std::mt19937_64& rng) {
  const int n = int(m.rows());
  // Only the tangent part matters; the Lipschitz constant of the gradient 2Mw restricted to
  // the simplex is 2·λmax(P M P).
  const Dense p = Dense::Identity(n, n) - Dense::Constant(n, n, 1.0 / n);
  const Dense dense = m;
  const double lipschitz =
      2.0 * std::max(1e-300,
                     Eigen::SelfAdjointEigenSolver<Dense>(p * dense * p).eigenvalues().maxCoeff());
  std::exponential_distribution<double> exponential;
  double best = std::numeric_limits<double>::infinity();
  for (int s = 0; s < starts; ++s) {
    DenseVector w(n);
    for (int i = 0; i < n; ++i) w[i] = exponential(rng);
    w /= w.sum();
    DenseVector y = w;
    double t = 1;
    for (int k = 0; k < iterations; ++k) {
      const DenseVector next = projectToSimplex(y - (2.0 * (dense * y)) / lipschitz);
      if (objective(m, next) > objective(m, w)) {
        // Adaptive restart (O'Donoghue & Candès 2015): drop the momentum.
        y = w;
        t = 1;
        continue;
      }
      const double tNext = 0.5 * (1 + std::sqrt(1 + 4 * t * t));
      y = next + ((t - 1) / tNext) * (next - w);
      t = tNext;
      w = next;
    }
    best = std::min(best, objective(m, w));
  }
  return best;
}

// KKT conditions of min wᵀMw on the simplex: g = 2Mw equals λ on the support and is ≥ λ off
// it, up to `tolerance`.
void expectKkt(const MseMatrix& m, const WeightVector& w, double tolerance) {
  const int n = int(m.rows());
  const WeightVector g = 2.0 * (m * w);
  double lambda = 0, mass = 0;
  for (int i = 0; i < n; ++i) lambda += w[i] * g[i], mass += w[i];
  lambda /= mass;
  for (int i = 0; i < n; ++i) {
    if (w[i] > 1e-7) {
      EXPECT_NEAR(g[i], lambda, tolerance) << "support index " << i;
    } else {
      EXPECT_GE(g[i] - lambda, -tolerance) << "bound index " << i;
    }
  }
}

void expectOnSimplex(const WeightVector& w, int n) {
  ASSERT_EQ(w.size(), n);
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    ASSERT_TRUE(std::isfinite(w[i])) << "weight " << i;
    ASSERT_GE(w[i], 0.0) << "weight " << i;
    sum += w[i];
  }
  ASSERT_NEAR(sum, 1.0, 1e-6);
}

const Shape kShapes[] = {Shape::FullRank,        Shape::RankOne,    Shape::RankTwo,
                         Shape::NearlyCollinear, Shape::Duplicated, Shape::DataLike};

// ---- tests ---------------------------------------------------------------------------------

TEST(SimplexQp, MatchesDenseGridForTwoAndThreeBases) {
  std::mt19937_64 rng(11);
  int instances = 0;
  for (int n : {2, 3})
    for (Shape shape : kShapes)
      for (int k = 0; k < (n == 2 ? 400 : 170); ++k, ++instances) {
        const MseMatrix m = randomInstance(n, shape, rng);
        const WeightVector w = solveSimplexQp(m).weights;
        expectOnSimplex(w, n);
        const double scale = std::max(tangentScale(m), 1e-300);
        // The grid minimum is an upper bound of the optimum: the solver must reach it, up to
        // its tie-breaking ridge (≤ 1e-8·s) and rounding.
        const double grid = gridMinimum(m, n == 2 ? 4000 : 300);
        ASSERT_LE(objective(m, w), grid + 1e-7 * scale + 1e-12 * m.cwiseAbs().maxCoeff())
            << "n " << n << " shape " << int(shape) << " instance " << k << "\n"
            << m;
      }
  EXPECT_GE(instances, 3000);
}

// Estimates of two nearly identical outputs left slightly indefinite on the tangent space
// (here −1e-5 of its scale along e_0 − e_1, as float rounding does): the solver ends well
// before its iteration cap on weights within the convexifying ridge (≤ 1e-3·s) of the grid
// optimum.
TEST(SimplexQp, SlightlyIndefiniteEstimatesConverge) {
  std::mt19937_64 rng(13);
  for (int n : {3, 5})
    for (int k = 0; k < 200; ++k) {
      MseMatrix m = randomInstance(n, Shape::Duplicated, rng);
      const double scale = std::max(tangentScale(m), 1e-300);
      WeightVector v = WeightVector::Zero(n);
      v[0] = 1.0, v[1] = -1.0;
      m -= 1e-5 * scale * v * v.transpose();
      const SimplexQpResult result = solveSimplexQp(m);
      expectOnSimplex(result.weights, n);
      ASSERT_LT(result.iterations, 8 * (n + 2)) << "n " << n << " instance " << k;
      if (n == 3) {
        ASSERT_LE(objective(m, result.weights), gridMinimum(m, 300) + 1e-3 * scale)
            << "instance " << k << "\n"
            << m;
      }
    }
}

TEST(SimplexQp, MatchesProjectedGradientAndKktUpToEightBases) {
  std::mt19937_64 rng(12);
  int instances = 0;
  for (int n = 4; n <= 8; ++n)
    for (Shape shape : kShapes)
      for (int k = 0; k < 40; ++k, ++instances) {
        const MseMatrix m = randomInstance(n, shape, rng);
        const WeightVector w = solveSimplexQp(m).weights;
        expectOnSimplex(w, n);
        const double scale = std::max(tangentScale(m), 1e-300);
        const double reference = projectedGradientMinimum(m, 6, 400, rng);
        ASSERT_LE(objective(m, w), reference + 1e-7 * scale + 1e-12 * m.cwiseAbs().maxCoeff())
            << "n " << n << " shape " << int(shape) << " instance " << k;
        expectKkt(m, w, 1e-6 * scale * n + 1e-11 * m.cwiseAbs().maxCoeff());
      }
  EXPECT_GE(instances, 1000);
}

TEST(SimplexQp, SixteenBases) {
  std::mt19937_64 rng(13);
  for (Shape shape : kShapes)
    for (int k = 0; k < 8; ++k) {
      const MseMatrix m = randomInstance(16, shape, rng);
      const SimplexQpResult result = solveSimplexQp(m);
      expectOnSimplex(result.weights, 16);
      const double scale = tangentScale(m);
      EXPECT_LE(objective(m, result.weights),
                projectedGradientMinimum(m, 4, 1500, rng) + 1e-7 * scale)
          << "shape " << int(shape);
      expectKkt(m, result.weights, 1e-5 * scale + 1e-11 * m.cwiseAbs().maxCoeff());
    }
}

TEST(SimplexQp, OneBaseGetsEverything) {
  MseMatrix m(1, 1);
  m << 3.0;
  const WeightVector w = solveSimplexQp(m).weights;
  ASSERT_EQ(w.size(), 1);
  EXPECT_EQ(w[0], 1.0);
}

TEST(SimplexQp, TieBreakPicksMinimiserClosestToUniform) {
  // Rank one, residuals e = (−1, 0, 2): every w with −w₁ + 2w₃ = 0 is optimal (objective 0);
  // the one closest to (⅓, ⅓, ⅓) is (3/7, 5/14, 3/14) (minimise |w − u|² on that segment).
  WeightVector e(3);
  e << -1.0, 0.0, 2.0;
  const WeightVector w = solveSimplexQp(e * e.transpose()).weights;
  EXPECT_NEAR(w[0], 3.0 / 7.0, 1e-6);
  EXPECT_NEAR(w[1], 5.0 / 14.0, 1e-6);
  EXPECT_NEAR(w[2], 3.0 / 14.0, 1e-6);
  // Symmetric residuals (−1, 0, 1): the closest minimiser is uniform.
  e << -1.0, 0.0, 1.0;
  const WeightVector u = solveSimplexQp(e * e.transpose()).weights;
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(u[i], 1.0 / 3.0, 1e-6);
}

TEST(SimplexQp, IdenticalOutputsShareWeight) {
  std::mt19937_64 rng(14);
  for (int k = 0; k < 200; ++k) {
    const int n = 2 + k % 7;
    const WeightVector w = solveSimplexQp(randomInstance(n, Shape::Duplicated, rng)).weights;
    EXPECT_NEAR(w[0], w[1], 1e-6) << "instance " << k;
  }
}

TEST(SimplexQp, AllEqualOutputsGiveUniformWeights) {
  for (int n : {2, 5, 16}) {
    // Every base has the same residuals: ⟨M⟩ is a multiple of 11ᵀ (here of either sign).
    for (double c : {4.0, -2.5, 0.0}) {
      const WeightVector w = solveSimplexQp(MseMatrix::Constant(n, n, c)).weights;
      for (int i = 0; i < n; ++i) EXPECT_DOUBLE_EQ(w[i], 1.0 / n) << "n " << n << " c " << c;
    }
  }
}

TEST(SimplexQp, ScaleInvariantFrom1e30To1eMinus30) {
  std::mt19937_64 rng(15);
  for (Shape shape : kShapes)
    for (int k = 0; k < 30; ++k) {
      const int n = 2 + k % 6;
      const MseMatrix m = randomInstance(n, shape, rng);
      const WeightVector w = solveSimplexQp(m).weights;
      for (double factor : {1e-30, 1e-15, 1e15, 1e30}) {
        const WeightVector scaled = solveSimplexQp(MseMatrix(m * factor)).weights;
        expectOnSimplex(scaled, n);
        for (int i = 0; i < n; ++i)
          EXPECT_NEAR(scaled[i], w[i], 1e-7) << "factor " << factor << " shape " << int(shape);
      }
    }
}

TEST(SimplexQp, NonFiniteBaseGetsZeroWeight) {
  std::mt19937_64 rng(16);
  const double kBad[] = {std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::infinity(),
                         -std::numeric_limits<double>::infinity()};
  for (int k = 0; k < 60; ++k) {
    const int n = 3 + k % 5;
    const MseMatrix m = randomInstance(n, Shape::FullRank, rng);
    const int bad = k % n;
    MseMatrix broken = m;
    broken.row(bad).setConstant(kBad[k % 3]);
    broken.col(bad).setConstant(kBad[k % 3]);
    const WeightVector w = solveSimplexQp(broken).weights;
    expectOnSimplex(w, n);
    EXPECT_EQ(w[bad], 0.0);
    // The others are the solution without that base.
    MseMatrix reduced(n - 1, n - 1);
    for (int r = 0, rr = 0; r < n; ++r) {
      if (r == bad) continue;
      for (int c = 0, cc = 0; c < n; ++c)
        if (c != bad) reduced(rr, cc++) = m(r, c);
      ++rr;
    }
    const WeightVector expected = solveSimplexQp(reduced).weights;
    for (int i = 0, j = 0; i < n; ++i) {
      if (i != bad) {
        EXPECT_NEAR(w[i], expected[j], 1e-12);
        ++j;
      }
    }
  }
  // The validity mask does the same without touching the matrix.
  const MseMatrix m = randomInstance(4, Shape::FullRank, rng);
  const WeightVector masked = solveSimplexQp(m, 0b1011).weights;
  EXPECT_EQ(masked[2], 0.0);
  expectOnSimplex(masked, 4);
}

TEST(SimplexQp, AlwaysFiniteOnTheSimplex) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (int n : {1, 2, 4, 16}) {
    for (double fill : {nan, inf, 0.0, 1e300, -1e300, 1e-300}) {
      const WeightVector w = solveSimplexQp(MseMatrix::Constant(n, n, fill)).weights;
      expectOnSimplex(w, n);
    }
    const WeightVector none = solveSimplexQp(MseMatrix::Identity(n, n), 0).weights;
    expectOnSimplex(none, n);
  }
  // Overflowing entries between two otherwise finite bases.
  MseMatrix m = MseMatrix::Identity(3, 3);
  m(0, 1) = m(1, 0) = inf;
  expectOnSimplex(solveSimplexQp(m).weights, 3);
}

TEST(SimplexQp, UnconstrainedSolvesTheAffineProblem) {
  // With only Σw = 1 the minimiser of wᵀ(M + ρsI)w is M⁻¹1 / 1ᵀM⁻¹1 (M positive definite).
  std::mt19937_64 rng(17);
  for (int k = 0; k < 50; ++k) {
    const int n = 2 + k % 8;
    const MseMatrix m = randomInstance(n, Shape::FullRank, rng);
    SimplexQpOptions options;
    options.nonNegative = false;
    options.relativeRidge = 0.0;
    const WeightVector w = solveSimplexQp(m, ~BaseMask(0), options).weights;
    const DenseVector x = Dense(m).ldlt().solve(DenseVector::Ones(n));
    const DenseVector expected = x / x.sum();
    for (int i = 0; i < n; ++i)
      EXPECT_NEAR(w[i], expected[i], 1e-6 * expected.cwiseAbs().maxCoeff());
  }
}

TEST(SimplexQp, Deterministic) {
  std::mt19937_64 rng(18);
  for (int k = 0; k < 50; ++k) {
    const MseMatrix m = randomInstance(2 + k % 10, kShapes[k % 6], rng);
    const WeightVector a = solveSimplexQp(m).weights, b = solveSimplexQp(m).weights;
    for (int i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]);
  }
}

}  // namespace
}  // namespace chorus
