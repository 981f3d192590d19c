#pragma once
// Pearson's χ² goodness-of-fit test for sampling routines, in the manner of Mitsuba's chi2.py:
// histogram the samples, compare with the expected counts (the pdf integrated over each cell),
// pool low-expectation cells, and judge the p-value against a Šidák-corrected significance.
#include <string>
#include <vector>

namespace chorus::test {

// Q(a, x) = Γ(a, x) / Γ(a): the upper regularised incomplete gamma function.
double upperIncompleteGammaRatio(double a, double x);
// P(X ≥ chi2) for X ~ χ²(dof).
double chi2PValue(double chi2, int dof);

struct Chi2Result {
  double chi2 = 0;
  int dof = 0;
  double pValue = 0;
  // Why the test failed outright (samples where the expected count is 0), or empty.
  std::string problem;
};

// observed and expected have one entry per cell (expected need not be integral). Cells whose
// expected count is below minExpected are pooled into one cell.
Chi2Result chi2Test(const std::vector<double>& observed, const std::vector<double>& expected,
                    double minExpected = 5.0);

// Per-test significance so that `testCount` tests together keep the overall level `alpha`.
double sidakSignificance(double alpha, int testCount);

// Both tables (rows × cols, row-major) as text, for failure messages.
std::string formatChi2Tables(const std::vector<double>& observed,
                             const std::vector<double>& expected, int rows, int cols);

}  // namespace chorus::test
