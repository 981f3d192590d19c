// The rank-revealing Gram solver against Eigen's column-pivoted QR, and the collaborative
// regression against a per-window brute force (Eigen QR on the weighted window matrix, as in
// Tungsten), on exactly affine data, and on rank-deficient feature sets.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "denoise/base/filters/box_filter.h"
#include "denoise/base/filters/collaborative_regression.h"
#include "denoise/base/filters/gram_solver.h"
#include "tests/support/denoiser_checks.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

using MatrixXd = Eigen::MatrixXd;

// Fitted values X β of the weighted problem, via the Gram solver.
MatrixXd gramFit(const MatrixXd& X, const Eigen::VectorXd& w, const MatrixXd& Y,
                 int* rank = nullptr) {
  const int d = int(X.cols()), C = int(Y.cols());
  const MatrixXd G = X.transpose() * w.asDiagonal() * X;
  const MatrixXd B = X.transpose() * w.asDiagonal() * Y;
  std::vector<double> g(size_t(d * d)), b(size_t(d * C)), beta(size_t(d * C));
  for (int i = 0; i < d; ++i)
    for (int j = 0; j < d; ++j) g[size_t(i * d + j)] = G(i, j);
  for (int i = 0; i < d; ++i)
    for (int c = 0; c < C; ++c) b[size_t(i * C + c)] = B(i, c);
  const int r = solveGramPivoted(g.data(), b.data(), d, C, beta.data());
  if (rank) *rank = r;
  MatrixXd betaM(d, C);
  for (int i = 0; i < d; ++i)
    for (int c = 0; c < C; ++c) betaM(i, c) = beta[size_t(i * C + c)];
  return X * betaM;
}

// Fitted values via Eigen's column-pivoted Householder QR of √W X (Tungsten's solver).
MatrixXd qrFit(const MatrixXd& X, const Eigen::VectorXd& w, const MatrixXd& Y) {
  const Eigen::VectorXd s = w.cwiseSqrt();
  return X * (s.asDiagonal() * X).colPivHouseholderQr().solve(s.asDiagonal() * Y);
}

TEST(GramSolver, MatchesPivotedQrOnFullRankProblems) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1), pos(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 40, d = 2 + trial % 9, C = 3;
    MatrixXd X(n, d), Y(n, C);
    Eigen::VectorXd w(n);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < d; ++j) X(i, j) = u(rng) * std::pow(10.0, j % 3 - 1);
      for (int c = 0; c < C; ++c) Y(i, c) = u(rng);
      w(i) = pos(rng);
    }
    int rank = 0;
    const MatrixXd got = gramFit(X, w, Y, &rank);
    EXPECT_EQ(rank, d);
    EXPECT_LT((got - qrFit(X, w, Y)).cwiseAbs().maxCoeff(), 1e-9) << "trial " << trial;
  }
}

TEST(GramSolver, RankDeficientColumnsGiveTheSameFitWithoutBlowingUp) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1), pos(0.1, 1);
  const int n = 30, C = 2;
  MatrixXd X(n, 6), Y(n, C);
  Eigen::VectorXd w(n);
  for (int i = 0; i < n; ++i) {
    X(i, 0) = 1;
    X(i, 1) = u(rng);
    X(i, 2) = 0;               // a constant (zero) feature difference
    X(i, 3) = X(i, 1);         // a duplicated feature
    X(i, 4) = -3.0 * X(i, 1);  // a scaled copy
    X(i, 5) = u(rng);
    for (int c = 0; c < C; ++c) Y(i, c) = u(rng);
    w(i) = pos(rng);
  }
  int rank = 0;
  const MatrixXd got = gramFit(X, w, Y, &rank);
  EXPECT_EQ(rank, 3);
  EXPECT_TRUE(got.allFinite());
  // The fit equals the full-rank fit on the independent columns {0, 1, 5}.
  MatrixXd Xr(n, 3);
  Xr << X.col(0), X.col(1), X.col(5);
  EXPECT_LT((got - qrFit(Xr, w, Y)).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(GramSolver, AllZeroProblemGivesZero) {
  std::vector<double> g(9, 0.0), b(3, 0.0), beta(3, 1.0);
  EXPECT_EQ(solveGramPivoted(g.data(), b.data(), 3, 1, beta.data()), 0);
  for (double v : beta) EXPECT_EQ(v, 0.0);
}

// ---- Collaborative regression ----------------------------------------------------------------

struct Scene {
  Image guide, variance, features, image;
};

// Smooth random features, a guide with real structure, and data affine in position and
// features (different coefficients per channel).
Scene affineScene(int w, int h, int m, uint32_t seed) {
  Scene s;
  s.features = boxFilter(test::randomImage(w, h, m, seed, 0.0f, 1.0f), 2);
  s.guide = boxFilter(test::randomImage(w, h, 3, seed + 1, 0.0f, 1.0f), 1);
  s.variance = Image(w, h, 3, 0.01f);
  s.image = Image(w, h, 3);
  std::mt19937 rng(seed + 2);
  std::uniform_real_distribution<float> coef(-1.0f, 1.0f);
  for (int c = 0; c < 3; ++c) {
    const float a = coef(rng), bx = 0.01f * coef(rng), by = 0.01f * coef(rng);
    std::vector<float> bf(static_cast<size_t>(m));
    for (float& v : bf) v = coef(rng);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        float v = a + bx * x + by * y;
        for (int j = 0; j < m; ++j) v += bf[size_t(j)] * s.features(x, y, j);
        s.image(x, y, c) = v;
      }
  }
  return s;
}

NlMeansWeights regressionWeights(const Scene& s, int r, float k = 1.0f) {
  return NlMeansWeights(NlMeansTerm{.guide = &s.guide,
                                    .variance = &s.variance,
                                    .f = 2,
                                    .k = k,
                                    .s = 2.0f,
                                    .epsilon = 1e-7f,
                                    .distanceClamp = 1e4f,
                                    .channels = ChannelWeights::MinOverChannels},
                        NlMeansParams{.r = r, .minCenterWeight = 1e-4f});
}

void expectRelativeNear(const Image& got, const Image& want, double tol) {
  ASSERT_TRUE(got.sameShape(want));
  double worst = 0;
  for (size_t i = 0; i < got.size(); ++i) {
    ASSERT_TRUE(std::isfinite(got.data()[i]));
    worst = std::max(worst, std::abs(double(got.data()[i]) - want.data()[i]) /
                                (1e-3 + std::abs(double(want.data()[i]))));
  }
  EXPECT_LT(worst, tol);
}

TEST(CollaborativeRegression, RecoversAnExactlyAffineFunctionOfTheFeatures) {
  const Scene s = affineScene(40, 37, 5, 10);
  const Image out = collaborativeRegression(s.image, s.features, regressionWeights(s, 6));
  expectRelativeNear(out, s.image, 1e-4);
}

TEST(CollaborativeRegression, RankDeficientFeaturesDoNotBlowUp) {
  Scene s = affineScene(32, 32, 2, 20);
  // Add a constant feature, a duplicate and a scaled copy of feature 0.
  Image features(32, 32, 5);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      features(x, y, 0) = s.features(x, y, 0);
      features(x, y, 1) = s.features(x, y, 1);
      features(x, y, 2) = 0.7f;
      features(x, y, 3) = s.features(x, y, 0);
      features(x, y, 4) = 1000.0f * s.features(x, y, 1);
    }
  const Image out = collaborativeRegression(s.image, features, regressionWeights(s, 5));
  expectRelativeNear(out, s.image, 1e-4);
}

TEST(CollaborativeRegression, PoweredWeightsMatchTheSmallerBandwidth) {
  // Data that no first-order model fits (noise), so the output depends on every weight: the
  // regression with weights w^4 (k = 1) must equal one with weights computed for k = 0.5, and
  // power 1 the plain regression.
  Scene s = affineScene(40, 36, 4, 40);
  s.image = test::randomImage(40, 36, 3, 41, 0.0f, 1.0f);
  const int powers[] = {4, 1};
  const std::vector<Image> out =
      collaborativeRegressions(s.image, s.features, regressionWeights(s, 5, 1.0f), powers);
  ASSERT_EQ(out.size(), 2u);
  expectRelativeNear(
      out[0], collaborativeRegression(s.image, s.features, regressionWeights(s, 5, 0.5f)), 1e-3);
  expectRelativeNear(
      out[1], collaborativeRegression(s.image, s.features, regressionWeights(s, 5, 1.0f)), 1e-6);
}

TEST(CollaborativeRegression, ZeroVarianceGuideKeepsEveryPixel) {
  // Zero variance and distinct guide values: every neighbour weight is 0, each window holds
  // only its centre, and the regression returns the input.
  Scene s = affineScene(24, 20, 3, 30);
  s.variance.fill(0.0f);
  s.image = test::randomImage(24, 20, 3, 31, -1.0f, 5.0f);
  const Image out = collaborativeRegression(s.image, s.features, regressionWeights(s, 4));
  expectRelativeNear(out, s.image, 1e-6);
}

// Brute force: every window's weighted least squares with Eigen's pivoted QR in double,
// predictions accumulated with their weights (Regression.cpp's algorithm).
Image bruteForceRegression(const Image& image, const Image& features, const NlMeansWeights& weights,
                           const Scene& s, int r) {
  const int w = image.width(), h = image.height(), m = features.channels(), d = 3 + m;
  // The weights w(p, q) from the same machinery (tested against its own brute force).
  NlMeansScratch scratch;
  const PixelRect all = PixelRect::image(w, h);
  std::vector<std::vector<float>> table(size_t((2 * r + 1) * (2 * r + 1)),
                                        std::vector<float>(size_t(w * h)));
  auto index = [&](int dx, int dy) { return size_t((dy + r) * (2 * r + 1) + dx + r); };
  weights.center(all, scratch, table[index(0, 0)].data());
  weights.forEachOffsetPair([&](int dx, int dy) {
    weights.offsetPair(all, dx, dy, scratch, table[index(dx, dy)].data(),
                       table[index(-dx, -dy)].data());
  });
  (void)s;
  MatrixXd acc = MatrixXd::Zero(w * h, 3);
  Eigen::VectorXd wsum = Eigen::VectorXd::Zero(w * h);
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      std::vector<int> qs;
      for (int qy = std::max(0, py - r); qy <= std::min(h - 1, py + r); ++qy)
        for (int qx = std::max(0, px - r); qx <= std::min(w - 1, px + r); ++qx)
          qs.push_back(qy * w + qx);
      const int n = int(qs.size());
      MatrixXd X(n, d), Y(n, 3);
      Eigen::VectorXd wq(n);
      for (int i = 0; i < n; ++i) {
        const int qx = qs[size_t(i)] % w, qy = qs[size_t(i)] / w;
        X(i, 0) = 1;
        X(i, 1) = qx - px;
        X(i, 2) = qy - py;
        for (int j = 0; j < m; ++j) X(i, 3 + j) = features(qx, qy, j) - features(px, py, j);
        for (int c = 0; c < 3; ++c) Y(i, c) = image(qx, qy, c);
        wq(i) = table[index(qx - px, qy - py)][size_t(py * w + px)];
      }
      const MatrixXd pred = qrFit(X, wq, Y);
      for (int i = 0; i < n; ++i) {
        acc.row(qs[size_t(i)]) += wq(i) * pred.row(i);
        wsum(qs[size_t(i)]) += wq(i);
      }
    }
  Image out(w, h, 3);
  for (int i = 0; i < w * h; ++i)
    for (int c = 0; c < 3; ++c) out(i % w, i / w, c) = float(acc(i, c) / wsum(i));
  return out;
}

void expectMatchesPerWindowPivotedQr(int features) {
  // Non-affine random data: the fits are genuine least-squares problems.
  Scene s = affineScene(21, 19, features, 40);
  s.image = test::randomImage(21, 19, 3, 41, 0.0f, 2.0f);
  const int r = 3;
  const NlMeansWeights weights = regressionWeights(s, r, 0.7f);
  const Image out = collaborativeRegression(s.image, s.features, weights);
  const Image want = bruteForceRegression(s.image, s.features, weights, s, r);
  expectRelativeNear(out, want, 2e-4);
}

TEST(CollaborativeRegression, MatchesPerWindowPivotedQr) {
  expectMatchesPerWindowPivotedQr(3);
}

// NFOR's shape (8 features, RGB) runs a kernel of its own (fixed sizes, sums in register blocks).
TEST(CollaborativeRegression, MatchesPerWindowPivotedQrInNforsShape) {
  expectMatchesPerWindowPivotedQr(8);
}

// The Gram sums are blocked for the CPU's vector registers (AVX-512: two design rows over half a
// group's lanes; otherwise one row over a quarter, with the weights, columns and predictions
// eight lanes at a time); every sum adds the same terms in the same order, so both blockings give
// the same bits, in NFOR's shape and the generic one, for powered weights too. (Whichever
// blocking this CPU prefers, both run here.)
TEST(CollaborativeRegression, BothSumBlockingsGiveTheSameBits) {
  for (int features : {3, 8}) {
    Scene s = affineScene(37, 23, features, 50);
    s.image = test::randomImage(37, 23, 3, 51, 0.0f, 2.0f);
    const NlMeansWeights weights = regressionWeights(s, 4, 0.7f);
    const int powers[] = {4, 1};
    const std::vector<Image> wide =
        collaborativeRegressions(s.image, s.features, weights, powers, {}, GramSumBlocking::Wide);
    const std::vector<Image> narrow =
        collaborativeRegressions(s.image, s.features, weights, powers, {}, GramSumBlocking::Narrow);
    for (size_t i = 0; i < wide.size(); ++i)
      EXPECT_TRUE(test::bitIdentical(wide[i], narrow[i]))
          << features << " features, power " << powers[i];
  }
}

}  // namespace
}  // namespace chorus
