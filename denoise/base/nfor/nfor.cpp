#include "denoise/base/nfor/nfor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "common/error.h"
#include "denoise/base/filters/collaborative_regression.h"
#include "denoise/base/filters/local_range.h"
#include "denoise/base/filters/nlmeans_filter.h"
#include "denoise/base/input_planes.h"
#include "denoise/base/selection_knee.h"
#include "denoise/base/variance_estimates.h"

namespace chorus {

NforParams NforParams::fromParams(ParamMap& map) {
  NforParams p;
  p.prefilterF = map.getInt("prefilterF", p.prefilterF);
  p.prefilterR = map.getInt("prefilterR", p.prefilterR);
  p.prefilterK = map.getFloat("prefilterK", p.prefilterK);
  p.regressionF = map.getInt("regressionF", p.regressionF);
  p.regressionR = map.getInt("regressionR", p.regressionR);
  p.k1 = map.getFloat("k1", p.k1);
  p.k2 = map.getFloat("k2", p.k2);
  p.mseF = map.getInt("mseF", p.mseF);
  p.mseR = map.getInt("mseR", p.mseR);
  p.mseK = map.getFloat("mseK", p.mseK);
  p.finalFeatureF = map.getInt("finalFeatureF", p.finalFeatureF);
  p.finalFeatureR = map.getInt("finalFeatureR", p.finalFeatureR);
  p.finalFeatureK = map.getFloat("finalFeatureK", p.finalFeatureK);
  p.finalF = map.getInt("finalF", p.finalF);
  p.finalR = map.getInt("finalR", p.finalR);
  p.finalK = map.getFloat("finalK", p.finalK);
  p.epsilon = map.getFloat("epsilon", p.epsilon);
  p.distanceClamp = map.getFloat("distanceClamp", p.distanceClamp);
  p.minCenterWeight = map.getFloat("minCenterWeight", p.minCenterWeight);
  p.selectionKnee = map.getFloat("selectionKnee", p.selectionKnee);
  if (!validKnee(p.selectionKnee)) throw Error("nfor: selectionKnee must be 0 (off) or positive");
  p.varianceKnee = map.getFloat("varianceKnee", p.varianceKnee);
  if (!validKnee(p.varianceKnee)) throw Error("nfor: varianceKnee must be 0 (off) or positive");
  for (int v : {p.prefilterF, p.prefilterR, p.regressionF, p.regressionR, p.mseF, p.mseR,
                p.finalFeatureF, p.finalFeatureR, p.finalF, p.finalR})
    if (v < 0 || v > 32) throw Error("nfor: patch and window radii must be in [0, 32]");
  for (float k : {p.prefilterK, p.k1, p.k2, p.mseK, p.finalFeatureK, p.finalK})
    if (!(k > 0)) throw Error("nfor: bandwidths k must be positive");
  return p;
}

namespace {

// How far beyond its window's data range (in units of that range) a regression's prediction
// may go before the NL-means average replaces it.
constexpr float kImplausibleMargin = 0.5f;

// Tungsten's feature order: depth, albedo R G B, normal x y z, visibility.
constexpr Quantity kFeatureOrder[] = {Quantity::Depth, Quantity::Albedo, Quantity::Normal,
                                      Quantity::Visibility};

int featureChannelCount() {
  int m = 0;
  for (Quantity q : kFeatureOrder) m += channelCount(q);
  return m;
}

// The features of a buffer as one image with a channel per scalar feature. Where a feature
// mean is not finite its variance becomes NaN ("no sample": matches nothing) and the mean 0.
Image featureMeans(const SubBuffer& buffer) {
  Image out(buffer.width(), buffer.height(), featureChannelCount());
  int channel = 0;
  for (Quantity q : kFeatureOrder) {
    const Image& mean = buffer.get(q).mean;
    for (int c = 0; c < mean.channels(); ++c, ++channel)
      for (int y = 0; y < out.height(); ++y)
        for (int x = 0; x < out.width(); ++x) out(x, y, channel) = clampedFinite(mean(x, y, c));
  }
  return out;
}

Image featureVariances(const DenoiseInput& input) {
  const auto& halves = *input.halves;
  Image out(input.width(), input.height(), featureChannelCount());
  int channel = 0;
  for (Quantity q : kFeatureOrder) {
    const Image variance = wholeVarianceOfMean(input, q);
    const Image& m1 = halves[0].get(q).mean;
    const Image& m2 = halves[1].get(q).mean;
    for (int c = 0; c < variance.channels(); ++c, ++channel)
      for (int y = 0; y < out.height(); ++y)
        for (int x = 0; x < out.width(); ++x) {
          const bool known = std::isfinite(m1(x, y, c)) && std::isfinite(m2(x, y, c));
          out(x, y, channel) = known ? variance(x, y, c) : std::numeric_limits<float>::quiet_NaN();
        }
  }
  return out;
}

Image colorVariance(const DenoiseInput& input) {
  Image variance = wholeVarianceOfMean(input, Quantity::Color);
  const auto& halves = *input.halves;
  for (size_t i = 0; i < variance.size(); ++i)
    if (!std::isfinite(halves[0].color.mean.data()[i]) ||
        !std::isfinite(halves[1].color.mean.data()[i]))
      variance.data()[i] = std::numeric_limits<float>::quiet_NaN();
  return variance;
}

// Per-pixel arithmetic on images of the same shape.
template <typename Fn>
Image combine(const Image& a, const Image& b, Fn&& fn) {
  Image out(a.width(), a.height(), a.channels());
  for (size_t i = 0; i < out.size(); ++i) out.data()[i] = fn(a.data()[i], b.data()[i]);
  return out;
}

// Per-pixel mean of two images of the same shape.
Image pixelMean(const Image& a, const Image& b) {
  return combine(a, b, [](float x, float y) { return (x + y) * 0.5f; });
}

class NforRun {
 public:
  NforRun(const NforParams& p, const DenoiseInput& input) : p_(p), input_(input) {}

  // Each stage is a function of its own, so that its intermediate images are freed (and their
  // memory reused by the next stage) as soon as it ends: fewer pages first touched.
  Image run() {
    const Image c = clampedFinite(input_.whole.color.mean);
    const std::array<Image, 2> fFiltered = prefilteredFeatures();
    const std::array<Image, 2> r = firstPass(c, fFiltered);
    Image out = secondPass(fFiltered, r);
    for (size_t i = 0; i < out.size(); ++i)
      if (!std::isfinite(out.data()[i])) out.data()[i] = c.data()[i];
    return out;
  }

 private:
  // Feature cross-prefiltering (§5.1): A's features with weights from B's, and vice versa.
  std::array<Image, 2> prefilteredFeatures() const {
    const auto& halves = *input_.halves;
    const Image f1 = featureMeans(halves[0]), f2 = featureMeans(halves[1]);
    const Image fVar = featureVariances(input_);
    const NlMeansParams prefilterWindow = window(p_.prefilterR);
    return {
        nlMeans(f1, perChannelTerm(f2, fVar, p_.prefilterF, p_.prefilterK, 2.0f), prefilterWindow),
        nlMeans(f2, perChannelTerm(f1, fVar, p_.prefilterF, p_.prefilterK, 2.0f), prefilterWindow)};
  }

  // The halves' first-pass outputs r1, r2: each half's two bandwidths blended by the selection.
  std::array<Image, 2> firstPass(const Image& c, const std::array<Image, 2>& fFiltered) const {
    const auto& halves = *input_.halves;
    const Image c1 = clampedFinite(halves[0].color.mean), c2 = clampedFinite(halves[1].color.mean);
    const Image sigma2 = colorVariance(input_);

    // Regression passes (§5.2): colour of one half, weights from the other half's colour,
    // regressed on the other half's filtered features.
    const double knee = kneeLevel({c.data(), c.size()}, p_.varianceKnee);
    const std::array<Image, 2> y1 =
        regressBothBandwidths(c1, fFiltered[1], c2, kneedVariance(sigma2, c2, knee));
    const std::array<Image, 2> y2 =
        regressBothBandwidths(c2, fFiltered[0], c1, kneedVariance(sigma2, c1, knee));
    const Image selection = selectionMap(c, c1, c2, sigma2, y1, y2);
    return {blend(y1[0], y1[1], selection), blend(y2[0], y2[1], selection)};
  }

  // Bandwidth selection (§5.3): smoothed MSE, per-channel binary map, smoothed map.
  Image selectionMap(const Image& c, const Image& c1, const Image& c2, const Image& sigma2,
                     const std::array<Image, 2>& y1, const std::array<Image, 2>& y2) const {
    Image mse[2];
    for (int i = 0; i < 2; ++i) mse[i] = mseEstimate(c1, c2, y1[i], y2[i], sigma2);
    // The pixel's level: the halves' narrow-bandwidth outputs (selection_knee.h).
    const Image level = pixelMean(y1[0], y2[0]);
    float* const maps[] = {mse[0].data(), mse[1].data()};
    kneeBrightErrors(
        maps, level.size(), [&](size_t e) { return double(level.data()[e]); },
        kneeLevel({c.data(), c.size()}, p_.selectionKnee));
    const NlMeansWeights smoothing(perChannelTerm(c, sigma2, p_.mseF, p_.mseK, 1.0f),
                                   window(p_.mseR));
    const Image* mses[] = {&mse[0], &mse[1]};
    const NlMeansFilterResult smoothed = nlMeansFilterAll(mses, smoothing);
    const Image noisySelection = combine(smoothed.filtered[0], smoothed.filtered[1],
                                         [](float e1, float e2) { return e1 < e2 ? 0.0f : 1.0f; });
    return nlMeansFilter(noisySelection, smoothing);
  }

  // Second filter pass (§5.4) on the means of the halves, with their dual-buffer variances.
  Image secondPass(const std::array<Image, 2>& fFiltered, const std::array<Image, 2>& r) const {
    const Image fFinal = finalFeatures(fFiltered);
    const Image rMean = pixelMean(r[0], r[1]);
    const Image rMeanVar =
        combine(r[0], r[1], [](float a, float b) { return (b - a) * (b - a) * 0.25f; });
    const double knee = kneeLevel({rMean.data(), rMean.size()}, p_.varianceKnee);
    return regress(rMean, fFinal, rMean, kneedVariance(rMeanVar, rMean, knee), p_.finalF, p_.finalK,
                   p_.finalR);
  }

  Image finalFeatures(const std::array<Image, 2>& fFiltered) const {
    const Image fMean = pixelMean(fFiltered[0], fFiltered[1]);
    const Image fMeanVar = combine(fFiltered[0], fFiltered[1],
                                   [](float a, float b) { return (b - a) * (b - a) * 0.25f; });
    return nlMeans(fMean, perChannelTerm(fMean, fMeanVar, p_.finalFeatureF, p_.finalFeatureK, 1.0f),
                   window(p_.finalFeatureR));
  }

  NlMeansParams window(int r) const {
    return {.r = r, .center = CenterWeight::Computed, .minCenterWeight = p_.minCenterWeight};
  }

  NlMeansTerm perChannelTerm(const Image& guide, const Image& variance, int f, float k,
                             float s) const {
    return {.guide = &guide,
            .variance = &variance,
            .f = f,
            .k = k,
            .alpha = 1.0f,
            .s = s,
            .epsilon = p_.epsilon,
            .distanceClamp = p_.distanceClamp,
            .channels = ChannelWeights::PerChannel};
  }

  // Tungsten's regression weights: one weight per pixel (min over the colour channels), the
  // variance scale always 2 (a half's variance is twice the whole's) — also in the final pass,
  // where it is kept for fidelity.
  NlMeansTerm regressionTerm(const Image& guide, const Image& variance, int f, float k) const {
    return {.guide = &guide,
            .variance = &variance,
            .f = f,
            .k = k,
            .alpha = 1.0f,
            .s = 2.0f,
            .epsilon = p_.epsilon,
            .distanceClamp = p_.distanceClamp,
            .channels = ChannelWeights::MinOverChannels};
  }

  Image regress(const Image& image, const Image& features, const Image& guide,
                const Image& variance, int f, float k, int r) const {
    const NlMeansWeights weights(regressionTerm(guide, variance, f, k), window(r));
    Image out = collaborativeRegression(image, features, weights);
    fallBackWhereImplausible(out, image, weights, r);
    return out;
  }

  // The first-pass regressions for k1 and k2. When (k2 / k1)² is a whole number p (Tungsten's
  // 0.5 and 1: p = 4), k1's weights are k2's to the power p, so the weights are computed once.
  std::array<Image, 2> regressBothBandwidths(const Image& image, const Image& features,
                                             const Image& guide, const Image& variance) const {
    const int f = p_.regressionF, r = p_.regressionR;
    const double ratio = double(p_.k2) / double(p_.k1), power = std::round(ratio * ratio);
    if (power < 1 || power > kMaxWeightPower || std::abs(ratio * ratio - power) > 1e-6)
      return {regress(image, features, guide, variance, f, p_.k1, r),
              regress(image, features, guide, variance, f, p_.k2, r)};
    const NlMeansWeights weights2(regressionTerm(guide, variance, f, p_.k2), window(r));
    const int powers[2] = {int(power), 1};
    std::vector<Image> out = collaborativeRegressions(image, features, weights2, powers);
    fallBackWhereImplausible(out[1], image, weights2, r);
    const NlMeansWeights weights1(regressionTerm(guide, variance, f, p_.k1), window(r));
    fallBackWhereImplausible(out[0], image, weights1, r);
    return {std::move(out[0]), std::move(out[1])};
  }

  // Where the regression's prediction leaves the range of the data in the pixel's window by
  // more than half that range (or is not finite), the pixel takes the NL-means average of the
  // data with the same weights instead, which stays inside it. A fit that extrapolates that far
  // rests on an ill-conditioned window: defocused or noisy features, a firefly at the edge of
  // the window (docs/outliers.md). On ordinary windows the prediction never gets there.
  static void fallBackWhereImplausible(Image& out, const Image& image,
                                       const NlMeansWeights& weights, int r) {
    const LocalRange range = localRange(image, r);
    std::vector<size_t> implausible;
    const int channels = out.channels();
    for (size_t i = 0; i < out.pixelCount(); ++i)
      for (int c = 0; c < channels; ++c) {
        const size_t e = i * size_t(channels) + size_t(c);
        const float lo = range.lo.data()[e], hi = range.hi.data()[e], v = out.data()[e];
        const float margin = kImplausibleMargin * (hi - lo);
        if (lo <= hi && !(v >= lo - margin && v <= hi + margin)) {
          implausible.push_back(i);
          break;
        }
      }
    if (implausible.empty()) return;
    const Image average = nlMeansFilter(image, weights);
    for (size_t i : implausible)
      for (int c = 0; c < channels; ++c) {
        const size_t e = i * size_t(channels) + size_t(c);
        out.data()[e] = average.data()[e];
      }
  }

  // e = ½[(c2 − y1)² − 2σ² + (c1 − y2)² − 2σ²] − ¼(y2 − y1)²: the error of the average of the
  // two outputs (2σ² is a half's variance; the last term removes their residual variance).
  static Image mseEstimate(const Image& c1, const Image& c2, const Image& y1, const Image& y2,
                           const Image& sigma2) {
    Image out(c1.width(), c1.height(), c1.channels());
    for (size_t i = 0; i < out.size(); ++i) {
      const float v = sigma2.data()[i], a = c2.data()[i] - y1.data()[i];
      const float b = c1.data()[i] - y2.data()[i], r = y2.data()[i] - y1.data()[i];
      float e = 0.5f * ((a * a - 2.0f * v) + (b * b - 2.0f * v)) - 0.25f * r * r;
      out.data()[i] = std::isfinite(e) ? e : 0.0f;
    }
    return out;
  }

  static Image blend(const Image& a, const Image& b, const Image& t) {
    Image out(a.width(), a.height(), a.channels());
    for (size_t i = 0; i < out.size(); ++i) {
      const float s = t.data()[i];
      out.data()[i] = a.data()[i] * (1.0f - s) + b.data()[i] * s;
    }
    return out;
  }

  const NforParams& p_;
  const DenoiseInput& input_;
};

}  // namespace

Image NforDenoiser::run(const DenoiseInput& input) const {
  if (!input.halves)
    throw Error("nfor: needs two independent halves of its input (render with 2 or 4 sub-buffers)");
  return NforRun(params_, input).run();
}

}  // namespace chorus
