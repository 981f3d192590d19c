// Metrics against values computed by hand from their definitions (see metrics.h).
#include <gtest/gtest.h>

#include "common/error.h"
#include "denoise/metrics/metrics.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

Image pixel(std::initializer_list<float> values) {
  Image image(1, 1, int(values.size()));
  int c = 0;
  for (float v : values) image(0, 0, c++) = v;
  return image;
}

TEST(Metrics, MseOfThreeValues) {
  // ((1−1)² + (2−1)² + (3−1)²) / 3 = 5/3
  EXPECT_DOUBLE_EQ(mse(pixel({1, 2, 3}), pixel({1, 1, 1})), 5.0 / 3.0);
}

TEST(Metrics, RelMseUsesEpsilonOneHundredth) {
  // (2−1)²/(1+0.01) and (0.1−0)²/(0+0.01) = 1, averaged: 0.9950495…
  EXPECT_NEAR(relMse(pixel({2, 0.1f}), pixel({1, 0})), 0.995049504950495, 1e-7);
}

TEST(Metrics, RelMseInvariances) {
  const Image x = test::randomImage(8, 8, 3, 1, 0.0f, 4.0f);
  const Image r = test::randomImage(8, 8, 3, 2, 0.0f, 4.0f);
  const double base = relMse(x, r, 0.01);
  // Scaling image and reference by s with ε scaled by s² leaves relMSE unchanged.
  Image xs = x, rs = r;
  for (float& v : xs.values()) v *= 8.0f;
  for (float& v : rs.values()) v *= 8.0f;
  EXPECT_NEAR(relMse(xs, rs, 0.01 * 64), base, 1e-12 * base + 1e-15);
  // Permuting pixels consistently in both leaves it unchanged.
  Image xp(8, 8, 3), rp(8, 8, 3);
  for (int y = 0; y < 8; ++y)
    for (int xx = 0; xx < 8; ++xx)
      for (int c = 0; c < 3; ++c) {
        xp(7 - xx, y, c) = x(xx, y, c);
        rp(7 - xx, y, c) = r(xx, y, c);
      }
  EXPECT_NEAR(relMse(xp, rp), base, 1e-12);
  EXPECT_EQ(relMse(r, r), 0.0);
}

TEST(Metrics, PsnrOfKnownMse) {
  // MSE 0.01 → 10 log10(1/0.01) = 20 dB.
  EXPECT_NEAR(psnr(pixel({0.1f}), pixel({0.0f})), 20.0, 1e-5);
  EXPECT_TRUE(std::isinf(psnr(pixel({0.3f}), pixel({0.3f}))));
}

TEST(Metrics, SmapeOfOnePair) {
  // |1 − 3| / (1 + 3 + 0.01)
  EXPECT_NEAR(smape(pixel({1}), pixel({3})), 0.49875311720698257, 1e-9);
}

TEST(Metrics, SsimIsOneOnIdenticalImages) {
  const Image x = test::randomImage(40, 23, 3, 5, 0.0f, 2.0f);
  EXPECT_NEAR(ssim(x, x), 1.0, 1e-12);
  EXPECT_NEAR(dssim(x, x), 0.0, 1e-12);
}

TEST(Metrics, SsimOfConstantOffset) {
  // Constant images a = 0.25, b = 0.5: display values t = v^(1/2.2) are 0.53252054 and
  // 0.72974005; σ = 0 so SSIM = (2 ta tb + C1) / (ta² + tb² + C1) = 0.95234551.
  const Image a(30, 20, 3, 0.25f), b(30, 20, 3, 0.5f);
  EXPECT_NEAR(ssim(a, b), 0.9523455066003682, 1e-6);
  EXPECT_NEAR(dssim(a, b), (1 - 0.9523455066003682) / 2, 1e-6);
  // Tiny images (smaller than the window) still give the same constant-image value.
  EXPECT_NEAR(ssim(Image(3, 2, 3, 0.25f), Image(3, 2, 3, 0.5f)), 0.9523455066003682, 1e-6);
}

TEST(Metrics, SsimDropsWithNoise) {
  const Image x = test::randomImage(32, 32, 3, 6, 0.2f, 0.8f);
  Image noisy = x;
  const Image noise = test::randomImage(32, 32, 3, 7, -0.2f, 0.2f);
  for (size_t i = 0; i < noisy.size(); ++i) noisy.data()[i] += noise.data()[i];
  EXPECT_LT(ssim(noisy, x), 0.95);
  EXPECT_GT(ssim(noisy, x), 0.0);
}

TEST(Metrics, MismatchedShapesAreErrors) {
  EXPECT_THROW(mse(Image(2, 2, 3), Image(2, 3, 3)), Error);
  EXPECT_THROW(computeMetrics(Image(2, 2, 3), Image(2, 2, 1)), Error);
}

}  // namespace
}  // namespace chorus
