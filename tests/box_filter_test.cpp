// The true-count box filter against a direct double-precision average over the clipped box.
#include <gtest/gtest.h>

#include <algorithm>

#include "denoise/base/filters/box_filter.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

TEST(BoxFilter, MatchesClippedAverageForSmallAndLargeRadii) {
  const Image image = test::randomImage(23, 17, 2, 7, -1.0f, 3.0f);
  for (int radius : {0, 1, 3, 4, 5, 10, 30}) {
    const Image out = boxFilter(image, radius);
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x)
        for (int c = 0; c < 2; ++c) {
          double sum = 0;
          int count = 0;
          for (int j = std::max(0, y - radius); j <= std::min(image.height() - 1, y + radius); ++j)
            for (int i = std::max(0, x - radius); i <= std::min(image.width() - 1, x + radius);
                 ++i) {
              sum += image(i, j, c);
              ++count;
            }
          ASSERT_NEAR(out(x, y, c), sum / count, 2e-6)
              << "radius " << radius << " at (" << x << "," << y << ")";
        }
  }
}

TEST(BoxFilter, KeepsAConstantExactly) {
  const Image image(9, 40, 1, 0.3f);
  for (int radius : {1, 2, 7}) {
    const Image out = boxFilter(image, radius);
    for (float v : out.values()) EXPECT_NEAR(v, 0.3f, 1e-7f);
  }
}

}  // namespace
}  // namespace chorus
