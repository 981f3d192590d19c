// Two-buffer variance helpers (buffer_variance.h) against direct computations.
#include "denoise/base/buffer_variance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tests/support/test_support.h"

namespace chorus {
namespace {

TEST(BufferVariance, SquaredDifferenceAndFiniteness) {
  Image a(2, 1, 1), b(2, 1, 1);
  a(0, 0, 0) = 3.0f;
  b(0, 0, 0) = 1.0f;
  a(1, 0, 0) = std::numeric_limits<float>::quiet_NaN();
  const Image d = squaredDifference(a, b, 0.25f);
  EXPECT_FLOAT_EQ(d(0, 0, 0), 1.0f);  // (3 − 1)² / 4
  EXPECT_EQ(d(1, 0, 0), 0.0f);
}

TEST(BufferVariance, CompletedVarianceFillsOnlyUnmeasuredPixels) {
  Image sample(5, 1, 1), twoBuffer(5, 1, 1);
  const float values[5][2] = {{0.5f, 0.1f},    // measured: kept
                              {0.0f, 0.0f},    // noise-free: kept
                              {0.0f, 0.3f},    // 0 while the buffers differ: not measured
                              {NAN, 0.2f},     // missing
                              {-1.0f, 0.4f}};  // invalid
  for (int x = 0; x < 5; ++x) {
    sample(x, 0, 0) = values[x][0];
    twoBuffer(x, 0, 0) = values[x][1];
  }
  const Image v = completedVariance(sample, twoBuffer);
  const float expected[5] = {0.5f, 0.0f, 0.3f, 0.2f, 0.4f};
  for (int x = 0; x < 5; ++x) EXPECT_FLOAT_EQ(v(x, 0, 0), expected[x]) << x;
}

// V = σ² Box(v_buf) / Box(σ²), against a naive clipped box in double precision.
TEST(BufferVariance, RescaledVarianceMatchesNaiveBoxes) {
  const Image sample = test::randomImage(13, 9, 3, 1, 0.1f, 2.0f);
  const Image twoBuffer = test::randomImage(13, 9, 3, 2, 0.0f, 3.0f);
  const int r = 2;
  const Image v = rescaledVariance(sample, twoBuffer, r);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 13; ++x)
      for (int c = 0; c < 3; ++c) {
        double s = 0, b = 0;
        int n = 0;
        for (int qy = std::max(0, y - r); qy <= std::min(8, y + r); ++qy)
          for (int qx = std::max(0, x - r); qx <= std::min(12, x + r); ++qx) {
            s += sample(qx, qy, c);
            b += twoBuffer(qx, qy, c);
            ++n;
          }
        const double expected = sample(x, y, c) * (b / n) / (1e-10 + s / n);
        EXPECT_NEAR(v(x, y, c), expected, 1e-5 * expected) << x << "," << y << "," << c;
      }
}

TEST(BufferVariance, RescaledVarianceLeavesMaskedPixelsOut) {
  Image sample(3, 1, 1, 1.0f), twoBuffer(3, 1, 1, 2.0f);
  twoBuffer(2, 0, 0) = 100.0f;
  const std::vector<uint8_t> mask = {1, 1, 0};
  const Image v = rescaledVariance(sample, twoBuffer, 1, &mask);
  EXPECT_FLOAT_EQ(v(0, 0, 0), 2.0f);
  EXPECT_FLOAT_EQ(v(1, 0, 0), 2.0f);  // the masked 100 does not enter
  EXPECT_EQ(v(2, 0, 0), 0.0f);
}

TEST(BufferVariance, Smooth3TapWeightsAndBorders) {
  Image image(3, 1, 1);
  image(0, 0, 0) = 1.0f;
  image(1, 0, 0) = 2.0f;
  image(2, 0, 0) = 4.0f;
  const float w = std::exp(-2.0f);
  const Image s = smooth3Tap(image, w);
  EXPECT_NEAR(s(0, 0, 0), (1.0f + w * 2.0f) / (1.0f + w), 1e-6f);
  EXPECT_NEAR(s(1, 0, 0), (2.0f + w * (1.0f + 4.0f)) / (1.0f + 2.0f * w), 1e-6f);
  EXPECT_NEAR(s(2, 0, 0), (4.0f + w * 2.0f) / (1.0f + w), 1e-6f);
  const std::vector<uint8_t> mask = {1, 1, 0};
  EXPECT_NEAR(smooth3Tap(image, w, &mask)(1, 0, 0), (2.0f + w * 1.0f) / (1.0f + w), 1e-6f);
}

// On a ramp f = a x + b y the squared gradient is (a/2)² + (b/2)² inside, one axis on an edge.
TEST(BufferVariance, SquaredGradientOfARamp) {
  Image ramp(5, 4, 1);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x) ramp(x, y, 0) = 0.3f * x - 0.2f * y;
  const Image g = squaredGradient(ramp);
  EXPECT_NEAR(g(2, 1, 0), 0.15f * 0.15f + 0.1f * 0.1f, 1e-6f);
  EXPECT_NEAR(g(0, 1, 0), 0.1f * 0.1f, 1e-6f);  // no horizontal neighbour pair on the border
  EXPECT_NEAR(g(2, 0, 0), 0.15f * 0.15f, 1e-6f);
  EXPECT_EQ(g(0, 0, 0), 0.0f);
  // A step: the smaller half-difference is 0, so the gradient does not see the edge.
  Image step(3, 1, 1);
  step(2, 0, 0) = 1.0f;
  EXPECT_EQ(squaredGradient(step)(1, 0, 0), 0.0f);
}

}  // namespace
}  // namespace chorus
