// Sampling warps: each pdf integrates to 1 over its domain, and samples follow the pdf (χ²
// against the pdf integrated over equal-area cells).
#include "renderer/sampling/warps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "tests/support/chi2.h"

namespace chorus::render {
namespace {

constexpr int kChi2Tests = 8;  // for the Šidák correction
const double kSignificance = test::sidakSignificance(0.01, kChi2Tests);
constexpr int kSamples = 400000;

float uniform(std::mt19937& rng) {
  return std::uniform_real_distribution<float>(0.0f, 1.0f)(rng);
}

// Sphere cells uniform in z = cos θ and φ (equal solid angle, dω = dz dφ).
constexpr int kZBins = 24, kPhiBins = 48, kSub = 10;

int sphereCell(Vec3f w) {
  const int zi = std::clamp(int((w.z + 1.0f) * 0.5f * kZBins), 0, kZBins - 1);
  float phi = std::atan2(w.y, w.x);
  if (phi < 0) phi += 2.0f * kPi;
  return zi * kPhiBins + std::clamp(int(phi / (2.0f * kPi) * kPhiBins), 0, kPhiBins - 1);
}

// ∫ pdf over each cell (midpoint rule on a kSub × kSub grid), times n; and the total integral.
std::vector<double> sphereExpected(const std::function<double(Vec3f)>& pdf, int n,
                                   double* integral) {
  std::vector<double> expected(kZBins * kPhiBins, 0.0);
  const double dz = 2.0 / (kZBins * kSub), dphi = 2.0 * M_PI / (kPhiBins * kSub);
  *integral = 0;
  for (int zi = 0; zi < kZBins; ++zi)
    for (int pi = 0; pi < kPhiBins; ++pi) {
      double sum = 0;
      for (int a = 0; a < kSub; ++a)
        for (int b = 0; b < kSub; ++b) {
          const double z = -1.0 + (zi * kSub + a + 0.5) * dz;
          const double phi = (pi * kSub + b + 0.5) * dphi;
          const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
          sum += pdf(Vec3f(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)));
        }
      expected[size_t(zi * kPhiBins + pi)] = n * sum * dz * dphi;
      *integral += sum * dz * dphi;
    }
  return expected;
}

void expectChi2(const std::string& name, const std::vector<double>& observed,
                const std::vector<double>& expected, int rows, int cols) {
  const test::Chi2Result result = test::chi2Test(observed, expected);
  std::printf("chi2 %-32s chi2 %8.1f dof %4d p %.4f\n", name.c_str(), result.chi2, result.dof,
              result.pValue);
  EXPECT_TRUE(result.problem.empty()) << name << ": " << result.problem;
  EXPECT_GT(result.pValue, kSignificance)
      << name << ": chi2 " << result.chi2 << " dof " << result.dof << "\n"
      << test::formatChi2Tables(observed, expected, rows, cols);
}

void checkSphereWarp(const std::string& name, const std::function<Vec3f(Vec2f)>& warp,
                     const std::function<double(Vec3f)>& pdf) {
  std::mt19937 rng(std::hash<std::string>{}(name));
  std::vector<double> observed(kZBins * kPhiBins, 0.0);
  for (int i = 0; i < kSamples; ++i) {
    const Vec3f w = warp({uniform(rng), uniform(rng)});
    ASSERT_NEAR(length(w), 1.0f, 1e-5f) << name;
    ASSERT_GT(pdf(w), 0.0) << name << ": sample where the pdf is 0";
    observed[size_t(sphereCell(w))] += 1;
  }
  double integral = 0;
  const std::vector<double> expected = sphereExpected(pdf, kSamples, &integral);
  EXPECT_NEAR(integral, 1.0, 2e-3) << name << ": pdf does not integrate to 1";
  expectChi2(name, observed, expected, kZBins, kPhiBins);
}

TEST(Warps, CosineHemisphere) {
  checkSphereWarp("cosine hemisphere", sampleCosineHemisphere,
                  [](Vec3f w) { return cosineHemispherePdfSolidAngle(w.z); });
  EXPECT_EQ(cosineHemispherePdfSolidAngle(-0.5f), 0.0f);
  EXPECT_FLOAT_EQ(cosineHemispherePdfSolidAngle(1.0f), 1.0f / kPi);
}

TEST(Warps, UniformSphere) {
  checkSphereWarp("uniform sphere", sampleUniformSphere,
                  [](Vec3f) { return double(kUniformSpherePdfSolidAngle); });
}

TEST(Warps, UniformCone) {
  for (float cosThetaMax : {0.95f, 0.5f, -0.3f}) {
    const float pdf = uniformConePdfSolidAngle(cosThetaMax);
    // The pdf times the cone's solid angle 2π(1 − cos θmax) is 1.
    EXPECT_NEAR(pdf * 2.0 * M_PI * (1.0 - cosThetaMax), 1.0, 1e-6);
    checkSphereWarp(
        "cone cos " + std::to_string(cosThetaMax),
        [&](Vec2f u) { return sampleUniformCone(u, cosThetaMax); },
        [&](Vec3f w) { return w.z >= cosThetaMax ? double(pdf) : 0.0; });
  }
  // The boundary of [0,1)² maps onto the cone's axis and rim.
  EXPECT_NEAR(sampleUniformCone({0.0f, 0.3f}, 0.7f).z, 1.0f, 1e-6f);
  EXPECT_NEAR(sampleUniformCone({1.0f, 0.3f}, 0.7f).z, 0.7f, 1e-6f);
}

// Disk cells uniform in r² and φ have equal area: each expects n / cells.
TEST(Warps, ConcentricDiskIsUniform) {
  const int rBins = 16, phiBins = 32;
  std::mt19937 rng(21);
  std::vector<double> observed(size_t(rBins * phiBins), 0.0);
  for (int i = 0; i < kSamples; ++i) {
    const Vec2f d = sampleConcentricDisk({uniform(rng), uniform(rng)});
    const float r2 = d.x * d.x + d.y * d.y;
    ASSERT_LE(r2, 1.0f + 1e-6f);
    float phi = std::atan2(d.y, d.x);
    if (phi < 0) phi += 2.0f * kPi;
    const int ri = std::clamp(int(r2 * rBins), 0, rBins - 1);
    const int pi = std::clamp(int(phi / (2.0f * kPi) * phiBins), 0, phiBins - 1);
    observed[size_t(ri * phiBins + pi)] += 1;
  }
  const std::vector<double> expected(observed.size(), double(kSamples) / (rBins * phiBins));
  expectChi2("concentric disk", observed, expected, rBins, phiBins);
  // The centre of the square maps to the centre of the disk, the edges to the rim.
  const Vec2f centre = sampleConcentricDisk({0.5f, 0.5f});
  EXPECT_EQ(centre.x, 0.0f);
  EXPECT_EQ(centre.y, 0.0f);
  const Vec2f rim = sampleConcentricDisk({1.0f, 0.7f});
  EXPECT_NEAR(rim.x * rim.x + rim.y * rim.y, 1.0f, 1e-5f);
}

// The mapping itself equals Shirley & Chiu's formula with library sin/cos in double precision
// (the implementation evaluates them by series) to float rounding.
TEST(Warps, ConcentricDiskMatchesTheTextbookMap) {
  std::mt19937 rng(22);
  double worst = 0;
  for (int i = 0; i < 200000; ++i) {
    const Vec2f u{uniform(rng), uniform(rng)};
    const double ox = 2.0 * u.x - 1.0, oy = 2.0 * u.y - 1.0;
    const bool xMajor = std::abs(ox) > std::abs(oy);
    const double r = xMajor ? ox : oy;
    const double theta = xMajor ? M_PI / 4 * (oy / ox) : M_PI / 2 - M_PI / 4 * (ox / oy);
    const Vec2f d = sampleConcentricDisk(u);
    worst =
        std::max({worst, std::abs(d.x - r * std::cos(theta)), std::abs(d.y - r * std::sin(theta))});
  }
  EXPECT_LT(worst, 3e-7);
}

// Barycentrics (b0, b1) of uniform points on a triangle are uniform on {b0, b1 ≥ 0, b0 + b1 ≤ 1}:
// grid cells inside it expect n · 2 · area, cells cut by the diagonal half as much.
TEST(Warps, TriangleIsUniform) {
  const int k = 20;
  std::mt19937 rng(22);
  std::vector<double> observed(size_t(k * k), 0.0), expected(size_t(k * k), 0.0);
  for (int i = 0; i < kSamples; ++i) {
    const Vec2f b = sampleUniformTriangle({uniform(rng), uniform(rng)});
    ASSERT_GE(b.x, 0.0f);
    ASSERT_GE(b.y, 0.0f);
    ASSERT_LE(b.x + b.y, 1.0f + 1e-6f);
    const int ix = std::min(int(b.x * k), k - 1), iy = std::min(int(b.y * k), k - 1);
    observed[size_t(iy * k + ix)] += 1;
  }
  for (int iy = 0; iy < k; ++iy)
    for (int ix = 0; ix < k; ++ix) {
      const double area = ix + iy + 2 <= k ? 1.0 : (ix + iy + 1 == k ? 0.5 : 0.0);
      expected[size_t(iy * k + ix)] = kSamples * 2.0 * area / (k * k);
    }
  expectChi2("triangle barycentrics", observed, expected, k, k);
  // The corners of the square land on the triangle's vertices.
  const Vec2f origin = sampleUniformTriangle({0.0f, 0.0f});
  EXPECT_EQ(origin.x, 0.0f);
  EXPECT_EQ(origin.y, 0.0f);
}

}  // namespace
}  // namespace chorus::render
