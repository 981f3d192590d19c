// The Owen-scrambled Sobol sampler: stratification within a pixel, uniformity, independence of
// sub-buffers, and the faster-than-Monte-Carlo convergence that motivates it.
#include "renderer/sampling/sampler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <set>
#include <vector>

namespace chorus::render {
namespace {

std::vector<Vec2f> pixelPoints(Sampler& sampler, int px, int py, int subBuffer, int count,
                               int callsBefore) {
  std::vector<Vec2f> points;
  for (int i = 0; i < count; ++i) {
    sampler.startPixelSample(px, py, uint32_t(i), subBuffer);
    for (int c = 0; c < callsBefore; ++c) {
      if (c % 2 == 0)
        sampler.get1D();
      else
        sampler.get2D();
    }
    points.push_back(callsBefore == 0 ? sampler.getPixel2D() : sampler.get2D());
  }
  return points;
}

// Every elementary interval of area 1/n (2^a × 2^(m−a) cells) holds exactly one of n = 2^m points.
void expectElementaryIntervals(const std::vector<Vec2f>& points, int log2n) {
  const int n = 1 << log2n;
  for (int a = 0; a <= log2n; ++a) {
    const int cellsX = 1 << a, cellsY = n / cellsX;
    std::vector<int> counts(size_t(n), 0);
    for (const Vec2f& p : points) {
      const int cx = int(p.x * float(cellsX)), cy = int(p.y * float(cellsY));
      ASSERT_LT(cx, cellsX);
      ASSERT_LT(cy, cellsY);
      ++counts[size_t(cy * cellsX + cx)];
    }
    for (int c = 0; c < n; ++c)
      ASSERT_EQ(counts[size_t(c)], 1)
          << "n = " << n << ", intervals " << cellsX << "x" << cellsY << ", cell " << c;
  }
}

TEST(Sampler, PixelPointsAreA02Net) {
  Sampler sampler(7);
  for (int log2n = 0; log2n <= 10; ++log2n)
    for (int subBuffer = 0; subBuffer < 4; ++subBuffer)
      expectElementaryIntervals(pixelPoints(sampler, 13, 5, subBuffer, 1 << log2n, 0), log2n);
}

TEST(Sampler, LaterDimensionsAreStratifiedToo) {
  Sampler sampler(11);
  for (int callsBefore : {1, 2, 5, 12})
    for (int log2n : {4, 8})
      expectElementaryIntervals(pixelPoints(sampler, 3, 9, 1, 1 << log2n, callsBefore), log2n);
}

TEST(Sampler, OneDimensionalValuesAreStratified) {
  // n = 2^m values of one get1D() call hit each interval [k/n, (k+1)/n) once.
  Sampler sampler(3);
  const int n = 256;
  for (int callsBefore : {0, 3}) {
    std::set<int> cells;
    for (int i = 0; i < n; ++i) {
      sampler.startPixelSample(4, 4, uint32_t(i), 2);
      for (int c = 0; c < callsBefore; ++c) sampler.get2D();
      cells.insert(int(sampler.get1D() * float(n)));
    }
    EXPECT_EQ(int(cells.size()), n);
  }
}

TEST(Sampler, DeterministicAndSeedDependent) {
  Sampler a(42), b(42), c(43);
  for (uint32_t i = 0; i < 64; ++i) {
    a.startPixelSample(10, 20, i, 3);
    b.startPixelSample(10, 20, i, 3);
    c.startPixelSample(10, 20, i, 3);
    for (int d = 0; d < 6; ++d) {
      const float va = a.get1D(), vb = b.get1D(), vc = c.get1D();
      EXPECT_EQ(va, vb);
      EXPECT_NE(va, vc) << "index " << i << " dimension " << d;
      EXPECT_GE(va, 0.0f);
      EXPECT_LT(va, 1.0f);
    }
  }
}

// The first sample of every pixel, over many pixels, is uniform on [0,1)² (χ² on a 16×16 grid)
// for the pixel dimensions and for a later pair: scrambles are random per pixel.
// A draw depends only on (seed, pixel, sub-buffer, sample index, dimension): not on which
// pixels, sub-buffers or dimensions were drawn before, nor on whether a dimension was skipped
// (reserve) or first drawn as 1D, and not on how far past the cached dimensions it lies.
TEST(Sampler, DrawsDoNotDependOnHistory) {
  const auto fresh1D = [](int px, int py, uint32_t index, int k, uint32_t dimension) {
    Sampler s(7);
    s.startPixelSample(px, py, index, k);
    return s.get1DAt(dimension);
  };
  const auto fresh2D = [](int px, int py, uint32_t index, int k, uint32_t dimension) {
    Sampler s(7);
    s.startPixelSample(px, py, index, k);
    return s.get2DAt(dimension);
  };
  Sampler shared(7);
  for (int round = 0; round < 3; ++round) {
    for (int pixel = 0; pixel < 3; ++pixel) {
      for (uint32_t i = 0; i < 4; ++i) {
        for (int k : {3, 2, 1, 0, 5}) {          // 5 shares a cache slot with 1
          const int px = 5 + pixel % 2, py = 9;  // pixels alternate: 5, 6, 5
          shared.startPixelSample(px, py, i, k);
          for (uint32_t d : {uint32_t(round), 63u - uint32_t(round), 70u + uint32_t(round)}) {
            EXPECT_EQ(shared.get1DAt(d), fresh1D(px, py, i, k, d));
            const Vec2f a = shared.get2DAt(d), b = fresh2D(px, py, i, k, d);
            EXPECT_EQ(a.x, b.x);
            EXPECT_EQ(a.y, b.y);
          }
          const uint32_t d = shared.reserve(5);
          EXPECT_EQ(d, 0u);
          EXPECT_EQ(shared.get1D(), fresh1D(px, py, i, k, 5));
        }
      }
    }
  }
}

// getBounce is the five separate draws of a vertex, bit for bit, whichever of them were drawn
// before, for cached and uncached dimensions alike (first = 60 straddles the cache's end).
TEST(Sampler, BounceDrawsEqualTheSeparateDraws) {
  Sampler batched(11), separate(11);
  for (int pixel = 0; pixel < 40; ++pixel) {
    for (uint32_t i = 0; i < 3; ++i) {
      for (int k = 0; k < 4; ++k) {
        batched.startPixelSample(pixel % 7, pixel / 7, i, k);
        separate.startPixelSample(pixel % 7, pixel / 7, i, k);
        for (uint32_t first : {2u, 9u, 16u, 60u, 100u}) {
          if (pixel % 3 == 0) batched.get1DAt(first + 3);  // a cached seed or not beforehand
          const Sampler::BounceDraws d = batched.getBounce(first);
          const Vec2f direction = separate.get2DAt(first + 1),
                      lightPoint = separate.get2DAt(first + 4);
          ASSERT_EQ(d.lobe, separate.get1DAt(first));
          ASSERT_EQ(d.direction.x, direction.x);
          ASSERT_EQ(d.direction.y, direction.y);
          ASSERT_EQ(d.light, separate.get1DAt(first + 3));
          ASSERT_EQ(d.lightPoint.x, lightPoint.x);
          ASSERT_EQ(d.lightPoint.y, lightPoint.y);
          ASSERT_EQ(d.roulette, separate.get1DAt(first + 6));
        }
      }
    }
  }
}

TEST(Sampler, FirstSamplesAreUniformAcrossPixels) {
  Sampler sampler(5);
  const int grid = 16, pixels = 256 * 64;
  for (int callsBefore : {0, 4}) {
    std::vector<int> counts(grid * grid, 0);
    for (int p = 0; p < pixels; ++p) {
      sampler.startPixelSample(p % 256, p / 256, 0, 0);
      for (int c = 0; c < callsBefore; ++c) sampler.get1D();
      const Vec2f u = sampler.get2D();
      ++counts[size_t(int(u.y * grid) * grid + int(u.x * grid))];
    }
    const double expected = double(pixels) / (grid * grid);
    double chi2 = 0;
    for (int c : counts) chi2 += (c - expected) * (c - expected) / expected;
    // 255 degrees of freedom: mean 255, sd 22.6; 360 is p ≈ 1e-5.
    EXPECT_LT(chi2, 360.0) << "callsBefore " << callsBefore;
  }
}

// Pearson correlation.
double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = double(a.size());
  double ma = 0, mb = 0;
  for (size_t i = 0; i < a.size(); ++i) ma += a[i] / n, mb += b[i] / n;
  double sab = 0, saa = 0, sbb = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

// A smooth integrand over four dimensions (pixel position, then a second pair), with exact
// integral ∫ x·y + exp(−(z + w)) / 4 = 1/4 + (1 − e⁻¹)² / 4.
double smoothIntegrand(Vec2f p, Vec2f q) {
  return double(p.x) * p.y + 0.25 * std::exp(-double(q.x) - q.y);
}
const double kSmoothIntegral = 0.25 + 0.25 * (1 - std::exp(-1.0)) * (1 - std::exp(-1.0));

double pixelEstimate(Sampler& sampler, int px, int py, int subBuffer, int first, int count) {
  double sum = 0;
  for (int k = 0; k < count; ++k) {
    sampler.startPixelSample(px, py, uint32_t(first + k), subBuffer);
    const Vec2f p = sampler.getPixel2D();
    const Vec2f q = sampler.get2D();
    sum += smoothIntegrand(p, q);
  }
  return sum / count;
}

TEST(Sampler, SubBuffersAreIndependent) {
  Sampler sampler(2021);
  const int pixels = 4096, spp = 16;
  std::vector<double> error0, error1, errorFirst, errorSecond;
  for (int p = 0; p < pixels; ++p) {
    const int px = p % 64, py = p / 64;
    error0.push_back(pixelEstimate(sampler, px, py, 0, 0, spp) - kSmoothIntegral);
    error1.push_back(pixelEstimate(sampler, px, py, 1, 0, spp) - kSmoothIntegral);
    // The wrong way, as a control: the first and second halves of one 2·spp sequence.
    errorFirst.push_back(pixelEstimate(sampler, px, py, 0, 0, spp) - kSmoothIntegral);
    errorSecond.push_back(pixelEstimate(sampler, px, py, 0, spp, spp) - kSmoothIntegral);
  }
  // With 4096 independent pairs the sample correlation has sd 1/64 ≈ 0.016.
  const double rho = correlation(error0, error1);
  EXPECT_LT(std::abs(rho), 0.06) << "sub-buffers 0 and 1 correlate: " << rho;
  // The control proves the check can fail: halves of one (0,2)-sequence fill each other's strata.
  const double rhoSplit = correlation(errorFirst, errorSecond);
  EXPECT_LT(rhoSplit, -0.3) << "halves of one sequence: " << rhoSplit;
  std::printf("correlation of sub-buffer errors %.4f; of the halves of one sequence %.4f\n", rho,
              rhoSplit);
}

// Root-mean-square error, over many independently scrambled pixels, of an n-sample estimate.
double rmsError(Sampler& sampler, int n, const std::function<double(Sampler&)>& sampleValue,
                double exact) {
  const int pixels = 512;
  double sumSquares = 0;
  for (int p = 0; p < pixels; ++p) {
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      sampler.startPixelSample(p, 0, uint32_t(i), 0);
      sum += sampleValue(sampler);
    }
    const double error = sum / n - exact;
    sumSquares += error * error;
  }
  return std::sqrt(sumSquares / pixels);
}

// Least-squares slope of log(rmse) against log(n).
double convergenceSlope(const std::function<double(Sampler&)>& sampleValue, double exact) {
  Sampler sampler(99);
  std::vector<double> logN, logE;
  for (int n = 4; n <= 1024; n *= 4) {
    logN.push_back(std::log(double(n)));
    logE.push_back(std::log(rmsError(sampler, n, sampleValue, exact)));
  }
  double mx = 0, my = 0;
  for (size_t i = 0; i < logN.size(); ++i) mx += logN[i], my += logE[i];
  mx /= double(logN.size()), my /= double(logN.size());
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < logN.size(); ++i) {
    sxy += (logN[i] - mx) * (logE[i] - my);
    sxx += (logN[i] - mx) * (logN[i] - mx);
  }
  return sxy / sxx;
}

// Owen-scrambled nets give O(n^-1.5) RMSE on smooth integrands (Owen 1997); plain Monte Carlo
// gives n^-0.5. Require clearly better than Monte Carlo.
TEST(Sampler, SmoothIntegralConvergesFasterThanMonteCarlo) {
  // ∫∫ exp(−x) cos(y) = (1 − e⁻¹) sin 1 over the pixel dimensions.
  const double exact2D = (1 - std::exp(-1.0)) * std::sin(1.0);
  const double slopePixel = convergenceSlope(
      [](Sampler& s) {
        const Vec2f u = s.getPixel2D();
        return std::exp(-double(u.x)) * std::cos(double(u.y));
      },
      exact2D);
  EXPECT_LT(slopePixel, -1.0) << "pixel dimensions";
  // The same integrand on a later, padded pair of dimensions.
  const double slopePadded = convergenceSlope(
      [](Sampler& s) {
        s.getPixel2D();
        s.get1D();
        const Vec2f u = s.get2D();
        return std::exp(-double(u.x)) * std::cos(double(u.y));
      },
      exact2D);
  EXPECT_LT(slopePadded, -1.0) << "padded dimensions";
  // A 1D integral on a get1D() dimension: ∫ x² = 1/3.
  const double slope1D = convergenceSlope(
      [](Sampler& s) {
        s.getPixel2D();
        const double x = s.get1D();
        return x * x;
      },
      1.0 / 3.0);
  EXPECT_LT(slope1D, -1.0) << "1D dimension";
  std::printf("RMSE slopes: pixel pair %.3f, padded pair %.3f, 1D %.3f\n", slopePixel, slopePadded,
              slope1D);
}

}  // namespace
}  // namespace chorus::render
