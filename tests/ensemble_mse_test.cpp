// The dual-buffer MSE estimate: against a naive per-pixel implementation of its definition,
// unbiased for the half-buffer error matrix (statistically, over many noise seeds, with a
// leaky estimator as negative control), and robust to non-finite inputs and extreme scales.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "common/error.h"
#include "denoise/ensemble/blend.h"
#include "denoise/ensemble/combiners.h"
#include "denoise/ensemble/mse_estimate.h"
#include "denoise/metrics/metrics.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

// Base-denoiser stand-ins, deterministic functions of the image they are given.
Image boxBlur(const Image& in, int r) {
  Image out(in.width(), in.height(), 3);
  for (int y = 0; y < in.height(); ++y)
    for (int x = 0; x < in.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        double sum = 0;
        int count = 0;
        for (int qy = std::max(0, y - r); qy <= std::min(in.height() - 1, y + r); ++qy)
          for (int qx = std::max(0, x - r); qx <= std::min(in.width() - 1, x + r); ++qx, ++count)
            sum += in(qx, qy, c);
        out(x, y, c) = float(sum / count);
      }
  return out;
}
Image scaled(const Image& in, float factor) {
  Image out = in;
  for (float& v : out.values()) v *= factor;
  return out;
}

struct Fixture {
  EnsembleGuides guides;
  std::vector<BaseOutputs> bases;
  Image truth;
};

// A smooth truth with an edge, halves with independent noise, three bases run on half A, half
// B and the full buffer. With `quarters`, the halves are the means of two quarters each (noise
// √2 times the halves'), and the bases also run on every three of the four (held-out runs).
Fixture makeFixture(int w, int h, uint64_t seed, float noise = 0.3f, bool quarters = false) {
  Fixture f;
  f.truth = Image(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        f.truth(x, y, c) = 0.5f + 0.1f * c + (x > w / 2 ? 0.8f : 0.0f) + 0.02f * y;
  std::mt19937_64 rng(seed);
  const auto noisy = [&](float sigma) {
    std::normal_distribution<float> gauss(0.0f, sigma);
    Image out = f.truth;
    for (float& v : out.values()) v += gauss(rng);
    return out;
  };
  const auto mean = [](std::vector<const Image*> images) {
    Image out = *images[0];
    for (size_t e = 0; e < out.size(); ++e) {
      double sum = 0;
      for (const Image* image : images) sum += image->data()[e];
      out.data()[e] = float(sum / double(images.size()));
    }
    return out;
  };
  if (quarters) {
    for (int k = 0; k < 4; ++k) f.guides.quarters.push_back(noisy(noise * std::sqrt(2.0f)));
    const std::vector<Image>& q = f.guides.quarters;
    f.guides.colorA = mean({&q[0], &q[1]});
    f.guides.colorB = mean({&q[2], &q[3]});
  } else {
    f.guides.colorA = noisy(noise);
    f.guides.colorB = noisy(noise);
  }
  f.guides.color = mean({&f.guides.colorA, &f.guides.colorB});
  f.guides.albedo = Image(w, h, 3, 0.5f);
  f.guides.normal = Image(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      f.guides.normal(x, y, 2) = 1.0f;
      for (int c = 0; c < 3; ++c) f.guides.albedo(x, y, c) = x > w / 2 ? 0.8f : 0.3f;
    }
  const auto run = [&](const std::string& name, auto fn) {
    BaseOutputs b{name, fn(f.guides.colorA), fn(f.guides.colorB), fn(f.guides.color), {}};
    const std::vector<Image>& q = f.guides.quarters;
    if (quarters)
      for (int k = 0; k < 4; ++k) {
        std::vector<const Image*> others;
        for (int j = 0; j < 4; ++j)
          if (j != k) others.push_back(&q[size_t(j)]);
        b.heldOut.push_back(fn(mean(others)));
      }
    f.bases.push_back(std::move(b));
  };
  run("box1", [](const Image& in) { return boxBlur(in, 1); });
  run("box3", [](const Image& in) { return boxBlur(in, 3); });
  run("dim", [](const Image& in) { return scaled(boxBlur(in, 2), 0.9f); });
  return f;
}

std::vector<const BaseOutputs*> pointers(const Fixture& f) {
  return pointersTo(f.bases);
}

// The window's colour guide from its definition (MseOptions::windowSigmaColor): the mean z̄ of
// the bases' full runs and the noisy halves' ½(x^A − x^B)² under a Gaussian blur (radius 4,
// σ 1.7, clipped and renormalised at the borders), both in units of s = mean |z̄|, plus
// (0.05 z̄ / s)².
struct WindowColor {
  Image z, v;
};
WindowColor windowColorOf(const Fixture& f) {
  const int w = f.truth.width(), h = f.truth.height();
  WindowColor out{Image(w, h, 3), Image(w, h, 3)};
  double scale = 0;
  for (size_t e = 0; e < out.z.size(); ++e) {
    double sum = 0;
    for (const BaseOutputs& b : f.bases) sum += b.full.data()[e];
    out.z.data()[e] = float(sum / double(f.bases.size()));
    scale += std::abs(out.z.data()[e]) / double(out.z.size());
  }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        double sum = 0, weight = 0;
        for (int qy = std::max(0, y - 4); qy <= std::min(h - 1, y + 4); ++qy)
          for (int qx = std::max(0, x - 4); qx <= std::min(w - 1, x + 4); ++qx) {
            const double t =
                std::exp(-0.5 * ((qx - x) * (qx - x) + (qy - y) * (qy - y)) / (1.7 * 1.7));
            const double d = double(f.guides.colorA(qx, qy, c)) - f.guides.colorB(qx, qy, c);
            sum += t * 0.5 * d * d;
            weight += t;
          }
        const double z = out.z(x, y, c) / scale;
        out.v(x, y, c) = float(sum / weight / (scale * scale) + std::pow(0.05 * z, 2));
        out.z(x, y, c) = float(z);
      }
  return out;
}

// The window's joint-bilateral weight k(p, q), in double.
double windowWeight(const Fixture& f, const MseOptions& o, const WindowColor& color, int x, int y,
                    int qx, int qy) {
  if (o.windowRadius == 0) return 1.0;
  const double sigmaSpatial = o.windowSigmaSpatial > 0 ? o.windowSigmaSpatial : o.windowRadius;
  double d = ((qx - x) * (qx - x) + (qy - y) * (qy - y)) / (2 * sigmaSpatial * sigmaSpatial);
  for (int c = 0; c < 3; ++c) {
    d += std::pow(f.guides.normal(x, y, c) - f.guides.normal(qx, qy, c), 2) /
         (2.0 * o.windowSigmaNormal * o.windowSigmaNormal);
    d += std::pow(f.guides.albedo(x, y, c) - f.guides.albedo(qx, qy, c), 2) /
         (2.0 * o.windowSigmaAlbedo * o.windowSigmaAlbedo);
    if (o.windowSigmaColor > 0)
      d += std::pow(color.z(x, y, c) - color.z(qx, qy, c), 2) /
           (2.0 * o.windowSigmaColor * o.windowSigmaColor *
            (double(color.v(x, y, c)) + color.v(qx, qy, c) + 1e-6));
  }
  return std::exp(-d);
}

// The relative terms' 1 / (μ_f² + ε) of fold A (y^A against x^B, run = &BaseOutputs::a) or B,
// μ_f the mean of the bases' runs of that fold.
double foldWeight(const Fixture& f, Image BaseOutputs::*run, int x, int y, int c, double epsilon) {
  double mu = 0;
  for (const BaseOutputs& b : f.bases) mu += (b.*run)(x, y, c);
  mu /= double(f.bases.size());
  return 1.0 / (mu * mu + epsilon);
}

// ⟨M⟩ at one pixel straight from the definition, in double.
PixelMse naiveMse(const Fixture& f, const MseOptions& o, int x, int y) {
  const int n = int(f.bases.size()), w = f.truth.width(), h = f.truth.height();
  const int groups = o.form == MseForm::PerChannel ? 3 : 1;
  const WindowColor color = windowColorOf(f);
  PixelMse out;
  out.groups = groups;
  for (int g = 0; g < groups; ++g) out.h[size_t(g)] = MseMatrix::Zero(n, n);
  // The relative form's weight of fold A or B (foldWeight); 1 otherwise.
  const auto weightOf = [&](int qx, int qy, int c, Image BaseOutputs::*run) {
    return o.relative ? foldWeight(f, run, qx, qy, c, kRelMseEpsilon) : 1.0;
  };
  // Σ_c Σ_i ½(w_A (y_i^A − x^B)² + w_B (y_i^B − x^A)²).
  const auto traceAt = [&](int qx, int qy) {
    double trace = 0;
    for (int c = 0; c < 3; ++c) {
      const double xA = f.guides.colorA(qx, qy, c), xB = f.guides.colorB(qx, qy, c);
      const double wA = weightOf(qx, qy, c, &BaseOutputs::a);
      const double wB = weightOf(qx, qy, c, &BaseOutputs::b);
      for (const BaseOutputs& b : f.bases)
        trace +=
            0.5 * (wA * std::pow(b.a(qx, qy, c) - xB, 2) + wB * std::pow(b.b(qx, qy, c) - xA, 2));
    }
    return trace;
  };
  // outlierCap F scales each pixel's terms by F / (tr H (all groups) / u + F): u the larger of
  // 1 (relative form) or the mean |x^A|, |x^B| squared (absolute) and the 95th percentile of
  // the image's per-pixel traces (every row: the fixture is far below 512 rows; relative
  // form: every fourth row).
  double unit = 1.0;
  if (!o.relative) {
    double sum = 0;
    for (const Image* image : {&f.guides.colorA, &f.guides.colorB})
      for (float v : image->values()) sum += std::abs(v);
    unit = std::pow(sum / double(2 * f.truth.size()), 2);
  }
  std::vector<double> traces;
  for (int qy = 0; qy < h; qy += o.relative ? 4 : 1)
    for (int qx = 0; qx < w; ++qx) traces.push_back(traceAt(qx, qy));
  std::sort(traces.begin(), traces.end());
  unit = std::max(unit, traces[std::min(traces.size() - 1, size_t(0.95 * double(traces.size())))]);
  // One pixel's terms (every group), capped, before the window.
  const auto terms = [&](int qx, int qy) {
    std::array<MseMatrix, 3> t;
    for (int g = 0; g < groups; ++g) t[size_t(g)] = MseMatrix::Zero(n, n);
    double cap = 1.0;
    if (o.outlierCap > 0) {
      cap = o.outlierCap / (traceAt(qx, qy) / unit + o.outlierCap);
    }
    for (int c = 0; c < 3; ++c) {
      const int g = groups == 3 ? c : 0;
      const double xA = f.guides.colorA(qx, qy, c), xB = f.guides.colorB(qx, qy, c);
      const double wA = cap * weightOf(qx, qy, c, &BaseOutputs::a);
      const double wB = cap * weightOf(qx, qy, c, &BaseOutputs::b);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const double yAi = f.bases[size_t(i)].a(qx, qy, c), yAj = f.bases[size_t(j)].a(qx, qy, c);
          const double yBi = f.bases[size_t(i)].b(qx, qy, c), yBj = f.bases[size_t(j)].b(qx, qy, c);
          // The paper's form with equal weights: ⟨M⟩^A = y^A y^Aᵀ − x^B (1 y^Aᵀ + y^A 1ᵀ) +
          // x^A x^B 11ᵀ, i.e. e^A e^Aᵀ minus the comparators' noise ½(x^A − x^B)²; each fold
          // weighted by its own w, the noise by their mean.
          const double eA = (yAi - xB) * (yAj - xB), eB = (yBi - xA) * (yBj - xA);
          t[size_t(g)](i, j) +=
              0.5 * (wA * eA + wB * eB) - 0.5 * (wA + wB) * 0.5 * (xA - xB) * (xA - xB);
        }
    }
    return t;
  };
  // Windows wider than 8 take a tap every third pixel, each the mean of the 3 × 3 box of terms
  // around it (clipped to the image).
  const int step = o.windowRadius > 8 ? 3 : 1;
  double kernelSum = 0;
  for (int qy = std::max(0, y - o.windowRadius); qy <= std::min(h - 1, y + o.windowRadius); ++qy)
    for (int qx = std::max(0, x - o.windowRadius); qx <= std::min(w - 1, x + o.windowRadius);
         ++qx) {
      if ((qx - x) % step != 0 || (qy - y) % step != 0) continue;
      const double k = windowWeight(f, o, color, x, y, qx, qy);
      kernelSum += k;
      const int b = step / 2;
      int boxPixels = 0;
      std::array<MseMatrix, 3> box;
      for (int g = 0; g < groups; ++g) box[size_t(g)] = MseMatrix::Zero(n, n);
      for (int by = std::max(0, qy - b); by <= std::min(h - 1, qy + b); ++by)
        for (int bx = std::max(0, qx - b); bx <= std::min(w - 1, qx + b); ++bx, ++boxPixels) {
          const std::array<MseMatrix, 3> t = terms(bx, by);
          for (int g = 0; g < groups; ++g) box[size_t(g)] += t[size_t(g)];
        }
      for (int g = 0; g < groups; ++g) out.h[size_t(g)] += k * box[size_t(g)] / boxPixels;
    }
  for (int g = 0; g < groups; ++g) out.h[size_t(g)] /= kernelSum;
  return out;
}

// ⟨M⟩ = h + c·11ᵀ as one matrix.
MseMatrix full(const PixelMse& m, int g) {
  return (m.h[size_t(g)].array() + m.constant[size_t(g)]).matrix();
}

TEST(MseEstimate, MatchesTheDefinition) {
  const Fixture f = makeFixture(19, 14, 1);
  for (MseForm form : {MseForm::PerChannel, MseForm::Summed})
    for (int radius : {0, 2, 10})
      for (bool relative : {false, true})
        for (double outlierCap : {0.0, 0.5}) {
          MseOptions o;
          o.form = form;
          o.windowRadius = radius;
          o.relative = relative;
          o.outlierCap = outlierCap;
          o.consistency = 0;  // a solver mask: it does not change the estimate
          o.imagePrior = 0;   // tested on its own (ImagePriorAddsTheScaledImageMean)
          const MseEstimator estimator(f.guides, pointers(f), o);
          for (int y = 0; y < 14; y += 3)
            for (int x = 0; x < 19; x += 2) {
              const PixelMse got = estimator.at(x, y), expected = naiveMse(f, o, x, y);
              ASSERT_EQ(got.groups, expected.groups);
              EXPECT_EQ(got.valid, 0b111u);
              for (int g = 0; g < got.groups; ++g) {
                const MseMatrix m = full(got, g);
                const double tolerance = 1e-5 * expected.h[size_t(g)].cwiseAbs().maxCoeff() + 1e-9;
                for (int i = 0; i < 3; ++i)
                  for (int j = 0; j < 3; ++j)
                    ASSERT_NEAR(m(i, j), expected.h[size_t(g)](i, j), tolerance)
                        << "form " << int(form) << " radius " << radius << " relative " << relative
                        << " outlierCap " << outlierCap << " pixel " << x << "," << y << " entry "
                        << i << j;
                // The solver's part h is positive semi-definite.
                const Eigen::MatrixXd h = got.h[size_t(g)];
                EXPECT_GE(
                    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(h).eigenvalues().minCoeff(),
                    -1e-6 * h.trace());
              }
            }
        }
}

// Image mean over pixels of ⟨M⟩ − T, per entry, with T the true error matrix of the runs the
// estimate judges, averaged over the same window (the windowed estimate is unbiased for the
// window's average error, not for the centre pixel's): for the halves
// ½((y^A − μ)(y^A − μ)ᵀ + (y^B − μ)(y^B − μ)ᵀ), for the quarters ¼ Σ_k (y^(−k) − μ)(y^(−k) − μ)ᵀ.
// Relative (o.relative): each fold's term divided by μ_f² + 0.01, μ_f the mean of that fold's
// runs over the bases, and the deviation taken up to a multiple of 11ᵀ (its mean over the
// entries subtracted): on {Σw = 1}, wᵀ(c·11ᵀ)w = c changes no weight, while any other term
// does. The common term itself is weighted by the folds' mean weight, which depends on every
// fold's runs, so it is not claimed unbiased.
std::vector<double> meanDeviation(const Fixture& f, const MseOptions& o) {
  const MseEstimator estimator(f.guides, pointers(f), o);
  const int n = 3, w = f.truth.width(), h = f.truth.height(), r = o.windowRadius;
  const WindowColor color = windowColorOf(f);
  std::vector<std::vector<const Image*>> runs(static_cast<size_t>(n));  // per base, runs judged
  for (int i = 0; i < n; ++i) {
    const BaseOutputs& b = f.bases[size_t(i)];
    if (o.estimate == MseEstimate::Quarters)
      for (const Image& run : b.heldOut) runs[size_t(i)].push_back(&run);
    else
      runs[size_t(i)] = {&b.a, &b.b};
  }
  const auto trueEntry = [&](int x, int y, int c, int i, int j) {
    const double mu = f.truth(x, y, c);
    double sum = 0;
    for (size_t k = 0; k < runs[size_t(i)].size(); ++k) {
      double level = 0;
      for (int b = 0; b < n; ++b) level += (*runs[size_t(b)][k])(x, y, c) / double(n);
      const double weight = o.relative ? 1.0 / (level * level + 0.01) : 1.0;
      sum += weight * ((*runs[size_t(i)][k])(x, y, c) - mu) * ((*runs[size_t(j)][k])(x, y, c) - mu);
    }
    return sum / double(runs[size_t(i)].size());
  };
  std::vector<double> sum(size_t(n * n), 0.0);
  const MseRows rows = estimator.rows(0, h);
  PixelMse m;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      rows.pixel(x, y, m);
      for (int c = 0; c < 3; ++c) {
        Eigen::Matrix3d deviation;
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j) {
            double truth = 0, kernelSum = 0;
            for (int qy = std::max(0, y - r); qy <= std::min(h - 1, y + r); ++qy)
              for (int qx = std::max(0, x - r); qx <= std::min(w - 1, x + r); ++qx) {
                const double k = windowWeight(f, o, color, x, y, qx, qy);
                truth += k * trueEntry(qx, qy, c, i, j);
                kernelSum += k;
              }
            deviation(i, j) = full(m, c)(i, j) - truth / kernelSum;
          }
        if (o.relative) deviation.array() -= deviation.mean();
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j) sum[size_t(i * n + j)] += deviation(i, j);
      }
    }
  for (double& v : sum) v /= double(w) * h * 3;
  return sum;
}

struct BiasCheck {
  double worstZ = 0;  // largest |mean| / standard error over the entries
};
BiasCheck biasOverSeeds(int radius, bool leaky, MseEstimate estimate = MseEstimate::Halves,
                        bool relative = false) {
  constexpr int kSeeds = 300;
  const bool quarters = estimate == MseEstimate::Quarters;
  MseOptions o;
  o.estimate = estimate;
  o.relative = relative;
  o.form = MseForm::PerChannel;
  o.windowRadius = radius;
  // The outlier cap weighs pixels by their own noisy terms, which trades a bias for robustness
  // to fireflies, and the image prior shrinks towards the image's mean: the plain estimator is
  // the unbiased one.
  o.outlierCap = 0;
  o.imagePrior = 0;
  std::vector<double> sum(9, 0.0), sumSq(9, 0.0);
  for (int s = 0; s < kSeeds; ++s) {
    Fixture f = makeFixture(16, 12, 1000 + uint64_t(s), 0.3f, quarters);
    if (leaky && quarters) {
      // The premise broken: each held-out run is the run on all four quarters, so it saw the
      // quarter it is compared with.
      for (BaseOutputs& b : f.bases)
        for (Image& run : b.heldOut) run = b.full;
    } else if (leaky) {
      // The estimator's premise broken: the "other half" is the same half, so x^B is not
      // independent of y^A. The test must notice.
      f.guides.colorB = f.guides.colorA;
      for (BaseOutputs& b : f.bases) b.b = b.a;
    }
    const std::vector<double> d = meanDeviation(f, o);
    for (size_t e = 0; e < 9; ++e) sum[e] += d[e], sumSq[e] += d[e] * d[e];
  }
  BiasCheck check;
  for (size_t e = 0; e < 9; ++e) {
    const double mean = sum[e] / kSeeds;
    const double variance = (sumSq[e] - kSeeds * mean * mean) / (kSeeds - 1);
    const double standardError = std::sqrt(variance / kSeeds);
    check.worstZ = std::max(check.worstZ, std::abs(mean) / standardError);
  }
  return check;
}

TEST(MseEstimate, UnbiasedForTheHalfBufferErrorMatrix) {
  // Per pixel and with a window: the mean over 300 noise seeds of every entry's deviation is
  // within 3 standard errors of 0.
  for (int radius : {0, 2}) EXPECT_LT(biasOverSeeds(radius, false).worstZ, 3.0) << radius;
  // Negative control: the same statistic detects the bias of a leaky estimator.
  EXPECT_GT(biasOverSeeds(0, true).worstZ, 10.0);
}

TEST(MseEstimate, LeaveOneQuarterOutIsUnbiasedForTheThreeQuarterRuns) {
  // ⟨M⟩ = H + c·11ᵀ from the held-out runs and quarters (c from the quarters' spread): the mean
  // over 300 seeds of its deviation from the held-out runs' true error matrix is within 3
  // standard errors of 0, per pixel and windowed.
  for (int radius : {0, 2})
    EXPECT_LT(biasOverSeeds(radius, false, MseEstimate::Quarters).worstZ, 3.0) << radius;
  // Negative control: held-out runs that saw their quarter.
  EXPECT_GT(biasOverSeeds(0, true, MseEstimate::Quarters).worstZ, 10.0);
}

// A quarter that is 0 everywhere has no samples (a render below 4 spp): its fold would judge
// every member by its output squared. Left out, the held-out runs compared with it no longer
// enter the estimate at all; a quarter with samples keeps its fold (the negative control).
TEST(MseEstimate, AnEmptyQuarterIsNoFold) {
  for (bool empty : {true, false}) {
    Fixture f = makeFixture(16, 12, 7, 0.3f, true);
    if (empty) f.guides.quarters[3].fill(0.0f);
    MseOptions o;
    o.estimate = MseEstimate::Quarters;
    o.windowSigmaColor = 0;  // the colour guide reads the full runs only, but keep it out
    const MseEstimator before(f.guides, pointers(f), o);
    const std::vector<PixelMse> was = [&] {
      std::vector<PixelMse> v;
      for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 16; ++x) v.push_back(before.at(x, y));
      return v;
    }();
    for (BaseOutputs& b : f.bases) b.heldOut[3] = scaled(b.heldOut[3], 5.0f);
    const MseEstimator after(f.guides, pointers(f), o);
    bool same = true;
    for (int y = 0; y < 12; ++y)
      for (int x = 0; x < 16; ++x) {
        const PixelMse now = after.at(x, y), then = was[size_t(y * 16 + x)];
        for (int g = 0; g < now.groups; ++g)
          same = same && now.h[size_t(g)] == then.h[size_t(g)] &&
                 now.constant[size_t(g)] == then.constant[size_t(g)];
      }
    EXPECT_EQ(same, empty) << (empty ? "empty quarter" : "sampled quarter");
  }
}

TEST(MseEstimate, RelativeTermsAreUnbiasedUpToTheCommonTerm) {
  // --relative and the image prior divide each fold's terms by its own runs' level (μ_f² + ε):
  // a weight that does not see the fold's comparator keeps the estimate unbiased for what the
  // solve sees. The level taken from the bases' blended outputs, as before 2026-12-06, saw
  // every quarter: against its own weighted truth this statistic read z = 9–12 (halves and
  // quarters, radius 0 and 2) for the same seeds.
  for (MseEstimate estimate : {MseEstimate::Halves, MseEstimate::Quarters})
    for (int radius : {0, 2})
      EXPECT_LT(biasOverSeeds(radius, false, estimate, true).worstZ, 3.0)
          << estimateName(estimate) << " " << radius;
  EXPECT_GT(biasOverSeeds(0, true, MseEstimate::Quarters, true).worstZ, 10.0);
}

// The blend's estimated MSE (the mseEstimate layer) from the half blends and from the held-out
// blends, for fixed weights and members with known errors: m1 = the mean of the samples,
// m2 = ½ m1 + ½ c (biased towards c). With w = (0.3, 0.7) the blend is
// (w1 + ½w2)·mean + ½w2·c, whose error is (½w2 (c − μ))² + (w1 + ½w2)² σ²_run, with σ²_run =
// σ_q²/2 for a half and σ_q²/3 for three quarters. The image mean of each estimate (64k
// i.i.d. pixels × 3 channels) is within 3 % of that value.
struct AnalyticBlend {
  static constexpr int kSide = 256;
  static constexpr double mu = 2.0, c = 3.0, sigmaQ = 0.8, w1 = 0.3, w2 = 0.7;
  static double of(double mean) { return w1 * mean + w2 * (0.5 * mean + 0.5 * c); }
  // The error of a blend of runs on `quarters` quarters.
  static double error(int quarters) {
    return std::pow(0.5 * w2 * (c - mu), 2) +
           std::pow(w1 + 0.5 * w2, 2) * sigmaQ * sigmaQ / double(quarters);
  }
  // Four quarters, the first `sampled` of them noisy around μ and the others empty (0).
  static std::vector<Image> quarters(int sampled, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, sigmaQ);
    std::vector<Image> out(4, Image(kSide, kSide, 3));
    for (int k = 0; k < sampled; ++k)
      for (float& v : out[size_t(k)].values()) v = float(mu + noise(rng));
    return out;
  }
  static double mean(const Image& image) {
    double sum = 0;
    for (float v : image.values()) sum += v;
    return sum / double(image.size());
  }
};

TEST(MseEstimate, BlendMseEstimatesMatchTheAnalyticError) {
  using B = AnalyticBlend;
  const int w = B::kSide, h = B::kSide;
  const std::vector<Image> quarters = B::quarters(4, 77);
  Image zA(w, h, 3), zB(w, h, 3), xA(w, h, 3), xB(w, h, 3);
  std::vector<Image> heldOut(4, Image(w, h, 3));
  for (size_t e = 0; e < zA.size(); ++e) {
    double x[4], sum = 0;
    for (size_t k = 0; k < 4; ++k) sum += x[k] = quarters[k].data()[e];
    xA.data()[e] = float(0.5 * (x[0] + x[1]));
    xB.data()[e] = float(0.5 * (x[2] + x[3]));
    zA.data()[e] = float(B::of(xA.data()[e]));
    zB.data()[e] = float(B::of(xB.data()[e]));
    for (size_t k = 0; k < 4; ++k) heldOut[k].data()[e] = float(B::of((sum - x[k]) / 3.0));
  }
  const double halfError = B::error(2), threeQuarterError = B::error(3);
  EXPECT_NEAR(B::mean(estimatedBlendMse(zA, zB, xA, xB)), halfError, 0.03 * halfError);
  EXPECT_NEAR(B::mean(heldOutBlendMse(heldOut, quarters)), threeQuarterError,
              0.03 * threeQuarterError);
  // The two differ by more than the tolerance, so each test tells them apart.
  EXPECT_GT(halfError - threeQuarterError, 0.1 * threeQuarterError);
}

// Below 4 spp a quarter holds no samples (all 0). With quarter 3 empty, the runs without
// quarters 0, 1 or 2 see two quarters (σ²_run = σ_q²/2), and the blend's estimated MSE is the
// mean of those three folds' errors, B::error(2) (0.258). Counting the empty fold as a
// comparator of 0 gave 0.597.
TEST(MseEstimate, HeldOutBlendMseLeavesAnEmptyQuarterOut) {
  using B = AnalyticBlend;
  const std::vector<Image> quarters = B::quarters(3, 78);
  std::vector<Image> heldOut(4, Image(B::kSide, B::kSide, 3));
  for (size_t e = 0; e < heldOut[0].size(); ++e) {
    double x[3], sum = 0;
    for (size_t k = 0; k < 3; ++k) sum += x[k] = quarters[k].data()[e];
    for (size_t k = 0; k < 3; ++k) heldOut[k].data()[e] = float(B::of((sum - x[k]) / 2.0));
    heldOut[3].data()[e] = float(B::of(sum / 3.0));
  }
  EXPECT_NEAR(B::mean(heldOutBlendMse(heldOut, quarters)), B::error(2), 0.03 * B::error(2));
}

// Where every member is non-finite in every run, the blends take the noisy counterparts of the
// runs: for the run without quarter k the mean of the other quarters that hold samples. With
// quarter 3 empty and the quarters 1, 2, 4 there, the held-out blends are 3, 2.5 and 1.5 (not
// 2, 5/3 and 1 with the empty quarter's 0 counted), and the blend's estimated MSE there is
// mean((3 − 1)², (2.5 − 2)², (1.5 − 4)²) − var(1, 2, 4) = 3.5 − 7/3 = 7/6.
TEST(MseEstimate, WhereNoMemberIsFiniteTheHeldOutBlendsMeanTheSampledQuarters) {
  Fixture f = makeFixture(16, 12, 9, 0.3f, true);
  f.guides.quarters[3].fill(0.0f);
  const float values[3] = {1.0f, 2.0f, 4.0f};
  for (size_t k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) f.guides.quarters[k](5, 4, c) = values[k];
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (BaseOutputs& b : f.bases) {
    b.a = Image();
    b.b = Image();
    for (Image& run : b.heldOut)
      for (int c = 0; c < 3; ++c) run(5, 4, c) = nan;
  }
  const CombineResult r = combine(f.guides, pointers(f), {});
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.mseEstimate(5, 4, c), 7.0 / 6.0, 1e-5) << c;
}

TEST(MseEstimate, OracleIsTheTrueErrorMatrix) {
  const Fixture f = makeFixture(10, 8, 3);
  MseOptions o;
  o.form = MseForm::PerChannel;
  o.windowRadius = 0;
  const MseEstimator oracle = MseEstimator::oracle(f.guides, pointers(f), f.truth, o);
  const PixelMse m = oracle.at(4, 5);
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double ei = f.bases[size_t(i)].full(4, 5, c) - f.truth(4, 5, c);
        const double ej = f.bases[size_t(j)].full(4, 5, c) - f.truth(4, 5, c);
        EXPECT_NEAR(full(m, c)(i, j), ei * ej, 1e-6 * (std::abs(ei * ej) + 1e-6));
      }
}

TEST(MseEstimate, NonFiniteOutputsAreExcluded) {
  Fixture f = makeFixture(12, 10, 4);
  f.bases[1].a(5, 5, 0) = std::numeric_limits<float>::quiet_NaN();
  f.bases[2].full(7, 2, 1) = std::numeric_limits<float>::infinity();
  f.guides.colorB(2, 8, 2) = std::numeric_limits<float>::quiet_NaN();
  for (int radius : {0, 2}) {
    MseOptions o;
    o.windowRadius = radius;
    o.outlierCap = 0;   // naiveMse's definition
    o.consistency = 0;  // only non-finite outputs make a base invalid here
    o.plausibility = 0;
    o.imagePrior = 0;  // naiveMse's definition
    const MseEstimator estimator(f.guides, pointers(f), o);
    EXPECT_EQ(estimator.at(5, 5).valid, 0b101u);
    EXPECT_EQ(estimator.at(7, 2).valid, 0b011u);
    EXPECT_EQ(estimator.at(6, 5).valid, 0b111u);
    const MseRows rows = estimator.rows(0, 10);
    PixelMse m;
    for (int y = 0; y < 10; ++y)
      for (int x = 0; x < 12; ++x) {
        rows.pixel(x, y, m);
        for (int g = 0; g < m.groups; ++g) {
          ASSERT_TRUE(m.h[size_t(g)].allFinite()) << x << "," << y;
          ASSERT_TRUE(std::isfinite(m.constant[size_t(g)]));
        }
      }
    // The valid bases' entries at a pixel with an invalid base are those of the definition
    // restricted to them (per pixel; with a window the pixel leaves its own window).
    if (radius == 0) {
      const PixelMse got = estimator.at(5, 5);
      Fixture clean = makeFixture(12, 10, 4);
      MseOptions summed;
      summed.windowRadius = 0;
      summed.outlierCap = 0;
      summed.imagePrior = 0;
      const PixelMse expected = naiveMse(clean, summed, 5, 5);
      EXPECT_NEAR(full(got, 0)(0, 2), expected.h[0](0, 2), 1e-5 * std::abs(expected.h[0](0, 2)));
    }
  }
}

// mean |x| over both noisy halves: the scale of the 10 % floors.
double meanAbsOfHalves(const Fixture& f) {
  double scale = 0;
  for (const Image* image : {&f.guides.colorA, &f.guides.colorB})
    for (float v : image->values()) scale += std::abs(v) / double(2 * image->size());
  return scale;
}

// With a mask test on (`on`) and off (`off`), the solver's mask is `mask` at (x0, y0) and all
// three bases elsewhere, and the estimate itself (which the neighbours' windows use) is the same.
void expectOnlyMaskChanges(const Fixture& f, const MseOptions& on, const MseOptions& off, int x0,
                           int y0, BaseMask mask) {
  const MseEstimator with(f.guides, pointers(f), on), without(f.guides, pointers(f), off);
  for (int y = 0; y < f.truth.height(); ++y)
    for (int x = 0; x < f.truth.width(); ++x) {
      EXPECT_EQ(with.at(x, y).valid, x == x0 && y == y0 ? mask : 0b111u) << x << "," << y;
      EXPECT_EQ(without.at(x, y).valid, 0b111u) << x << "," << y;
      EXPECT_EQ(with.at(x, y).h[0], without.at(x, y).h[0]) << x << "," << y;
    }
}

// A base whose full-buffer output strays from both of its half outputs (a firefly kept only in
// the full run) is left out of the solve at that pixel, and only there; the estimate itself,
// which the neighbours' windows use, is the same with and without the test.
TEST(MseEstimate, InconsistentFullRunIsLeftOutOfTheSolve) {
  Fixture f = makeFixture(12, 10, 5);
  for (int c = 0; c < 3; ++c) f.bases[1].full(4, 4, c) += 20.0f;  // halves: box blurs, ~1
  f.bases[2].full(8, 6, 0) += 0.05f;                              // within the allowance
  MseOptions on, off;
  on.windowRadius = off.windowRadius = 2;
  off.consistency = 0;
  expectOnlyMaskChanges(f, on, off, 4, 4, 0b101u);
  // When every base strays the test would leave nothing: all of them stay.
  for (BaseOutputs& b : f.bases) b.full(4, 4, 0) += 20.0f;
  EXPECT_EQ(MseEstimator(f.guides, pointers(f), on).at(4, 4).valid, 0b111u);
}

// A base far from both noisy halves at a pixel (a blob in all of its runs, which the
// consistency test cannot see) is left out of the solve there; the threshold is κ² times the
// least base's own term plus the halves' difference and a 10 % floor.
TEST(MseEstimate, ImplausibleBaseIsLeftOutOfTheSolve) {
  Fixture f = makeFixture(12, 10, 6);
  for (Image* image : {&f.bases[1].a, &f.bases[1].b, &f.bases[1].full})
    for (int c = 0; c < 3; ++c) (*image)(4, 4, c) += 20.0f;
  MseOptions on, off;
  on.windowRadius = off.windowRadius = 2;
  off.plausibility = 0;
  expectOnlyMaskChanges(f, on, off, 4, 4, 0b101u);

  // At (8, 6) put base 2 at a distance t from the other half in every channel of both halves
  // (d_2 = 3t²), just inside and just outside the limit computed here from the definition.
  const int x = 8, y = 6;
  const double scale = meanAbsOfHalves(f);
  auto term = [&](int i) {
    double d = 0;
    for (int c = 0; c < 3; ++c)
      d += 0.5 * (std::pow(f.bases[size_t(i)].a(x, y, c) - f.guides.colorB(x, y, c), 2) +
                  std::pow(f.bases[size_t(i)].b(x, y, c) - f.guides.colorA(x, y, c), 2));
    return d;
  };
  double allowance = 0;
  for (int c = 0; c < 3; ++c) {
    const double xA = f.guides.colorA(x, y, c), xB = f.guides.colorB(x, y, c);
    allowance += 0.5 * (xA - xB) * (xA - xB) + std::pow(0.1 * (scale + std::abs(xA + xB) / 2), 2);
  }
  const double limit = 16.0 * (std::min(term(0), term(1)) + allowance);
  for (double share : {0.99, 1.01}) {
    const double t = std::sqrt(share * limit / 3.0);
    for (int c = 0; c < 3; ++c) {
      f.bases[2].a(x, y, c) = float(f.guides.colorB(x, y, c) + t);
      f.bases[2].b(x, y, c) = float(f.guides.colorA(x, y, c) + t);
      f.bases[2].full(x, y, c) = 0.5f * (f.bases[2].a(x, y, c) + f.bases[2].b(x, y, c));
    }
    ASSERT_NEAR(term(2), share * limit, 1e-4 * limit);
    EXPECT_EQ(MseEstimator(f.guides, pointers(f), on).at(x, y).valid, share < 1 ? 0b111u : 0b011u)
        << share;
  }
  // Off or at least 1: a smaller factor could leave the least base out too.
  on.plausibility = 0.5;
  EXPECT_THROW(MseEstimator(f.guides, pointers(f), on), Error);
}

// Where half A holds a firefly, every base's B term (y^B − x^A)² is huge and hides, in the
// whole-pixel test, the base that passed the firefly through its A run; each half's own test
// (at 2κ, against the other half as comparator) leaves it out, at that pixel only.
TEST(MseEstimate, FireflyHalfRevealsTheBaseThatPassedItThrough) {
  Fixture f = makeFixture(12, 10, 9);
  for (int c = 0; c < 3; ++c) {
    f.guides.colorA(4, 4, c) += 40.0f;
    f.bases[1].a(4, 4, c) = f.guides.colorA(4, 4, c);
    f.bases[1].full(4, 4, c) = 0.5f * (f.bases[1].a(4, 4, c) + f.bases[1].b(4, 4, c));
  }
  MseOptions on, off;
  on.windowRadius = off.windowRadius = 2;
  off.plausibility = 0;
  expectOnlyMaskChanges(f, on, off, 4, 4, 0b101u);

  // At (8, 6), with a firefly in half A, put base 2's A run at a distance t from x^B in every
  // channel (tA_2 = 3t²), just inside and just outside (2κ)²·(least other tA + 10 % floor of x^B).
  const int x = 8, y = 6;
  for (int c = 0; c < 3; ++c) f.guides.colorA(x, y, c) += 40.0f;
  const double scale = meanAbsOfHalves(f);
  auto termA = [&](int i) {
    double t = 0;
    for (int c = 0; c < 3; ++c)
      t += std::pow(f.bases[size_t(i)].a(x, y, c) - f.guides.colorB(x, y, c), 2);
    return t;
  };
  double floorB = 0;
  for (int c = 0; c < 3; ++c)
    floorB += std::pow(0.1 * (scale + std::abs(f.guides.colorB(x, y, c))), 2);
  const double limit = 64.0 * (std::min(termA(0), termA(1)) + floorB);
  for (double share : {0.99, 1.01}) {
    const double t = std::sqrt(share * limit / 3.0);
    for (int c = 0; c < 3; ++c) {
      f.bases[2].a(x, y, c) = float(f.guides.colorB(x, y, c) + t);
      f.bases[2].full(x, y, c) = 0.5f * (f.bases[2].a(x, y, c) + f.bases[2].b(x, y, c));
    }
    ASSERT_NEAR(termA(2), share * limit, 1e-4 * limit);
    EXPECT_EQ(MseEstimator(f.guides, pointers(f), on).at(x, y).valid, share < 1 ? 0b111u : 0b011u)
        << share;
  }
}

// Where even the best base is far from both noisy halves (its own term d above K² times the
// halves' difference plus a 10 % floor), the pixel is flagged for the noisy fallback; the limit
// is computed here from the definition and checked just inside and just outside.
TEST(MseEstimate, NoBasePlausibleWhereEveryBaseIsFarFromBothHalves) {
  Fixture f = makeFixture(12, 10, 10);
  MseOptions defaults;
  defaults.noisyFallback = 10;  // off by default
  const int x = 5, y = 3, width = 12;
  {
    const MseEstimator estimator(f.guides, pointers(f), defaults);
    for (size_t p = 0; p < size_t(12 * 10); ++p) EXPECT_FALSE(estimator.noBasePlausible(p)) << p;
  }
  const double scale = meanAbsOfHalves(f);
  double allowance = 0;
  for (int c = 0; c < 3; ++c) {
    const double xA = f.guides.colorA(x, y, c), xB = f.guides.colorB(x, y, c);
    allowance += 0.5 * (xA - xB) * (xA - xB) + std::pow(0.1 * (scale + std::abs(xA + xB) / 2), 2);
  }
  const double limit = 100.0 * allowance;  // K = 10
  for (double share : {0.99, 1.01}) {
    // Base i at a distance (1 + i)·t from the other half in every channel of both halves:
    // the least d is base 0's, 3t².
    const double t = std::sqrt(share * limit / 3.0);
    for (int i = 0; i < 3; ++i)
      for (int c = 0; c < 3; ++c) {
        BaseOutputs& b = f.bases[size_t(i)];
        b.a(x, y, c) = float(f.guides.colorB(x, y, c) + (1 + i) * t);
        b.b(x, y, c) = float(f.guides.colorA(x, y, c) + (1 + i) * t);
        b.full(x, y, c) = 0.5f * (b.a(x, y, c) + b.b(x, y, c));
      }
    const MseEstimator estimator(f.guides, pointers(f), defaults);
    EXPECT_EQ(estimator.noBasePlausible(size_t(y * width + x)), share > 1) << share;
    MseOptions off;
    off.noisyFallback = 0;
    EXPECT_FALSE(MseEstimator(f.guides, pointers(f), off).noBasePlausible(size_t(y * width + x)));
  }
  MseOptions bad;
  bad.noisyFallback = 0.5;
  EXPECT_THROW(MseEstimator(f.guides, pointers(f), bad), Error);
}

// With the image prior, each pixel's H gains α·(τ(H)/τ(Ḡ))·Ḡ: Ḡ the mean over the image of the
// per-pixel terms divided by μ̂² + (mean |x| / 2)², τ the trace on the tangent space {Σv = 0}.
// The prior's mean is over every k-th row, k = ⌊h / 256⌋ (every row below 512 rows; the image
// at 6 × 1100 reads rows 0, 4, 8, …), the radiance scale over every pixel.
TEST(MseEstimate, ImagePriorAddsTheScaledImageMean) {
  for (const auto& [w, h] : {std::pair{14, 11}, std::pair{6, 1100}})
    for (double cap : {0.0, 0.5}) {
      const Fixture f = makeFixture(w, h, 8);
      const int n = 3, stride = std::max(1, h / 256);
      const double scale = meanAbsOfHalves(f);
      // Every stride-th row's relative terms: each fold relative to its own runs' level (the
      // mean over the bases of y^A, y^B), knee (mean |x| / 2)².
      std::vector<MseMatrix> terms;
      std::vector<double> traces;
      for (int y = 0; y < h; y += stride)
        for (int x = 0; x < w; ++x) {
          MseMatrix t = MseMatrix::Zero(n, n);
          for (int c = 0; c < 3; ++c) {
            const double weightA = foldWeight(f, &BaseOutputs::a, x, y, c, 0.25 * scale * scale);
            const double weightB = foldWeight(f, &BaseOutputs::b, x, y, c, 0.25 * scale * scale);
            const double xA = f.guides.colorA(x, y, c), xB = f.guides.colorB(x, y, c);
            for (int i = 0; i < n; ++i)
              for (int j = 0; j < n; ++j)
                t(i, j) += 0.5 * (weightA * (f.bases[size_t(i)].a(x, y, c) - xB) *
                                      (f.bases[size_t(j)].a(x, y, c) - xB) +
                                  weightB * (f.bases[size_t(i)].b(x, y, c) - xA) *
                                      (f.bases[size_t(j)].b(x, y, c) - xA));
          }
          terms.push_back(t);
          traces.push_back(t.trace());
        }
      // The outlier cap F / (trace / u + F), u the larger of 1 and the 95th percentile of the
      // traces of every fourth of these rows.
      std::vector<double> sorted;
      for (size_t p = 0; p < traces.size(); ++p)
        if ((p / size_t(w)) % 4 == 0) sorted.push_back(traces[p]);
      std::sort(sorted.begin(), sorted.end());
      const double unit = std::max(1.0, sorted[size_t(0.95 * double(sorted.size()))]);
      MseMatrix mean = MseMatrix::Zero(n, n);
      for (size_t p = 0; p < terms.size(); ++p)
        mean += (cap > 0 ? cap / (traces[p] / unit + cap) : 1.0) * terms[p] / double(terms.size());
      const auto tangentTrace = [&](const MseMatrix& m) { return m.trace() - m.sum() / n; };
      for (double alpha : {0.5, 4.0}) {
        MseOptions with, without;
        with.windowRadius = without.windowRadius = 2;
        with.outlierCap = without.outlierCap = cap;
        with.imagePrior = alpha;
        without.imagePrior = 0;
        const MseEstimator a(f.guides, pointers(f), with), b(f.guides, pointers(f), without);
        for (int y = 0; y<h; y += h> 100 ? 97 : 2)
          for (int x = 0; x < w; x += 3) {
            const MseMatrix local = b.at(x, y).h[0];
            const MseMatrix expected =
                local + alpha * tangentTrace(local) / tangentTrace(mean) * mean;
            const MseMatrix got = a.at(x, y).h[0];
            for (int i = 0; i < n; ++i)
              for (int j = 0; j < n; ++j)
                EXPECT_NEAR(got(i, j), expected(i, j), 1e-4 * expected.cwiseAbs().maxCoeff())
                    << w << "x" << h << ", cap " << cap << ", " << alpha << " at " << x << "," << y
                    << " entry " << i << "," << j;
          }
      }
    }
}

TEST(MseEstimate, ExtremeScales) {
  const Fixture f = makeFixture(9, 7, 5);
  MseOptions o;
  const PixelMse reference = MseEstimator(f.guides, pointers(f), o).at(4, 3);
  for (float factor : {1e-30f, 1e30f}) {
    Fixture g = f;
    for (Image* image : {&g.guides.color, &g.guides.colorA, &g.guides.colorB})
      for (float& v : image->values()) v *= factor;
    for (BaseOutputs& b : g.bases)
      for (Image* image : {&b.a, &b.b, &b.full})
        for (float& v : image->values()) v *= factor;
    const PixelMse m = MseEstimator(g.guides, pointers(g), o).at(4, 3);
    const double factor2 = double(factor) * factor;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        EXPECT_NEAR(m.h[0](i, j) / factor2, reference.h[0](i, j),
                    1e-4 * reference.h[0].cwiseAbs().maxCoeff());
  }
}

}  // namespace
}  // namespace chorus
