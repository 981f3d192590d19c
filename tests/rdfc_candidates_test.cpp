// RDFC's candidate filters (rdfc_candidates.h): the derivative against re-runs with a perturbed
// input, SURE against the true error under Gaussian noise, and the selection in clear cases.
#include "denoise/base/rdfc/rdfc_candidates.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "denoise/base/buffer_variance.h"
#include "denoise/base/rdfc/rdfc.h"
#include "tests/support/gaussian_buffers.h"
#include "tests/support/synthetic_scene.h"

namespace chorus {
namespace {

test::SyntheticScene smallScene(int size, uint32_t seed = 1) {
  test::SyntheticSceneOptions o;
  o.width = o.height = size;
  o.seed = seed;
  return test::makeSyntheticScene(o);
}

// ∂F_c/∂y_c at pixels inside, on the border and in a corner, against a central difference of
// two complete re-runs with y_c(p) moved by ±0.5 % (both buffers moved, so y moves).
TEST(RdfcCandidates, DerivativeMatchesCentralDifferenceOfReruns) {
  const test::SyntheticScene scene = smallScene(24);
  const DenoiseInput input = scene.fullInput();
  const Image& b1 = (*input.halves)[0].color.mean;
  const Image& b2 = (*input.halves)[1].color.mean;
  const Image variance = squaredDifference(b1, b2, 0.25f);
  const std::vector<RdfcFeature> features = prefilterRdfcFeatures(input, {});
  RdfcCandidateParams params;
  params.r = 6;
  params.derivativeFallback = false;
  const auto base = rdfcCandidates(b1, b2, variance, features, params);
  int compared = 0;
  for (const auto& [x, y] :
       {std::pair{12, 12}, std::pair{0, 0}, std::pair{23, 9}, std::pair{5, 0}, std::pair{15, 17}})
    for (int c = 0; c < 3; ++c) {
      Image up1 = b1, up2 = b2, down1 = b1, down2 = b2;
      for (Image* im : {&up1, &up2}) (*im)(x, y, c) *= 1.005f;
      for (Image* im : {&down1, &down2}) (*im)(x, y, c) *= 0.995f;
      const auto up = rdfcCandidates(up1, up2, variance, features, params);
      const auto down = rdfcCandidates(down1, down2, variance, features, params);
      const double dy = 0.5 * (double(up1(x, y, c)) + up2(x, y, c)) -
                        0.5 * (double(down1(x, y, c)) + down2(x, y, c));
      for (int s = 0; s < 3; ++s) {
        const double numeric = (double(up[s].mean(x, y, c)) - down[s].mean(x, y, c)) / dy;
        EXPECT_NEAR(base[s].derivative(x, y, c), numeric, 2e-3)
            << "candidate " << s << " at (" << x << ", " << y << ") channel " << c;
        ++compared;
      }
    }
  EXPECT_EQ(compared, 45);
}

// Mean over seeds of (mean SURE − true MSE) per candidate, in units of its standard error.
std::array<double, 3> sureBiasInStandardErrors(bool fallback, float relativeSigma, int seeds) {
  const test::SyntheticScene scene = smallScene(32);
  Image sigma = scene.truth;
  for (float& v : sigma.values()) v = relativeSigma * (0.2f + v);
  const std::vector<RdfcFeature> features = prefilterRdfcFeatures(scene.fullInput(), {});
  RdfcCandidateParams params;
  params.derivativeFallback = fallback;
  std::array<double, 3> sum{}, sumSq{};
  for (int seed = 0; seed < seeds; ++seed) {
    const DenoiseInput input =
        test::gaussianHalves(scene.truth, sigma, scene.fullInput().whole, 100 + seed);
    Image variance = sigma;
    for (float& v : variance.values()) v *= v;
    const auto cands = rdfcCandidates((*input.halves)[0].color.mean, (*input.halves)[1].color.mean,
                                      variance, features, params);
    for (int s = 0; s < 3; ++s) {
      double sure = 0, mse = 0;
      for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
          sure += cands[s].sure(x, y, 0);
          for (int c = 0; c < 3; ++c) {
            const double d = cands[s].mean(x, y, c) - scene.truth(x, y, c);
            mse += d * d / 3.0;
          }
        }
      const double diff = (sure - mse) / (32.0 * 32.0);
      sum[s] += diff;
      sumSq[s] += diff * diff;
    }
  }
  std::array<double, 3> z{};
  for (int s = 0; s < 3; ++s) {
    const double mean = sum[s] / seeds;
    const double sd = std::sqrt(std::max(0.0, sumSq[s] / seeds - mean * mean));
    z[s] = mean / (sd / std::sqrt(double(seeds - 1)));
  }
  return z;
}

TEST(RdfcCandidates, SureMatchesTrueMseUnderGaussianNoise) {
  const std::array<double, 3> z = sureBiasInStandardErrors(false, 0.15f, 24);
  for (int s = 0; s < 3; ++s) {
    std::cout << "candidate " << s << ": (SURE − MSE) / SE = " << z[s] << "\n";
    EXPECT_LT(std::abs(z[s]), 3.0) << "candidate " << s;
  }
}

// With the release's derivative fallback, THIRD (exact anyway) and SECOND stay unbiased.
TEST(RdfcCandidates, SureWithFallbackStaysWithinThreeStandardErrors) {
  const std::array<double, 3> z = sureBiasInStandardErrors(true, 0.15f, 24);
  for (int s = 0; s < 3; ++s) std::cout << "candidate " << s << ": z = " << z[s] << "\n";
  EXPECT_LT(std::abs(z[1]), 3.0);
  EXPECT_LT(std::abs(z[2]), 3.0);
}

// Constant features everywhere and a colour step (a shadow edge no feature sees): THIRD, which
// only looks at features, averages across the step; the colour candidates do not. Far from the
// step FIRST's small patches make the noisiest weights.
TEST(RdfcCandidates, SelectionPicksTheCandidateWithTheLowerTrueError) {
  const int w = 48, h = 24;
  Image truth(w, h, 3), sigma(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        truth(x, y, c) = x < w / 2 ? 0.2f : 1.0f;
        sigma(x, y, c) = 0.03f;
      }
  const DenoiseInput input = test::gaussianHalves(truth, sigma, test::flatFeatures(w, h, 8.0f), 7);
  RdfcParams params;
  params.rescaleVariance = false;  // independent noise: σ² is the variance
  const RdfcResult result = runRdfc(input, params);

  auto error = [&](const Image& image, int x, int y) {
    double e = 0;
    for (int c = 0; c < 3; ++c) e += std::pow(image(x, y, c) - truth(x, y, c), 2.0);
    return e;
  };
  int nearStep = 0, nearNotThird = 0, far = 0, farThird = 0, farFirst = 0;
  double nearThirdError = 0, nearSecondError = 0, farThirdError = 0, farSecondError = 0,
         farFirstError = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int distance = x < w / 2 ? w / 2 - 1 - x : x - w / 2;
      const int chosen = int(result.selection(x, y, 0));
      if (distance <= 1) {
        ++nearStep;
        nearNotThird += chosen != 2;
        nearThirdError += error(result.candidates[2].mean, x, y);
        nearSecondError += error(result.candidates[1].mean, x, y);
      } else if (distance >= 12 && x >= 3 && x < w - 3) {
        ++far;
        farThird += chosen == 2;
        farFirst += chosen == 0;
        farThirdError += error(result.candidates[2].mean, x, y);
        farFirstError += error(result.candidates[0].mean, x, y);
        farSecondError += error(result.candidates[1].mean, x, y);
      }
    }
  std::cout << "near: third " << nearThirdError << " second " << nearSecondError << "; far: first "
            << farFirstError << " second " << farSecondError << " third " << farThirdError
            << "; far picks first " << farFirst << " third " << farThird << " of " << far << "\n";
  // The cases are clear: at the step THIRD's error is far above SECOND's; far from it FIRST's
  // (3×3 patches, noisier weights) is well above the two wide candidates'.
  ASSERT_GT(nearThirdError, 10 * nearSecondError);
  ASSERT_GT(farFirstError, 1.5 * std::max(farSecondError, farThirdError));
  EXPECT_GE(nearNotThird, nearStep * 9 / 10) << nearNotThird << " of " << nearStep;
  EXPECT_LE(farFirst, far / 10) << farFirst << " of " << far;
  EXPECT_GT(far, 300);
}

}  // namespace
}  // namespace chorus
