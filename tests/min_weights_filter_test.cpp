// nlMeansFilterMin: one weight set equals nlMeansFilterAll with the largest-neighbour centre
// weight; with a second set, weights are the minimum of both (a feature step stops mixing).
#include "denoise/base/min_weights_filter.h"

#include <gtest/gtest.h>

#include "denoise/base/filters/nlmeans_filter.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

NlMeansParams window(int r, int box) {
  NlMeansParams p;
  p.r = r;
  p.weightBoxRadius = box;
  p.center = CenterWeight::MaxOfNeighbours;
  p.minCenterWeight = 1e-3f;
  return p;
}

TEST(MinWeightsFilter, OneSetMatchesNlMeansFilterAll) {
  const Image guide = test::randomImage(70, 20, 3, 3);  // two tiles wide
  const Image variance(70, 20, 3, 0.02f);
  const Image data = test::randomImage(70, 20, 2, 4);
  NlMeansTerm term;
  term.guide = &guide;
  term.variance = &variance;
  term.f = 2;
  term.symmetricRefinement = true;
  const NlMeansWeights weights(term, window(3, 1));
  const Image* images[] = {&data};
  const NlMeansWeights* sets[] = {&weights};
  const Image expected = nlMeansFilterAll(images, weights).filtered[0];
  const Image got = nlMeansFilterMin(images, sets, 1e-3f)[0];
  for (size_t k = 0; k < got.size(); ++k) EXPECT_NEAR(got.data()[k], expected.data()[k], 1e-6f);
}

TEST(MinWeightsFilter, SecondSetStopsMixingAcrossItsEdge) {
  const int w = 20, h = 12;
  const Image guide(w, h, 1, 0.5f), variance(w, h, 1, 0.1f);  // colour term: weight 1 anywhere
  Image feature(w, h, 1), featureVariance(w, h, 1), data(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      feature(x, y, 0) = x < 8 ? 0.0f : 1.0f;
      data(x, y, 0) = x < 8 ? 2.0f : 5.0f;
    }
  NlMeansTerm colour;
  colour.guide = &guide;
  colour.variance = &variance;
  colour.f = 1;
  NlMeansTerm edge;
  edge.guide = &feature;
  edge.variance = &featureVariance;
  edge.f = 0;
  // Box-filtered colour weights, unfiltered feature weights (as RDFC's second pass).
  const NlMeansWeights colourWeights(colour, window(4, 2)), edgeWeights(edge, window(4, 0));
  const Image* images[] = {&data};
  const NlMeansWeights* sets[] = {&colourWeights, &edgeWeights};
  const Image out = nlMeansFilterMin(images, sets, 1e-3f)[0];
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) EXPECT_NEAR(out(x, y, 0), x < 8 ? 2.0f : 5.0f, 1e-6f) << x;
  // The colour set alone mixes both sides.
  const NlMeansWeights* colourOnly[] = {&colourWeights};
  EXPECT_GT(nlMeansFilterMin(images, colourOnly, 1e-3f)[0](7, 5, 0), 2.5f);
}

TEST(MinWeightsFilter, RejectsMismatchedSets) {
  const Image a(8, 8, 1, 0.5f), v(8, 8, 1, 0.1f), b(9, 8, 1, 0.5f), vb(9, 8, 1, 0.1f);
  NlMeansTerm ta{.guide = &a, .variance = &v}, tb{.guide = &b, .variance = &vb};
  const NlMeansWeights wa(ta, window(2, 0)), wb(tb, window(2, 0)), wr(ta, window(3, 0));
  const Image* images[] = {&a};
  const NlMeansWeights* sizes[] = {&wa, &wb};
  const NlMeansWeights* radii[] = {&wa, &wr};
  EXPECT_THROW(nlMeansFilterMin(images, sizes, 1e-3f), std::invalid_argument);
  EXPECT_THROW(nlMeansFilterMin(images, radii, 1e-3f), std::invalid_argument);
}

}  // namespace
}  // namespace chorus
