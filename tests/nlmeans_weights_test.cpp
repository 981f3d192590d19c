// The NL-means weight machinery against a naive per-patch loop written from the formulas in
// base-denoisers.md §0 (double precision, no box filters, no tiles), plus the statistical
// properties the filters rely on: convergence on a noisy constant, edge preservation, and
// unbiased patch distances under variance cancellation.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <vector>

#include "denoise/base/filters/box_filter.h"
#include "denoise/base/filters/nlmeans_filter.h"
#include "denoise/base/filters/nlmeans_weights.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

// ---- Brute-force reference ---------------------------------------------------------------

bool inside(const Image& im, int x, int y) {
  return x >= 0 && y >= 0 && x < im.width() && y < im.height();
}

struct Ref {
  std::vector<NlMeansTerm> terms;
  NlMeansParams params;
  int weightChannels = 1;

  // Per-pixel distance of term t, channel c, between p and q (or the mean of q and q2).
  double pixelDistance(const NlMeansTerm& t, int c, int px, int py, int qx, int qy,
                       const int* q2 = nullptr) const {
    const Image& g = *t.guide;
    const Image& v = *t.variance;
    const Image& vd = t.denominatorVariance ? *t.denominatorVariance : v;
    auto missing = [&](int x, int y) {
      return !std::isfinite(g(x, y, c)) || !std::isfinite(v(x, y, c)) ||
             !std::isfinite(vd(x, y, c));
    };
    if (missing(px, py) || missing(qx, qy) || (q2 && missing(q2[0], q2[1]))) return t.distanceClamp;
    const double s = t.s, k2 = double(t.k) * t.k;
    const double vp = std::max(0.0f, v(px, py, c)) * s, dp = std::max(0.0f, vd(px, py, c)) * s;
    double gq = g(qx, qy, c), vq = std::max(0.0f, v(qx, qy, c)) * s;
    double minTerm = std::min(vp, vq), dq = std::max(0.0f, vd(qx, qy, c)) * s;
    if (q2) {
      const double v2 = std::max(0.0f, v(q2[0], q2[1], c)) * s;
      gq = 0.5 * (gq + g(q2[0], q2[1], c));
      minTerm = 0.25 * (std::min(vp, vq) + std::min(vp, v2));
      dq = 0.25 * (dq + std::max(0.0f, vd(q2[0], q2[1], c)) * s);
      vq = 0;
    }
    const double diff = g(px, py, c) - gq;
    const double num = diff * diff - t.alpha * (vp + minTerm);
    const double den = t.epsilon + k2 * (t.centerOnlyDenominator ? 2 * dp : dp + dq);
    return std::min(num / den, double(t.distanceClamp));
  }

  // Patch distance D_c(p, p+δ) (symmetric: to the mean of p+δ and p−δ).
  double patchDistance(const NlMeansTerm& t, int c, int px, int py, int dx, int dy,
                       bool symmetric) const {
    const Image& g = *t.guide;
    double sum = 0;
    int count = 0;
    for (int oy = -t.f; oy <= t.f; ++oy)
      for (int ox = -t.f; ox <= t.f; ++ox) {
        const int x = px + ox, y = py + oy;
        if (!inside(g, x, y) || !inside(g, x + dx, y + dy)) continue;
        if (symmetric && !inside(g, x - dx, y - dy)) continue;
        const int q2[2] = {x - dx, y - dy};
        sum += pixelDistance(t, c, x, y, x + dx, y + dy, symmetric ? q2 : nullptr);
        ++count;
      }
    return sum / count;
  }

  std::vector<double> termWeight(const NlMeansTerm& t, int px, int py, int dx, int dy,
                                 bool symmetric) const {
    const int channels = t.guide->channels();
    std::vector<double> d(static_cast<size_t>(channels));
    for (int c = 0; c < channels; ++c)
      d[size_t(c)] = patchDistance(t, c, px, py, dx, dy, symmetric);
    auto w = [](double D) { return std::exp(-std::max(0.0, D)); };
    std::vector<double> out;
    if (t.channels == ChannelWeights::PerChannel) {
      for (double D : d) out.push_back(w(D));
    } else if (t.channels == ChannelWeights::MinOverChannels) {
      double m = 1;
      for (double D : d) m = std::min(m, w(D));
      out.push_back(m);
    } else {
      double mean = 0;
      for (double D : d) mean += D / channels;
      out.push_back(w(mean));
    }
    return out;
  }

  // Weight of p for offset δ before the patchwise box (refined, min over terms); memoised.
  mutable std::map<std::array<int, 4>, std::vector<double>> rawCache;
  std::vector<double> rawWeight(int px, int py, int dx, int dy) const {
    const std::array<int, 4> key{px, py, dx, dy};
    if (auto it = rawCache.find(key); it != rawCache.end()) return it->second;
    return rawCache[key] = computeRawWeight(px, py, dx, dy);
  }
  std::vector<double> computeRawWeight(int px, int py, int dx, int dy) const {
    std::vector<double> out(size_t(weightChannels), 1.0);
    const Image& g = *terms[0].guide;
    for (const NlMeansTerm& t : terms) {
      std::vector<double> w1 = termWeight(t, px, py, dx, dy, false);
      const bool canRefine =
          t.symmetricRefinement && (dx != 0 || dy != 0) && inside(g, px - dx, py - dy);
      if (canRefine) {
        const std::vector<double> w2 = termWeight(t, px, py, -dx, -dy, false);
        const std::vector<double> ws = termWeight(t, px, py, dx, dy, true);
        const double minW = std::isfinite(t.symmetricDistanceLimit)
                                ? std::exp(-double(t.symmetricDistanceLimit))
                                : 0.0;
        for (size_t c = 0; c < w1.size(); ++c) {
          if (!(w1[c] >= minW && w2[c] >= minW)) continue;
          const double sum = w1[c] + w2[c];
          const double a = sum > 0 ? std::clamp(ws[c] / sum - 1, 0.0, 1.0) : (ws[c] > 0 ? 1 : 0);
          w1[c] = a * ws[c] + (1 - a) * w1[c];
        }
      }
      for (size_t c = 0; c < out.size(); ++c)
        out[c] = std::min(out[c], w1.size() == 1 ? w1[0] : w1[c]);
    }
    return out;
  }

  std::vector<double> weight(int px, int py, int dx, int dy) const {
    const Image& g = *terms[0].guide;
    const int b = params.weightBoxRadius;
    std::vector<double> sum(size_t(weightChannels), 0.0);
    int count = 0;
    for (int oy = -b; oy <= b; ++oy)
      for (int ox = -b; ox <= b; ++ox) {
        const int x = px + ox, y = py + oy;
        if (!inside(g, x, y) || !inside(g, x + dx, y + dy)) continue;
        const std::vector<double> w = rawWeight(x, y, dx, dy);
        for (size_t c = 0; c < sum.size(); ++c) sum[c] += w[c];
        ++count;
      }
    for (double& s : sum) {
      s /= count;
      if (s < params.weightThreshold) s = 0;
    }
    return sum;
  }

  std::vector<double> centerWeight(int px, int py, const std::vector<double>& maxNeighbour) const {
    if (params.center == CenterWeight::One) return std::vector<double>(size_t(weightChannels), 1.0);
    if (params.center == CenterWeight::MaxOfNeighbours) {
      std::vector<double> out = maxNeighbour;
      for (double& w : out) w = std::max(w, double(params.minCenterWeight));
      return out;
    }
    std::vector<double> w = weight(px, py, 0, 0);
    for (double& x : w) x = std::max(x, double(params.minCenterWeight));
    return w;
  }

  Image filter(const Image& data, Image* weightSumOut) const {
    const Image& g = *terms[0].guide;
    Image out(data.width(), data.height(), data.channels());
    Image wsumImage(data.width(), data.height(), weightChannels);
    const int r = params.r;
    for (int py = 0; py < g.height(); ++py)
      for (int px = 0; px < g.width(); ++px) {
        std::vector<double> acc(size_t(data.channels()), 0.0), wsum(size_t(weightChannels), 0.0);
        std::vector<double> maxW(size_t(weightChannels), 0.0);
        for (int dy = -r; dy <= r; ++dy)
          for (int dx = -r; dx <= r; ++dx) {
            if ((dx == 0 && dy == 0) || !inside(g, px + dx, py + dy)) continue;
            const std::vector<double> w = weight(px, py, dx, dy);
            for (int c = 0; c < data.channels(); ++c)
              acc[size_t(c)] += w[weightChannels == 1 ? 0 : size_t(c)] * data(px + dx, py + dy, c);
            for (size_t c = 0; c < w.size(); ++c) {
              wsum[c] += w[c];
              maxW[c] = std::max(maxW[c], w[c]);
            }
          }
        const std::vector<double> wc = centerWeight(px, py, maxW);
        for (int c = 0; c < data.channels(); ++c)
          acc[size_t(c)] += wc[weightChannels == 1 ? 0 : size_t(c)] * data(px, py, c);
        for (size_t c = 0; c < wc.size(); ++c) wsum[c] += wc[c];
        for (int c = 0; c < data.channels(); ++c) {
          const double s = wsum[weightChannels == 1 ? 0 : size_t(c)];
          out(px, py, c) = s > 0 ? float(acc[size_t(c)] / s) : data(px, py, c);
        }
        for (int c = 0; c < weightChannels; ++c) wsumImage(px, py, c) = float(wsum[size_t(c)]);
      }
    if (weightSumOut) *weightSumOut = wsumImage;
    return out;
  }
};

// A smooth-ish random guide (so that weights span the whole range) and a matching variance.
Image smoothRandom(int w, int h, int c, uint32_t seed, float lo, float hi) {
  return boxFilter(test::randomImage(w, h, c, seed, lo, hi), 1);
}

void expectNear(const Image& a, const Image& b, double relTol, const char* what) {
  ASSERT_TRUE(a.sameShape(b)) << what;
  int bad = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < a.channels(); ++c) {
        const double va = a(x, y, c), vb = b(x, y, c);
        if (std::abs(va - vb) > relTol * (1e-3 + std::abs(vb)) && bad++ < 5)
          ADD_FAILURE() << what << " differs at (" << x << "," << y << "," << c << "): " << va
                        << " vs brute force " << vb;
      }
  EXPECT_EQ(bad, 0) << what;
}

// Compares every offset pair's tile weights with the brute force, then the filtered image.
void checkAgainstBruteForce(const Ref& ref, const Image& data, double tol = 2e-5) {
  const NlMeansWeights weights(ref.terms, ref.params);
  ASSERT_EQ(weights.weightChannels(), ref.weightChannels);
  const int wch = weights.weightChannels();
  // An unaligned tile that touches the left border only.
  const PixelRect tile{0, 3, 11, 14};
  const size_t area = size_t(tile.area());
  std::vector<float> plus(area * size_t(wch)), minus(area * size_t(wch));
  NlMeansScratch scratch;
  int bad = 0;
  weights.forEachOffsetPair([&](int dx, int dy) {
    weights.offsetPair(tile, dx, dy, scratch, plus.data(), minus.data());
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x)
        for (int sign : {1, -1}) {
          const int ddx = sign * dx, ddy = sign * dy;
          const std::vector<float>& got = sign > 0 ? plus : minus;
          std::vector<double> want(size_t(wch), 0.0);
          if (inside(data, x + ddx, y + ddy)) want = ref.weight(x, y, ddx, ddy);
          for (int c = 0; c < wch; ++c) {
            const double g = got[size_t(c) * area + size_t(y - tile.y0) * size_t(tile.width()) +
                                 size_t(x - tile.x0)];
            const double e = want[size_t(c)];
            const bool nearThreshold =
                std::abs(e - ref.params.weightThreshold) < 1e-4 && ref.params.weightThreshold > 0;
            if (std::abs(g - e) > tol * (1e-6 + e) && !nearThreshold && bad++ < 5)
              ADD_FAILURE() << "weight p=(" << x << "," << y << ") δ=(" << ddx << "," << ddy
                            << ") c=" << c << ": " << g << " vs brute force " << e;
          }
        }
  });
  EXPECT_EQ(bad, 0);

  const Image* images[] = {&data};
  const NlMeansFilterResult got = nlMeansFilterAll(images, weights);
  Image wantSum;
  const Image want = ref.filter(data, &wantSum);
  expectNear(got.filtered[0], want, tol, "filtered");
  expectNear(got.weightSum, wantSum, tol, "weight sum");
}

// Random 16×16 inputs for one term: a smooth RGB guide (seeded with `seed`), its variance in
// [varianceLo, varianceHi) (seed + 1) and the data to filter (seed + 2).
struct OneTermInputs {
  Image guide, variance, data;
};

OneTermInputs oneTermInputs(uint32_t seed, float varianceLo, float varianceHi,
                            int dataChannels = 3) {
  return {smoothRandom(16, 16, 3, seed, 0.0f, 1.0f),
          test::randomImage(16, 16, 3, seed + 1, varianceLo, varianceHi),
          test::randomImage(16, 16, dataChannels, seed + 2)};
}

// checkAgainstBruteForce for the single term `term` reading in.guide and in.variance.
void checkTermAgainstBruteForce(const OneTermInputs& in, NlMeansTerm term,
                                const NlMeansParams& params, int weightChannels = 1) {
  term.guide = &in.guide;
  term.variance = &in.variance;
  Ref ref;
  ref.terms = {term};
  ref.params = params;
  ref.weightChannels = weightChannels;
  checkAgainstBruteForce(ref, in.data);
}

// ---- Agreement with the brute force --------------------------------------------------------

TEST(NlMeansWeights, TungstenStylePerChannelMatchesBruteForce) {
  checkTermAgainstBruteForce(oneTermInputs(1, 0.001f, 0.02f),
                             {.f = 3,
                              .k = 0.5f,
                              .alpha = 1.0f,
                              .s = 2.0f,
                              .epsilon = 1e-7f,
                              .distanceClamp = 1e4f,
                              .channels = ChannelWeights::PerChannel},
                             {.r = 5, .center = CenterWeight::Computed, .minCenterWeight = 1e-4f},
                             /*weightChannels=*/3);
}

TEST(NlMeansWeights, MinOverChannelsMatchesBruteForce) {
  checkTermAgainstBruteForce(
      oneTermInputs(4, 0.001f, 0.02f, /*dataChannels=*/2),
      {.f = 2, .k = 1.0f, .s = 2.0f, .epsilon = 1e-7f, .channels = ChannelWeights::MinOverChannels},
      {.r = 4, .minCenterWeight = 1e-4f});
}

TEST(NlMeansWeights, RousselleStyleSymmetricPatchwiseMatchesBruteForce) {
  checkTermAgainstBruteForce(
      oneTermInputs(7, 0.002f, 0.03f),
      {.f = 3,
       .k = 0.45f,
       .alpha = 1.0f,
       .channels = ChannelWeights::AverageDistance,
       .symmetricRefinement = true},
      {.r = 3, .weightBoxRadius = 3, .weightThreshold = 0.05f, .center = CenterWeight::One});
}

TEST(NlMeansWeights, FeatureTermsAndMaxCenterMatchBruteForce) {
  // RDFC-like: a colour patch term and a pixel-wise feature term with its own normalising
  // variance, centre-only denominators on the feature, a refinement limit, max-neighbour centre.
  const Image guide = smoothRandom(16, 16, 3, 10, 0.0f, 1.0f);
  const Image variance = test::randomImage(16, 16, 3, 11, 0.002f, 0.03f);
  const Image feature = smoothRandom(16, 16, 1, 12, 0.0f, 1.0f);
  const Image featureVar = test::randomImage(16, 16, 1, 13, 0.0f, 0.01f);
  const Image featureNorm = test::randomImage(16, 16, 1, 14, 0.001f, 0.05f);
  const Image data = test::randomImage(16, 16, 3, 15);
  Ref ref;
  ref.terms = {NlMeansTerm{.guide = &guide,
                           .variance = &variance,
                           .f = 1,
                           .k = 0.45f,
                           .channels = ChannelWeights::AverageDistance,
                           .symmetricRefinement = true,
                           .symmetricDistanceLimit = 25.0f},
               NlMeansTerm{.guide = &feature,
                           .variance = &featureVar,
                           .denominatorVariance = &featureNorm,
                           .f = 0,
                           .k = 0.6f,
                           .centerOnlyDenominator = true,
                           .symmetricRefinement = true,
                           .symmetricDistanceLimit = 25.0f}};
  ref.params = {.r = 3,
                .weightBoxRadius = 1,
                .center = CenterWeight::MaxOfNeighbours,
                .minCenterWeight = 1e-3f};
  checkAgainstBruteForce(ref, data);
}

TEST(NlMeansWeights, MissingStatisticsMatchNothing) {
  Image guide = smoothRandom(16, 16, 1, 16, 0.0f, 1.0f);
  Image variance = test::randomImage(16, 16, 1, 17, 0.001f, 0.02f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < 16; ++y) variance(12, y, 0) = nan;  // a column without samples
  variance(4, 5, 0) = nan;
  guide(7, 9, 0) = std::numeric_limits<float>::infinity();
  const Image data = test::randomImage(16, 16, 1, 18);
  Ref ref;
  ref.terms = {NlMeansTerm{.guide = &guide,
                           .variance = &variance,
                           .f = 1,
                           .k = 0.5f,
                           .s = 2.0f,
                           .epsilon = 1e-7f,
                           .channels = ChannelWeights::PerChannel}};
  ref.params = {.r = 3, .minCenterWeight = 1e-4f};
  checkAgainstBruteForce(ref, data);
  // A pixel whose variance is missing keeps its own value (only its floored centre weight).
  const Image out = nlMeans(data, ref.terms[0], ref.params);
  EXPECT_FLOAT_EQ(out.at(12, 8, 0), data.at(12, 8, 0));
  for (float v : out.values()) EXPECT_TRUE(std::isfinite(v));
}

TEST(NlMeansWeights, FusedSingleTermPathIsBitIdenticalToTheGeneralPath) {
  // A second term whose weight is exactly 1 everywhere (zero guide, zero variance: d = 0)
  // changes nothing but forces the general path.
  const Image guide = smoothRandom(37, 29, 3, 20, 0.0f, 1.0f);
  Image variance = test::randomImage(37, 29, 3, 21, 0.001f, 0.02f);
  variance(5, 7, 1) = std::numeric_limits<float>::quiet_NaN();
  const Image zero(37, 29, 1, 0.0f);
  const NlMeansTerm neutral{.guide = &zero, .variance = &zero, .f = 0};
  for (ChannelWeights mode : {ChannelWeights::PerChannel, ChannelWeights::MinOverChannels,
                              ChannelWeights::AverageDistance}) {
    for (int f : {0, 1, 3}) {
      const NlMeansTerm term{.guide = &guide,
                             .variance = &variance,
                             .f = f,
                             .k = 0.6f,
                             .s = 2.0f,
                             .epsilon = 1e-7f,
                             .channels = mode};
      const NlMeansParams params{.r = 4, .weightThreshold = 0.01f, .minCenterWeight = 1e-4f};
      const NlMeansWeights fused(term, params);
      const NlMeansTerm both[] = {term, neutral};
      const NlMeansWeights general(both, params);
      const PixelRect tile{3, 2, 25, 29};
      const size_t n = size_t(tile.area()) * size_t(fused.weightChannels());
      std::vector<float> p1(n), m1(n), p2(n), m2(n);
      NlMeansScratch s1, s2;
      fused.forEachOffsetPair([&](int dx, int dy) {
        fused.offsetPair(tile, dx, dy, s1, p1.data(), m1.data());
        general.offsetPair(tile, dx, dy, s2, p2.data(), m2.data());
        ASSERT_EQ(0, std::memcmp(p1.data(), p2.data(), n * sizeof(float)))
            << "f " << f << " δ (" << dx << "," << dy << ")";
        ASSERT_EQ(0, std::memcmp(m1.data(), m2.data(), n * sizeof(float)))
            << "f " << f << " δ (" << -dx << "," << -dy << ")";
      });
    }
  }
}

// ---- Statistical properties -----------------------------------------------------------------

Image noisyImage(int w, int h, const std::function<float(int, int)>& mean, float sigma,
                 uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, sigma);
  Image im(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) im(x, y, 0) = mean(x, y) + noise(rng);
  return im;
}

TEST(NlMeans, NoisyConstantConvergesToTheConstant) {
  // Dual-buffer setting: filter one noisy copy with weights from an independent second copy.
  const float sigma = 0.1f, mu = 0.5f;
  const auto constant = [&](int, int) { return mu; };
  const Image a = noisyImage(64, 64, constant, sigma, 1);
  const Image b = noisyImage(64, 64, constant, sigma, 2);
  const Image variance(64, 64, 1, sigma * sigma);
  double previousRms = sigma;
  for (int r : {1, 3, 7}) {
    const NlMeansTerm term{.guide = &b, .variance = &variance, .f = 3, .k = 0.45f};
    const Image out = nlMeans(a, term, NlMeansParams{.r = r, .center = CenterWeight::One});
    double sum = 0, sq = 0;
    for (float v : out.values()) {
      sum += v - mu;
      sq += (v - mu) * (v - mu);
    }
    const double n = double(out.size()), rms = std::sqrt(sq / n);
    // Nearly every neighbour gets a full weight: the error shrinks like 1 / (2r + 1).
    EXPECT_LT(rms, 1.6 * sigma / (2 * r + 1)) << "r = " << r;
    EXPECT_LT(rms, previousRms);
    EXPECT_LT(std::abs(sum / n), 0.01 * sigma) << "r = " << r;
    previousRms = rms;
  }
}

TEST(NlMeans, EdgeBetweenTwoConstantsIsPreserved) {
  const float sigma = 0.05f, low = 0.2f, high = 0.8f;
  const auto step = [&](int x, int) { return x < 32 ? low : high; };
  const Image a = noisyImage(64, 64, step, sigma, 3);
  const Image b = noisyImage(64, 64, step, sigma, 4);
  const Image variance(64, 64, 1, sigma * sigma);
  const NlMeansTerm term{
      .guide = &b, .variance = &variance, .f = 3, .k = 0.45f, .symmetricRefinement = true};
  const Image out = nlMeans(
      a, term,
      NlMeansParams{
          .r = 7, .weightBoxRadius = 3, .weightThreshold = 0.05f, .center = CenterWeight::One});
  const Image boxed = boxFilter(a, 7);  // an edge-blind filter of the same reach fails this
  double worstNear = 0, worstFar = 0, boxWorstFar = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const double truth = step(x, y), distance = x < 32 ? 31.5 - x : x - 31.5;
      const double err = std::abs(out(x, y, 0) - truth);
      if (distance < 2)
        worstNear = std::max(worstNear, err);
      else
        worstFar = std::max(worstFar, err);
      if (distance >= 2) boxWorstFar = std::max(boxWorstFar, std::abs(boxed(x, y, 0) - truth));
    }
  const double jump = high - low;
  EXPECT_LT(worstNear, 0.25 * jump);  // at most a quarter of the step right at the edge
  EXPECT_LT(worstFar, 2.0 * sigma);   // ≥ 2 px away: within the noise of one input pixel
  EXPECT_GT(boxWorstFar, 2.0 * sigma);
}

TEST(NlMeans, VarianceCancellationMakesPatchDistanceUnbiased) {
  // g = a·x + noise (variance V). For δ = (dx, 0), E[(g(p) − g(q))²] = (a dx)² + 2V, so with
  // α = 1 the expected distance is (a dx)² / (2 V k²); with α = 0 it is biased by 1/k².
  const int w = 128, h = 128;
  const float sigma = 0.1f, slope = 0.01f, k = 1.0f;
  const Image g = noisyImage(
      w, h, [&](int x, int) { return slope * x; }, sigma, 5);
  const Image variance(w, h, 1, sigma * sigma);
  for (float alpha : {1.0f, 0.0f}) {
    const NlMeansTerm term{.guide = &g, .variance = &variance, .f = 2, .k = k, .alpha = alpha};
    const NlMeansWeights weights(term, NlMeansParams{.r = 5});
    NlMeansScratch scratch;
    for (int dx : {1, 3, 5}) {
      const PixelRect region = neighbourInside(w, h, dx, 0);
      std::vector<float> d(size_t(region.area()));
      weights.patchDistance(0, region, dx, 0, scratch, d.data());
      double mean = 0;
      for (float v : d) mean += v / double(d.size());
      const double v = sigma * sigma, delta = slope * dx;
      const double expected = (delta * delta + 2 * v * (1 - alpha)) / (2 * v * k * k);
      // Per-pixel d has standard deviation ≈ √2 / k²; ~16k pixel pairs → 0.02 standard error.
      EXPECT_NEAR(mean, expected, 0.1) << "alpha " << alpha << " dx " << dx;
    }
  }
}

}  // namespace
}  // namespace chorus
