// Alias table and 2D piecewise-constant distribution: sampled frequencies against the pmf/pdf
// (χ²), normalisation, and agreement between sample() and pdf().
#include "renderer/sampling/distributions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "common/error.h"
#include "tests/support/chi2.h"

namespace chorus::render {
namespace {

using test::chi2Test;
using test::formatChi2Tables;

constexpr double kSignificance = 0.01;
constexpr int kChi2Tests = 4;  // χ² tests in this file, for the Šidák correction

float uniform(std::mt19937& rng) {
  return std::uniform_real_distribution<float>(0.0f, 1.0f)(rng);
}

std::vector<float> testWeights() {
  std::mt19937 rng(17);
  std::vector<float> weights;
  for (int i = 0; i < 37; ++i) weights.push_back(i % 7 == 3 ? 0.0f : 0.01f + uniform(rng) * 5);
  weights[5] = 40.0f;  // one dominant entry
  return weights;
}

TEST(AliasTable, PmfIsTheNormalisedWeights) {
  const std::vector<float> weights = testWeights();
  const AliasTable table(weights);
  double total = 0;
  for (float w : weights) total += w;
  double sum = 0;
  for (int i = 0; i < table.size(); ++i) {
    EXPECT_NEAR(table.pmf(i), weights[size_t(i)] / total, 1e-7) << i;
    sum += table.pmf(i);
  }
  EXPECT_NEAR(sum, 1.0, 1e-6);
  EXPECT_EQ(table.pmf(-1), 0.0f);
  EXPECT_EQ(table.pmf(table.size()), 0.0f);
}

TEST(AliasTable, SampledFrequenciesMatchThePmf) {
  const std::vector<float> weights = testWeights();
  const AliasTable table(weights);
  const int n = 1000000;
  std::vector<double> observed(weights.size(), 0), expected(weights.size(), 0);
  std::vector<double> remappedObserved(16, 0), remappedExpected(16, n / 16.0);
  std::mt19937 rng(3);
  for (int s = 0; s < n; ++s) {
    float pmf = -1, remapped = -1;
    const int i = table.sample(uniform(rng), &pmf, &remapped);
    ASSERT_GE(i, 0);
    ASSERT_LT(i, table.size());
    ASSERT_EQ(pmf, table.pmf(i));
    ASSERT_GE(remapped, 0.0f);
    ASSERT_LT(remapped, 1.0f);
    observed[size_t(i)] += 1;
    remappedObserved[size_t(remapped * 16)] += 1;
  }
  for (size_t i = 0; i < weights.size(); ++i) expected[i] = n * double(table.pmf(int(i)));
  const auto result = chi2Test(observed, expected);
  EXPECT_TRUE(result.problem.empty()) << result.problem;
  EXPECT_GT(result.pValue, test::sidakSignificance(kSignificance, kChi2Tests))
      << "chi2 " << result.chi2 << " dof " << result.dof << "\n"
      << formatChi2Tables(observed, expected, 1, int(weights.size()));
  std::printf("alias table: chi2 %.1f, dof %d, p = %.3f\n", result.chi2, result.dof, result.pValue);
  // The recovered uniform number is itself uniform, so callers can reuse it.
  const auto remappedResult = chi2Test(remappedObserved, remappedExpected);
  EXPECT_GT(remappedResult.pValue, test::sidakSignificance(kSignificance, kChi2Tests))
      << formatChi2Tables(remappedObserved, remappedExpected, 1, 16);
}

TEST(AliasTable, ExtremeInputs) {
  const std::vector<float> one{3.0f};
  const AliasTable single(one);
  float pmf = 0;
  EXPECT_EQ(single.sample(0.999999f, &pmf), 0);
  EXPECT_EQ(pmf, 1.0f);
  // u just below 1 and exactly 0 stay in range; a zero weight is never returned.
  const std::vector<float> weights{0.0f, 1.0f, 0.0f, 2.0f};
  const AliasTable table(weights);
  for (float u : {0.0f, 0x1.fffffep-1f, 0.25f, 0.5f, 0.74999f}) {
    const int i = table.sample(u, &pmf);
    EXPECT_TRUE(i == 1 || i == 3) << "u " << u << " gave " << i;
  }
  EXPECT_THROW(AliasTable(std::vector<float>{}), Error);
  EXPECT_THROW(AliasTable(std::vector<float>{0.0f, 0.0f}), Error);
  EXPECT_THROW(AliasTable(std::vector<float>{1.0f, -1.0f}), Error);
}

// A 2D function with zero rows, zero cells and a bright spot, as an environment map has.
constexpr int kNu = 8, kNv = 6;
std::vector<float> testFunction() {
  std::vector<float> f(kNu * kNv);
  for (int v = 0; v < kNv; ++v)
    for (int u = 0; u < kNu; ++u) f[size_t(v * kNu + u)] = float(1 + (u * 3 + v * 5) % 7);
  for (int u = 0; u < kNu; ++u) f[size_t(2 * kNu + u)] = 0;  // an empty row
  f[size_t(4 * kNu + 1)] = 0;
  f[size_t(5 * kNu + 6)] = 60;
  return f;
}

TEST(PiecewiseConstant2D, PdfIsTheNormalisedFunctionAndIntegratesToOne) {
  const std::vector<float> f = testFunction();
  const PiecewiseConstant2D distribution(f, kNu, kNv);
  double mean = 0;
  for (float v : f) mean += v / double(f.size());
  // Integrate on a grid 5x finer than the cells (exact for a piecewise-constant pdf).
  const int fine = 5;
  double integral = 0;
  for (int j = 0; j < kNv * fine; ++j)
    for (int i = 0; i < kNu * fine; ++i) {
      const Vec2f p{(i + 0.5f) / (kNu * fine), (j + 0.5f) / (kNv * fine)};
      const float pdf = distribution.pdf(p);
      EXPECT_NEAR(pdf, f[size_t((j / fine) * kNu + i / fine)] / mean, 1e-5);
      integral += pdf / (kNu * fine * kNv * fine);
    }
  EXPECT_NEAR(integral, 1.0, 1e-5);
  EXPECT_EQ(distribution.pdf({-0.1f, 0.5f}), 0.0f);
  EXPECT_EQ(distribution.pdf({0.5f, 1.5f}), 0.0f);
}

TEST(PiecewiseConstant2D, SampledFrequenciesMatchThePdf) {
  const std::vector<float> f = testFunction();
  const PiecewiseConstant2D distribution(f, kNu, kNv);
  // Histogram on a grid that splits every cell 3×3, which also checks the position inside a cell.
  const int split = 3, cols = kNu * split, rows = kNv * split, n = 1000000;
  std::vector<double> observed(size_t(rows * cols), 0), expected(size_t(rows * cols), 0);
  std::mt19937 rng(5);
  for (int s = 0; s < n; ++s) {
    float pdf = -1;
    const Vec2f p = distribution.sample({uniform(rng), uniform(rng)}, &pdf);
    ASSERT_GE(p.x, 0.0f);
    ASSERT_LT(p.x, 1.0f);
    ASSERT_GE(p.y, 0.0f);
    ASSERT_LT(p.y, 1.0f);
    ASSERT_EQ(pdf, distribution.pdf(p)) << p.x << ", " << p.y;
    ASSERT_GT(pdf, 0.0f);
    observed[size_t(int(p.y * rows) * cols + int(p.x * cols))] += 1;
  }
  double total = 0;
  for (float v : f) total += v;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i)
      expected[size_t(j * cols + i)] =
          n * double(f[size_t((j / split) * kNu + i / split)]) / total / (split * split);
  const auto result = chi2Test(observed, expected);
  EXPECT_TRUE(result.problem.empty()) << result.problem;
  EXPECT_GT(result.pValue, test::sidakSignificance(kSignificance, kChi2Tests))
      << "chi2 " << result.chi2 << " dof " << result.dof << "\n"
      << formatChi2Tables(observed, expected, rows, cols);
  std::printf("piecewise-constant 2D: chi2 %.1f, dof %d, p = %.3f\n", result.chi2, result.dof,
              result.pValue);
}

TEST(PiecewiseConstant2D, SamplesStayInTheirCellAtCellBoundaries) {
  // Uniform numbers at the edges of the cdf intervals must not round into a neighbouring cell.
  const int nu = 4096, nv = 3;
  std::vector<float> f(size_t(nu * nv));
  for (size_t i = 0; i < f.size(); ++i) f[i] = float(1 + i % 5);
  const PiecewiseConstant2D distribution(f, nu, nv);
  for (float ux : {0.0f, 0x1.fffffep-1f, 0.5f, 0.2f, 0.99999f})
    for (float uy : {0.0f, 0x1.fffffep-1f, 0.5f}) {
      float pdf = 0;
      const Vec2f p = distribution.sample({ux, uy}, &pdf);
      EXPECT_LT(p.x, 1.0f);
      EXPECT_LT(p.y, 1.0f);
      EXPECT_EQ(pdf, distribution.pdf(p)) << ux << ", " << uy;
    }
}

TEST(PiecewiseConstant2D, WideRowsInvertTheirCdfExactly) {
  // As wide as a 1k environment map, with runs of empty cells and spikes, so that the search
  // goes through the guide tables: every u (a fine sweep that includes the guides' own steps,
  // multiples of 1/64) must land in the cell a brute-force inversion of the cdf gives.
  const int nu = 1024, nv = 2;
  std::vector<float> f(size_t(nu * nv));
  for (int i = 0; i < nu; ++i) {
    f[size_t(i)] = (i / 40) % 3 == 0 ? 0.0f : float(1 + i % 7);  // empty runs of 40
    f[size_t(nu + i)] = i % 97 == 0 ? 500.0f : 0.01f;            // spikes on a dim floor
  }
  const PiecewiseConstant2D distribution(f, nu, nv);
  for (int row = 0; row < nv; ++row) {
    std::vector<double> cdf(size_t(nu + 1), 0.0);
    for (int i = 0; i < nu; ++i) cdf[size_t(i + 1)] = cdf[size_t(i)] + f[size_t(row * nu + i)];
    for (double& c : cdf) c /= cdf[size_t(nu)];
    // Row 0 holds about a third of the integral, row 1 the rest.
    const float uy = row == 0 ? 0.125f : 0.9f;
    float previousX = -1;
    for (int s = 0; s < 16384; ++s) {
      const float ux = float(s) / 16384.0f;
      float pdf = 0;
      const Vec2f p = distribution.sample({ux, uy}, &pdf);
      ASSERT_EQ(int(p.y * nv), row);
      ASSERT_GT(pdf, 0.0f) << "u " << ux << " sampled an empty cell";
      ASSERT_GE(p.x, previousX) << "inversion is monotone in u";
      previousX = p.x;
      const int expected =
          int(std::upper_bound(cdf.begin() + 1, cdf.end(), double(ux)) - cdf.begin()) - 1;
      const double edge =
          std::min(std::abs(ux - cdf[size_t(expected)]), std::abs(ux - cdf[size_t(expected + 1)]));
      if (edge > 1e-5) {
        ASSERT_EQ(int(p.x * nu), expected) << "u " << ux;
      }
    }
  }
}

TEST(PiecewiseConstant2D, AllZeroFunctionIsUniform) {
  const std::vector<float> zeros(12, 0.0f);
  const PiecewiseConstant2D distribution(zeros, 4, 3);
  float pdf = 0;
  const Vec2f p = distribution.sample({0.3f, 0.7f}, &pdf);
  EXPECT_EQ(pdf, 1.0f);
  EXPECT_NEAR(p.x, 0.3f, 1e-6);
  EXPECT_NEAR(p.y, 0.7f, 1e-6);
  EXPECT_THROW(PiecewiseConstant2D(zeros, 5, 3), Error);
}

}  // namespace
}  // namespace chorus::render
