#include "tests/support/chi2.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace chorus::test {

double upperIncompleteGammaRatio(double a, double x) {
  if (x <= 0) return 1.0;
  const double logPrefactor = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    // Series for the lower function: P(a, x) = e^−x x^a / Γ(a+1) · Σ x^n / ((a+1)…(a+n)).
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 100000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-15) break;
    }
    return std::max(0.0, 1.0 - sum * std::exp(logPrefactor));
  }
  // Continued fraction for Q(a, x), evaluated with the modified Lentz method.
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return std::exp(logPrefactor) * h;
}

double chi2PValue(double chi2, int dof) {
  if (dof <= 0) return 1.0;
  return upperIncompleteGammaRatio(0.5 * dof, 0.5 * chi2);
}

Chi2Result chi2Test(const std::vector<double>& observed, const std::vector<double>& expected,
                    double minExpected) {
  Chi2Result result;
  std::vector<size_t> order(expected.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return expected[a] < expected[b]; });

  double pooledObserved = 0, pooledExpected = 0;
  int cells = 0;
  for (size_t i : order) {
    if (expected[i] == 0) {
      if (observed[i] > 0) {
        char buffer[128];
        std::snprintf(buffer, sizeof buffer, "%g samples in cell %zu where the pdf is 0",
                      observed[i], i);
        result.problem = buffer;
        return result;
      }
      continue;
    }
    if (expected[i] < minExpected) {
      pooledObserved += observed[i];
      pooledExpected += expected[i];
      // Close the pool once it is large enough to count as a cell of its own.
      if (pooledExpected >= minExpected) {
        result.chi2 +=
            (pooledObserved - pooledExpected) * (pooledObserved - pooledExpected) / pooledExpected;
        ++cells;
        pooledObserved = pooledExpected = 0;
      }
      continue;
    }
    result.chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++cells;
  }
  if (pooledExpected > 0) {
    // A small remainder joins the χ² as its own term, as Mitsuba does.
    result.chi2 +=
        (pooledObserved - pooledExpected) * (pooledObserved - pooledExpected) / pooledExpected;
    ++cells;
  }
  result.dof = cells - 1;
  result.pValue = chi2PValue(result.chi2, result.dof);
  return result;
}

double sidakSignificance(double alpha, int testCount) {
  return 1.0 - std::pow(1.0 - alpha, 1.0 / testCount);
}

std::string formatChi2Tables(const std::vector<double>& observed,
                             const std::vector<double>& expected, int rows, int cols) {
  std::string text;
  char buffer[32];
  for (const auto* table : {&observed, &expected}) {
    text += table == &observed ? "observed:\n" : "expected:\n";
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        std::snprintf(buffer, sizeof buffer, "%8.1f", (*table)[size_t(r * cols + c)]);
        text += buffer;
      }
      text += '\n';
    }
  }
  return text;
}

}  // namespace chorus::test
