// featureNlMeans against the general NL-means machinery (nlmeans_weights.h / nlmeans_filter.h),
// an independent implementation of the same distances: one patch term (plain, patchwise,
// centre-only denominators), patch plus feature terms, feature terms alone; plus the minimum
// over terms at a feature step and the non-refined feature mode.
#include "denoise/base/filters/feature_nlmeans.h"

#include <gtest/gtest.h>

#include "denoise/base/filters/nlmeans_filter.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

NlMeansParams machineryWindow(int r, int box) {
  NlMeansParams p;
  p.r = r;
  p.weightBoxRadius = box;
  p.center = CenterWeight::MaxOfNeighbours;
  p.minCenterWeight = 1e-3f;
  return p;
}

NlMeansTerm machineryTerm(const Image& guide, const Image& variance, int f, float k,
                          const Image* denominator = nullptr, bool centreOnly = false) {
  NlMeansTerm t;
  t.guide = &guide;
  t.variance = &variance;
  t.denominatorVariance = denominator;
  t.f = f;
  t.k = k;
  t.epsilon = 1e-10f;
  t.channels = ChannelWeights::AverageDistance;
  t.symmetricRefinement = true;
  t.symmetricDistanceLimit = 25.0f;
  t.centerOnlyDenominator = centreOnly;
  return t;
}

void expectClose(const Image& got, const Image& expected, float tolerance) {
  ASSERT_TRUE(got.sameShape(expected));
  float worst = 0;
  for (size_t k = 0; k < got.size(); ++k)
    worst = std::max(worst, std::abs(got.data()[k] - expected.data()[k]));
  EXPECT_LE(worst, tolerance);
}

struct Inputs {
  // 70×40: two tiles wide, two high; noisy guide over smooth structure.
  Image guide = test::randomImage(70, 40, 3, 11, 0.2f, 0.8f);
  Image variance = test::randomImage(70, 40, 3, 12, 0.002f, 0.02f);
  Image feature = test::randomImage(70, 40, 2, 13, 0.0f, 0.3f);
  Image featureVariance = test::randomImage(70, 40, 2, 14, 0.0f, 0.01f);
  Image normalizing = test::randomImage(70, 40, 2, 15, 0.005f, 0.02f);
  Image data = test::randomImage(70, 40, 2, 16);
};

TEST(FeatureNlMeans, PatchTermMatchesTheMachinery) {
  const Inputs in;
  const Image* data[] = {&in.data};
  for (const auto& [box, centreOnly] :
       {std::pair{0, false}, std::pair{2, false}, std::pair{2, true}}) {
    const PatchTerm patch{.guide = &in.guide,
                          .variance = &in.variance,
                          .f = 2,
                          .k = 0.45f,
                          .centerOnlyDenominator = centreOnly,
                          .weightBoxRadius = box};
    const Image got = featureNlMeans(data, &patch, {}, {.r = 4})[0];
    const NlMeansTerm term = machineryTerm(in.guide, in.variance, 2, 0.45f, nullptr, centreOnly);
    const Image expected = nlMeansFilter(in.data, NlMeansWeights(term, machineryWindow(4, box)));
    SCOPED_TRACE(testing::Message() << "box " << box << " centre-only " << centreOnly);
    expectClose(got, expected, 2e-5f);
  }
}

TEST(FeatureNlMeans, PatchAndFeatureTermsMatchTheMachinery) {
  const Inputs in;
  const Image* data[] = {&in.data};
  const PatchTerm patch{.guide = &in.guide, .variance = &in.variance, .f = 1, .k = 0.45f};
  const FeatureTerm feature{.value = &in.feature,
                            .variance = &in.featureVariance,
                            .normalizingVariance = &in.normalizing,
                            .k = 0.6f};
  const FeatureTerm features[] = {feature};
  const Image got = featureNlMeans(data, &patch, features, {.r = 3})[0];
  const NlMeansTerm terms[] = {
      machineryTerm(in.guide, in.variance, 1, 0.45f),
      machineryTerm(in.feature, in.featureVariance, 0, 0.6f, &in.normalizing)};
  const Image expected = nlMeansFilter(in.data, NlMeansWeights(terms, machineryWindow(3, 0)));
  expectClose(got, expected, 2e-5f);

  // Feature terms only.
  const Image onlyFeatures = featureNlMeans(data, nullptr, features, {.r = 3})[0];
  const NlMeansTerm featureOnly[] = {terms[1]};
  expectClose(onlyFeatures,
              nlMeansFilter(in.data, NlMeansWeights(featureOnly, machineryWindow(3, 0))), 2e-5f);
}

// A step in one feature stops all mixing across it, whatever the colour; the non-refined mode
// keeps that minimum.
TEST(FeatureNlMeans, FeatureStepStopsMixing) {
  const int w = 20, h = 12;
  const Image guide(w, h, 1, 0.5f), variance(w, h, 1, 0.1f), zero(w, h, 1);
  Image step(w, h, 1), data(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      step(x, y, 0) = x < 8 ? 0.0f : 1.0f;
      data(x, y, 0) = x < 8 ? 2.0f : 5.0f;
    }
  const PatchTerm patch{.guide = &guide, .variance = &variance, .f = 1, .weightBoxRadius = 2};
  const FeatureTerm feature{.value = &step, .variance = &zero};
  const FeatureTerm features[] = {feature};
  const Image* images[] = {&data};
  for (bool refine : {true, false}) {
    const Image out =
        featureNlMeans(images, &patch, features, {.r = 4, .refineFeatures = refine})[0];
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) EXPECT_NEAR(out(x, y, 0), x < 8 ? 2.0f : 5.0f, 1e-6f) << x;
  }
  // Without the feature term the colour weights (flat guide) mix both sides.
  EXPECT_GT(featureNlMeans(images, &patch, {}, {.r = 4})[0](7, 5, 0), 2.5f);
}

TEST(FeatureNlMeans, RejectsMismatchedInputs) {
  const Image a(8, 8, 1, 0.5f), v(8, 8, 1, 0.1f), b(9, 8, 1, 0.5f);
  const Image* images[] = {&b};
  const PatchTerm patch{.guide = &a, .variance = &v};
  EXPECT_THROW(featureNlMeans(images, &patch, {}, {.r = 2}), std::invalid_argument);
}

}  // namespace
}  // namespace chorus
