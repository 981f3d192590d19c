// fastExpNonPositive / fastExpNegated against std::exp, their special values, and agreement of
// the SIMD lanes with the scalar form.
#include "denoise/util/fast_exp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace chorus {
namespace {

TEST(FastExp, RelativeErrorAgainstStdExp) {
  std::vector<float> e;
  for (int i = 0; i <= 200000; ++i) e.push_back(87.0f * float(i) / 200000.0f);
  std::vector<float> out(e.size());
  fastExpNegated(e.data(), out.data(), int(e.size()));
  for (size_t i = 0; i < e.size(); ++i) {
    const double exact = std::exp(-double(e[i]));
    const double tolerance = e[i] <= 10.0f ? 1e-6 : 5e-6;
    ASSERT_LE(std::abs(out[i] - exact), tolerance * exact) << "exp(-" << e[i] << ")";
    ASSERT_EQ(out[i], fastExpNonPositive(-e[i])) << "lane and scalar differ at " << e[i];
  }
}

// The degree-4 polynomial (à-trous's weights): 3.5e-6 from the interpolant on top of the
// float evaluation; the SSE lanes compute exactly the scalar form.
TEST(FastExp, DegreeFourRelativeError) {
  for (int i = 0; i <= 200000; i += 4) {
    float e[4], lanes[4];
    for (int k = 0; k < 4; ++k) e[k] = 87.0f * float(i + k) / 200000.0f;
#if defined(__SSE2__)
    _mm_storeu_ps(lanes, fastExpNegatedSse<4>(_mm_loadu_ps(e)));
#else
    for (int k = 0; k < 4; ++k) lanes[k] = fastExpNonPositive<4>(-e[k]);
#endif
    for (int k = 0; k < 4; ++k) {
      const double exact = std::exp(-double(e[k])), value = fastExpNonPositive<4>(-e[k]);
      const double tolerance = e[k] <= 10.0f ? 5e-6 : 1e-5;
      ASSERT_LE(std::abs(value - exact), tolerance * exact) << "exp(-" << e[k] << ")";
      ASSERT_EQ(lanes[k], value) << "lane and scalar differ at " << e[k];
    }
  }
  EXPECT_EQ(fastExpNonPositive<4>(0.0f), 1.0f);  // the centre tap's weight stays exact
}

TEST(FastExp, SpecialValues) {
  const float nan = std::numeric_limits<float>::quiet_NaN(),
              inf = std::numeric_limits<float>::infinity();
  const std::vector<float> e = {0.0f, -0.0f, -5.0f, inf, -inf, nan, 200.0f, 1e-30f, 88.5f};
  std::vector<float> out(e.size());
  fastExpNegated(e.data(), out.data(), int(e.size()));
  const std::vector<float> expected = {1, 1, 1, 0, 1, 0, 0, 1, 0};
  for (size_t i = 0; i < e.size(); ++i) {
    EXPECT_EQ(out[i], expected[i]) << "exp(-" << e[i] << ")";
    EXPECT_EQ(fastExpNonPositive(-e[i]), expected[i]) << "exp(-" << e[i] << ")";
  }
}

}  // namespace
}  // namespace chorus
