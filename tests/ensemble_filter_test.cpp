// The joint-bilateral filter core (planar_filter) against a naive per-pixel implementation in
// double with std::exp, its independence of tiling and thread count, and the weight filter's
// renormalisation onto the simplex.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "denoise/ensemble/planar_filter.h"
#include "denoise/ensemble/weight_filter.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

std::vector<float> randomPlanes(int w, int h, int count, uint32_t seed, float lo, float hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(lo, hi);
  std::vector<float> v(size_t(w) * size_t(h) * size_t(count));
  for (float& x : v) x = dist(rng);
  return v;
}

// Guides with regions (so that the range terms matter) plus noise.
PlanarGuides randomGuides(int w, int h, uint32_t seed, bool color) {
  PlanarGuides g;
  g.width = w;
  g.height = h;
  g.normal = randomPlanes(w, h, 3, seed, -0.1f, 0.1f);
  g.albedo = randomPlanes(w, h, 3, seed + 1, 0.0f, 0.1f);
  const size_t pixels = size_t(w) * size_t(h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if ((x / 9 + y / 7) % 2) {
        g.normal[size_t(y) * size_t(w) + size_t(x)] += 0.8f;
        g.albedo[pixels + size_t(y) * size_t(w) + size_t(x)] += 0.5f;
      }
  if (color) {
    g.color = randomPlanes(w, h, 3, seed + 2, 0.0f, 2.0f);
    g.variance = randomPlanes(w, h, 3, seed + 3, 0.0f, 0.5f);
  }
  return g;
}

// The definition, one pixel at a time, in double.
std::vector<double> naiveFilter(const PlanarGuides& g, const BilateralKernel& k,
                                const std::vector<float>& planes, int count) {
  const int w = g.width, h = g.height;
  const size_t pixels = size_t(w) * size_t(h);
  std::vector<double> out(pixels * size_t(count));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t p = size_t(y) * size_t(w) + size_t(x);
      std::vector<double> sum(size_t(count), 0.0);
      double weight = 0;
      for (int qy = std::max(0, y - k.radius); qy <= std::min(h - 1, y + k.radius); ++qy)
        for (int qx = std::max(0, x - k.radius); qx <= std::min(w - 1, x + k.radius); ++qx) {
          // A sparse kernel's taps: offsets that are multiples of its step.
          if ((qx - x) % k.step != 0 || (qy - y) % k.step != 0) continue;
          const size_t q = size_t(qy) * size_t(w) + size_t(qx);
          double d = k.kSpatial * ((qx - x) * (qx - x) + (qy - y) * (qy - y));
          for (int c = 0; c < 3; ++c) {
            const size_t o = size_t(c) * pixels;
            d += k.kNormal * std::pow(double(g.normal[o + p]) - g.normal[o + q], 2);
            d += k.kAlbedo * std::pow(double(g.albedo[o + p]) - g.albedo[o + q], 2);
            if (k.kColor > 0)
              d += k.kColor * std::pow(double(g.color[o + p]) - g.color[o + q], 2) /
                   (double(g.variance[o + p]) + g.variance[o + q] + 1e-6);
          }
          const double kernel = std::exp(-d);
          weight += kernel;
          for (int j = 0; j < count; ++j) sum[size_t(j)] += kernel * planes[size_t(j) * pixels + q];
        }
      for (int j = 0; j < count; ++j) out[size_t(j) * pixels + p] = sum[size_t(j)] / weight;
    }
  return out;
}

std::vector<float> filterAll(const PlanarGuides& g, const BilateralKernel& k,
                             const std::vector<float>& planes, int count, int band) {
  const size_t pixels = size_t(g.width) * size_t(g.height);
  std::vector<float> out(pixels * size_t(count));
  std::vector<const float*> in;
  for (int j = 0; j < count; ++j) in.push_back(planes.data() + size_t(j) * pixels);
  for (int y0 = 0; y0 < g.height; y0 += band) {
    const int y1 = std::min(g.height, y0 + band);
    std::vector<float*> rows;
    for (int j = 0; j < count; ++j)
      rows.push_back(out.data() + size_t(j) * pixels + size_t(y0) * size_t(g.width));
    filterPlaneRows(g, k, in, 0, y0, y1, rows);
  }
  return out;
}

TEST(PlanarFilter, MatchesNaiveBilateral) {
  // 300 pixels wide: three column blocks of the implementation; bands of 5 rows.
  const int w = 300, h = 23;
  // {radius, step}: dense, and sparse with the radius a multiple of the step or not.
  const std::pair<int, int> shapes[] = {{0, 1}, {1, 1}, {3, 1}, {7, 1}, {9, 3}, {10, 3}, {7, 2}};
  for (bool color : {false, true})
    for (const auto& [radius, step] : shapes) {
      const PlanarGuides g = randomGuides(w, h, 31 + uint32_t(radius), color);
      BilateralKernel k;
      k.radius = radius;
      k.step = step;
      k.kSpatial = 0.5f / 9.0f;
      k.kNormal = 5.0f;
      k.kAlbedo = 8.0f;
      k.kColor = color ? 0.125f : 0.0f;
      const int count = 3;
      const std::vector<float> planes = randomPlanes(w, h, count, 41, -1.0f, 3.0f);
      const std::vector<double> expected = naiveFilter(g, k, planes, count);
      const std::vector<float> got = filterAll(g, k, planes, count, 5);
      for (size_t e = 0; e < expected.size(); ++e)
        ASSERT_NEAR(got[e], expected[e], 2e-5 * (1 + std::abs(expected[e])))
            << "radius " << radius << " step " << step << " color " << color << " element " << e;
    }
}

TEST(PlanarFilter, IndependentOfBandsAndInputWindow) {
  const int w = 150, h = 40;
  const PlanarGuides g = randomGuides(w, h, 51, true);
  BilateralKernel k;
  k.radius = 5;
  k.kSpatial = 0.05f;
  k.kNormal = 3.0f;
  k.kAlbedo = 2.0f;
  k.kColor = 0.2f;
  const std::vector<float> planes = randomPlanes(w, h, 2, 52, 0.0f, 1.0f);
  const std::vector<float> whole = filterAll(g, k, planes, 2, h);
  for (int band : {1, 3, 16}) EXPECT_EQ(filterAll(g, k, planes, 2, band), whole) << "band " << band;
  // Rows 10..20 from inputs that hold only rows 5..25 (the radius around them).
  const size_t pixels = size_t(w) * size_t(h);
  std::vector<std::vector<float>> partial(2);
  std::vector<const float*> in;
  std::vector<std::vector<float>> outRows(2, std::vector<float>(size_t(10) * size_t(w)));
  std::vector<float*> out;
  for (int j = 0; j < 2; ++j) {
    partial[size_t(j)].assign(planes.begin() + std::ptrdiff_t(size_t(j) * pixels + 5 * size_t(w)),
                              planes.begin() + std::ptrdiff_t(size_t(j) * pixels + 25 * size_t(w)));
    in.push_back(partial[size_t(j)].data());
    out.push_back(outRows[size_t(j)].data());
  }
  filterPlaneRows(g, k, in, 5, 10, 20, out);
  for (int j = 0; j < 2; ++j)
    for (size_t e = 0; e < size_t(10) * size_t(w); ++e)
      ASSERT_EQ(outRows[size_t(j)][e], whole[size_t(j) * pixels + 10 * size_t(w) + e]);
}

// The accumulation in sixteen-lane vectors (AVX-512 CPUs) and in eight (the others) adds the
// same terms in the same order: the same bits, whichever this CPU would pick.
TEST(PlanarFilter, BothAccumulationWidthsGiveTheSameBits) {
  const int w = 300, h = 23;
  const PlanarGuides g = randomGuides(w, h, 57, true);
  BilateralKernel k;
  k.radius = 5;
  k.kSpatial = 0.5f / 9.0f;
  k.kNormal = 5.0f;
  k.kAlbedo = 8.0f;
  k.kColor = 0.125f;
  const int count = 11;  // a group of eight planes, then two and one
  const std::vector<float> planes = randomPlanes(w, h, count, 43, -1.0f, 3.0f);
  k.width = BilateralKernel::Width::Sixteen;
  const std::vector<float> sixteen = filterAll(g, k, planes, count, 7);
  k.width = BilateralKernel::Width::Eight;
  const std::vector<float> eight = filterAll(g, k, planes, count, 7);
  ASSERT_EQ(sixteen.size(), eight.size());
  for (size_t e = 0; e < sixteen.size(); ++e) ASSERT_EQ(sixteen[e], eight[e]) << e;
  const std::vector<double> expected = naiveFilter(g, k, planes, count);
  for (size_t e = 0; e < expected.size(); ++e)
    ASSERT_NEAR(eight[e], expected[e], 2e-5 * (1 + std::abs(expected[e]))) << e;
}

TEST(WeightFilter, ConstantMapsStayConstantAndOnTheSimplex) {
  const int w = 40, h = 30;
  const Image normal = test::randomImage(w, h, 3, 61, -1, 1),
              albedo = test::randomImage(w, h, 3, 62);
  const Image blend = test::randomImage(w, h, 3, 63, 0, 5),
              blendA = test::randomImage(w, h, 3, 64, 0, 5),
              blendB = test::randomImage(w, h, 3, 65, 0, 5);
  const ColorGuide guide = makeColorGuide(blend, blendA, blendB, {});
  std::vector<Image> weights = {Image(w, h, 3, 0.2f), Image(w, h, 3, 0.3f), Image(w, h, 3, 0.5f)};
  const std::vector<Image> filtered = crossBilateralFilter(weights, guide, normal, albedo, {});
  for (size_t i = 0; i < 3; ++i)
    for (float v : filtered[i].values()) ASSERT_NEAR(v, weights[i].values()[0], 1e-6);
}

TEST(WeightFilter, RenormalisesOntoTheSimplexAndDropsInvalidBases) {
  const int w = 8, h = 6;
  std::vector<Image> weights = {test::randomImage(w, h, 1, 71, -0.2f, 1.0f),
                                test::randomImage(w, h, 1, 72, 0.0f, 1.0f),
                                test::randomImage(w, h, 1, 73, 0.0f, 1.0f)};
  weights[1](3, 2, 0) = std::numeric_limits<float>::quiet_NaN();
  std::vector<BaseMask> valid(size_t(w * h), 0b111);
  valid[5] = 0b101;  // base 1 is invalid at pixel 5
  std::vector<Image> fallback(3, Image(w, h, 1, 1.0f / 3));
  fallback[0].fill(1.0f);
  fallback[1].fill(0.0f);
  fallback[2].fill(0.0f);
  const std::vector<Image> zeros(3, Image(w, h, 1, 0.0f));
  const std::vector<Image> out = renormalizeWeights(weights, valid, fallback, true);
  for (int p = 0; p < w * h; ++p) {
    double sum = 0;
    for (int i = 0; i < 3; ++i) {
      const float v = out[size_t(i)].data()[p];
      ASSERT_TRUE(std::isfinite(v));
      ASSERT_GE(v, 0.0f);
      sum += v;
    }
    EXPECT_NEAR(sum, 1.0, 1e-6);
  }
  EXPECT_EQ(out[1].data()[5], 0.0f);
  EXPECT_EQ(out[1](3, 2, 0), 0.0f);
  // Nothing left: the fallback weights.
  const std::vector<Image> empty = renormalizeWeights(zeros, valid, fallback, true);
  EXPECT_EQ(empty[0](1, 1, 0), 1.0f);
  EXPECT_EQ(empty[1](1, 1, 0), 0.0f);
}

TEST(WeightFilter, EdgesInTheGuidesStopTheSmoothing) {
  // Two halves with albedo 0 and 1 and weights (1,0) / (0,1): without the albedo term the
  // filter mixes them near the edge, with it (σ_a = 0.5: weight e^-6 across) they stay apart.
  const int w = 30, h = 10;
  Image albedo(w, h, 3), normal(w, h, 3, 0.0f);
  std::vector<Image> weights = {Image(w, h, 1), Image(w, h, 1)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool left = x < w / 2;
      for (int c = 0; c < 3; ++c) albedo(x, y, c) = left ? 0.0f : 1.0f;
      weights[0](x, y, 0) = left ? 1.0f : 0.0f;
      weights[1](x, y, 0) = left ? 0.0f : 1.0f;
    }
  const Image flat(w, h, 3, 1.0f);
  const ColorGuide guide = makeColorGuide(flat, flat, flat, {});
  const std::vector<Image> guided = crossBilateralFilter(weights, guide, normal, albedo, {});
  WeightFilterOptions blind;
  blind.sigmaAlbedo = 1e6f;
  const std::vector<Image> unguided = crossBilateralFilter(weights, guide, normal, albedo, blind);
  EXPECT_GT(guided[0](w / 2 - 1, 5, 0), 0.98f);
  EXPECT_LT(unguided[0](w / 2 - 1, 5, 0), 0.8f);
}

TEST(WeightFilter, ColorGuideIsScaleInvariant) {
  const int w = 12, h = 9;
  const Image z = test::randomImage(w, h, 3, 81, 0, 4), zA = test::randomImage(w, h, 3, 82, 0, 4),
              zB = test::randomImage(w, h, 3, 83, 0, 4);
  const ColorGuide reference = makeColorGuide(z, zA, zB, {});
  for (float factor : {1e-30f, 1e30f}) {
    Image sz = z, szA = zA, szB = zB;
    for (Image* image : {&sz, &szA, &szB})
      for (float& v : image->values()) v *= factor;
    const ColorGuide scaled = makeColorGuide(sz, szA, szB, {});
    for (size_t e = 0; e < z.size(); ++e) {
      EXPECT_NEAR(scaled.color.data()[e], reference.color.data()[e],
                  1e-5 * reference.color.data()[e]);
      EXPECT_NEAR(scaled.variance.data()[e], reference.variance.data()[e],
                  1e-4 * reference.variance.data()[e] + 1e-12);
    }
  }
}

// One pixel of half variance in a constant blend: the guide's variance is that impulse blurred
// by the 9 × 9 Gaussian (σ 1.7) whose taps are renormalised where they leave the image, written
// here from the definition, at a corner, an edge and in the interior.
TEST(WeightFilter, ColorGuideBlursTheHalfVarianceWithRenormalisedBorders) {
  const int w = 13, h = 11;
  const WeightFilterOptions options;  // radius 4, σ 1.7, no relative tolerance
  const double sigma = options.varianceBlurSigma;
  const int r = options.varianceBlurRadius;
  const auto tap = [&](int d) { return std::exp(-0.5 * d * d / (sigma * sigma)); };
  // The weight of position i of n: the taps whose neighbour is inside.
  const auto norm = [&](int i, int n) {
    double sum = 0;
    for (int d = -r; d <= r; ++d)
      if (i + d >= 0 && i + d < n) sum += tap(d);
    return sum;
  };
  for (const auto& [x0, y0] : {std::pair{0, 0}, std::pair{6, 0}, std::pair{6, 5}}) {
    Image z(w, h, 3, 1.0f), a(w, h, 3, 1.0f), b(w, h, 3, 1.0f);
    a(x0, y0, 1) = 3.0f;  // ½(a − b)² = 2 in channel 1 at (x0, y0); the blend's mean |z| is 1
    const ColorGuide guide = makeColorGuide(z, a, b, options);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const bool near = std::abs(x - x0) <= r && std::abs(y - y0) <= r;
        const double expected =
            near ? 2.0 * tap(x - x0) / norm(x, w) * tap(y - y0) / norm(y, h) : 0.0;
        EXPECT_NEAR(guide.variance(x, y, 1), expected, 1e-6 * (1 + expected)) << x << "," << y;
        EXPECT_EQ(guide.variance(x, y, 0), 0.0f);
      }
  }
}

// Four quarter means x_k = μ + noise (σ_q = 1 per channel, i.i.d. pixels) and a linear blend
// (the identity member): z^A, z^B are the half means, z^(−k) the means without quarter k.
// Both guides estimate a half's variance, σ_q²/2, divided by s² = μ² (s = mean |z| ≈ μ).
// Averaged over the image, each is within 2 % of that analytic value (64k pixels × 3 channels:
// a standard error of about 0.4 %; the blur only averages neighbours).
TEST(WeightFilter, HeldOutGuideHasTheExpectationOfTheHalvesGuide) {
  const int w = 256, h = 256;
  const float mu = 10.0f;
  std::mt19937 rng(2026);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  std::vector<Image> quarters(4, Image(w, h, 3));
  for (Image& q : quarters)
    for (float& v : q.values()) v = mu + noise(rng);
  Image full(w, h, 3), a(w, h, 3), b(w, h, 3);
  std::vector<Image> heldOut(4, Image(w, h, 3));
  for (size_t e = 0; e < full.size(); ++e) {
    const float x[4] = {quarters[0].data()[e], quarters[1].data()[e], quarters[2].data()[e],
                        quarters[3].data()[e]};
    const float sum = x[0] + x[1] + x[2] + x[3];
    full.data()[e] = 0.25f * sum;
    a.data()[e] = 0.5f * (x[0] + x[1]);
    b.data()[e] = 0.5f * (x[2] + x[3]);
    for (size_t k = 0; k < 4; ++k) heldOut[k].data()[e] = (sum - x[k]) / 3.0f;
  }
  const double expected = 0.5 / (double(mu) * mu);
  const auto meanVariance = [](const ColorGuide& guide) {
    double sum = 0;
    for (float v : guide.variance.values()) sum += v;
    return sum / double(guide.variance.size());
  };
  EXPECT_NEAR(meanVariance(makeColorGuide(full, a, b, {})), expected, 0.02 * expected);
  EXPECT_NEAR(meanVariance(makeColorGuide(full, heldOut, {})), expected, 0.02 * expected);
  // Negative control: the spread of the held-out blends alone (without the factor 1.5) is
  // 2/3 of it.
  std::vector<Image> shrunk = heldOut;
  for (size_t k = 0; k < 4; ++k)
    for (size_t e = 0; e < full.size(); ++e)
      shrunk[k].data()[e] =
          full.data()[e] + std::sqrt(2.0f / 3.0f) * (heldOut[k].data()[e] - full.data()[e]);
  EXPECT_LT(meanVariance(makeColorGuide(full, shrunk, {})), 0.8 * expected);
}

TEST(WeightFilter, SameResultForAnyThreadCount) {
  const int w = 70, h = 50;
  const Image normal = test::randomImage(w, h, 3, 91, -1, 1),
              albedo = test::randomImage(w, h, 3, 92);
  const Image z = test::randomImage(w, h, 3, 93, 0, 5);
  const ColorGuide guide = makeColorGuide(z, test::randomImage(w, h, 3, 94, 0, 5),
                                          test::randomImage(w, h, 3, 95, 0, 5), {});
  const std::vector<Image> weights = {test::randomImage(w, h, 3, 96),
                                      test::randomImage(w, h, 3, 97)};
  std::vector<Image> one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = crossBilateralFilter(weights, guide, normal, albedo, {});
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = crossBilateralFilter(weights, guide, normal, albedo, {});
  }
  for (size_t i = 0; i < weights.size(); ++i)
    EXPECT_TRUE(
        std::equal(one[i].values().begin(), one[i].values().end(), two[i].values().begin()));
}

}  // namespace
}  // namespace chorus
