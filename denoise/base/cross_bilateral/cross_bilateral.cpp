#include "denoise/base/cross_bilateral/cross_bilateral.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "denoise/base/input_planes.h"
#include "denoise/util/fast_exp.h"
#include "denoise/util/float_lanes.h"

namespace chorus {

FeatureGuide makeFeatureGuide(const SubBuffer& buffer, const FeatureSigmas& sigmas) {
  struct Source {
    const MeanVariance* feature;
    float sigma;
    float scale;  // applied to the feature value before σ (depth normalisation)
  };
  const float depthScale = 1.0f / maxFiniteDepth(buffer.depth.mean);
  std::vector<Source> sources;
  if (sigmas.normal > 0) sources.push_back({&buffer.normal, sigmas.normal, 1.0f});
  if (sigmas.albedo > 0) sources.push_back({&buffer.albedo, sigmas.albedo, 1.0f});
  if (sigmas.depth > 0) sources.push_back({&buffer.depth, sigmas.depth, depthScale});

  int channels = 0;
  for (const Source& s : sources) channels += s.feature->mean.channels();
  const int w = buffer.width(), h = buffer.height();
  FeatureGuide guide{PlanarImage(w, h, channels), PlanarImage(w, h, channels)};
  int k = 0;
  for (const Source& s : sources) {
    const PlanarImage variance = perSampleVariance(*s.feature, buffer.sampleCount);
    const PlanarImage mean(s.feature->mean);
    const float valueScale = s.scale / (std::sqrt(2.0f) * s.sigma);
    const float varianceScale = s.scale * s.scale;
    for (int c = 0; c < mean.channels(); ++c, ++k) {
      float* value = guide.value.plane(k);
      float* var = guide.variance.plane(k);
      for (size_t i = 0; i < mean.pixelCount(); ++i) {
        float f = mean.plane(c)[i];
        float v = variance.plane(c)[i];
        // Infinite depth (a miss) normalises to 1; other non-finite values carry no weight.
        if (std::isinf(f) && f > 0 && s.feature == &buffer.depth) {
          f = 1.0f / s.scale;
        } else if (!std::isfinite(f)) {
          f = 0.0f;
          v = kUnknownVariance;
        }
        value[i] = f * valueScale;
        var[i] =
            v < kUnknownVariance ? std::min(v * varianceScale, kUnknownVariance) : kUnknownVariance;
      }
    }
  }
  return guide;
}

namespace {

constexpr float kVarianceFloor = 0.01f;  // Li et al.'s release (c_VarMax)
constexpr float kInverseFloor = 1.0f / kVarianceFloor;
constexpr float kRangeEpsilon = 1e-10f;
constexpr int kBilateralTileWidth = 128;

// e[i] += (fp − fq)² · (1 / max(vp + vq, floor)), four lanes at a time where SSE2 exists (the
// compiler does not vectorise the max under default floating-point semantics); the scalar tail
// performs the same operations in the same order, so lanes and tail agree bit for bit.
void addFeatureTerm(float* __restrict e, const float* __restrict fp, const float* __restrict fq,
                    const float* __restrict vp, const float* __restrict vq, int n) {
  int i = 0;
#if defined(__SSE2__)
  const __m128 floor = _mm_set1_ps(kVarianceFloor), one = _mm_set1_ps(1.0f);
  for (; i + 4 <= n; i += 4) {
    const __m128 d = _mm_sub_ps(_mm_loadu_ps(fp + i), _mm_loadu_ps(fq + i));
    const __m128 v = _mm_max_ps(_mm_add_ps(_mm_loadu_ps(vp + i), _mm_loadu_ps(vq + i)), floor);
    const __m128 term = _mm_mul_ps(_mm_mul_ps(d, d), _mm_div_ps(one, v));
    _mm_storeu_ps(e + i, _mm_add_ps(_mm_loadu_ps(e + i), term));
  }
#endif
  for (; i < n; ++i) {
    const float d = fp[i] - fq[i];
    const float v = vp[i] + vq[i];
    e[i] += d * d * (1.0f / (v > kVarianceFloor ? v : kVarianceFloor));
  }
}

int radiusOf(float sigmaS) {
  return sigmaS > 0 ? int(std::lround(2.0 * sigmaS)) : 0;
}

// The weighted sums of one filtering pass: for every candidate (spatial σ) and data plane
// Σ w data, Σ w, and with the colour range term the two sums its derivative needs.
struct PassOutput {
  std::vector<PlanarImage> sums;       // per candidate: one plane per data plane
  std::vector<PlanarImage> weightSum;  // per candidate: 1 plane
  std::vector<PlanarImage> rangeA;     // per candidate: Σ w t_c c_c(q), t_c = 2Δ_c / den_c
  std::vector<PlanarImage> rangeB;     // per candidate: Σ w t_c
};

struct PassInput {
  const PlanarImage* data;
  const FeatureGuide* guide;
  std::vector<float> sigmaS;
  const PlanarImage* rangeVariance = nullptr;  // colour range term on `data` when set
  float sigmaC = 0;
};

// Per-task scratch, allocated once per task (never per pixel).
struct Scratch {
  std::vector<float> exponent, weight;
  std::vector<std::vector<float>> t;  // per range channel
  std::vector<std::vector<float>> sums, weightSum, rangeA, rangeB;
};

void runPass(const PassInput& in, PassOutput& out) {
  const PlanarImage& data = *in.data;
  const FeatureGuide& guide = *in.guide;
  const int w = data.width(), h = data.height(), planes = data.channels();
  const int features = guide.value.channels();
  const bool range = in.rangeVariance != nullptr;
  const int rangeChannels = range ? planes : 0;
  const int candidates = int(in.sigmaS.size());

  // Spatial Gaussian per candidate and offset, over the largest window.
  std::vector<int> radius(static_cast<size_t>(candidates));
  int maxRadius = 0;
  for (int s = 0; s < candidates; ++s) {
    radius[size_t(s)] = radiusOf(in.sigmaS[size_t(s)]);
    maxRadius = std::max(maxRadius, radius[size_t(s)]);
  }
  const int side = 2 * maxRadius + 1;
  std::vector<std::vector<float>> spatial(size_t(candidates),
                                          std::vector<float>(size_t(side * side)));
  for (int s = 0; s < candidates; ++s)
    for (int dy = -maxRadius; dy <= maxRadius; ++dy)
      for (int dx = -maxRadius; dx <= maxRadius; ++dx) {
        const float sigma = in.sigmaS[size_t(s)];
        const double d2 = double(dx * dx + dy * dy);
        spatial[size_t(s)][size_t((dy + maxRadius) * side + dx + maxRadius)] =
            sigma > 0 ? float(std::exp(-d2 / (2.0 * sigma * sigma))) : (d2 == 0 ? 1.0f : 0.0f);
      }

  out.sums.assign(size_t(candidates), PlanarImage(w, h, planes));
  out.weightSum.assign(size_t(candidates), PlanarImage(w, h, 1));
  if (range) {
    out.rangeA.assign(size_t(candidates), PlanarImage(w, h, planes));
    out.rangeB.assign(size_t(candidates), PlanarImage(w, h, planes));
  }
  const float twoSigmaC2 = 2.0f * in.sigmaC * in.sigmaC;
  const int tilesPerRow = (w + kBilateralTileWidth - 1) / kBilateralTileWidth;

  // Largest feature variance per row tile, over the tile widened by the window radius.
  std::vector<std::vector<float>> tileMaxVariance(size_t(features),
                                                  std::vector<float>(size_t(h * tilesPerRow)));
  tbb::parallel_for(0, h, [&](int y) {
    for (int k = 0; k < features; ++k)
      for (int t = 0; t < tilesPerRow; ++t) {
        const float* v = guide.variance.row(k, y);
        const int lo = std::max(0, t * kBilateralTileWidth - maxRadius);
        const int hi = std::min(w, (t + 1) * kBilateralTileWidth + maxRadius);
        tileMaxVariance[size_t(k)][size_t(y * tilesPerRow + t)] = *std::max_element(v + lo, v + hi);
      }
  });

  tbb::parallel_for(
      tbb::blocked_range<int>(0, h * tilesPerRow), [&](const tbb::blocked_range<int>& tiles) {
        const FlushDenormals flush;  // tiny weights × the spatial Gaussian would be denormal
        Scratch s;
        s.exponent.resize(kBilateralTileWidth);
        s.weight.resize(kBilateralTileWidth);
        s.t.assign(size_t(rangeChannels), std::vector<float>(kBilateralTileWidth));
        const size_t accPlanes = size_t(candidates * planes);
        s.sums.assign(accPlanes, std::vector<float>(kBilateralTileWidth));
        s.weightSum.assign(size_t(candidates), std::vector<float>(kBilateralTileWidth));
        s.rangeA.assign(range ? accPlanes : 0, std::vector<float>(kBilateralTileWidth));
        s.rangeB.assign(range ? accPlanes : 0, std::vector<float>(kBilateralTileWidth));

        for (int tile = tiles.begin(); tile < tiles.end(); ++tile) {
          const int y = tile / tilesPerRow, tileX = tile % tilesPerRow;
          const int x0 = tileX * kBilateralTileWidth, x1 = std::min(w, x0 + kBilateralTileWidth);
          for (auto* group : {&s.sums, &s.weightSum, &s.rangeA, &s.rangeB})
            for (auto& v : *group) std::fill(v.begin(), v.end(), 0.0f);

          for (int dy = -maxRadius; dy <= maxRadius; ++dy) {
            const int qy = y + dy;
            if (qy < 0 || qy >= h) continue;
            for (int dx = -maxRadius; dx <= maxRadius; ++dx) {
              const int xs = std::max(x0, -dx), xe = std::min(x1, w - dx);
              if (xs >= xe) continue;
              const int n = xe - xs, base = xs - x0;
              const int chebyshev = std::max(std::abs(dx), std::abs(dy));
              float* __restrict e = s.exponent.data();
              float* __restrict wt = s.weight.data();

              // Feature term d² · (1 / max(v_p + v_q, floor)). Where both rows' variances are
              // small enough the reciprocal is the constant 1/floor: skip the divisions (same
              // bits).
              std::fill(e, e + n, 0.0f);
              for (int k = 0; k < features; ++k) {
                const float* __restrict fp = guide.value.row(k, y) + xs;
                const float* __restrict fq = guide.value.row(k, qy) + xs + dx;
                const float* maxVariance = tileMaxVariance[size_t(k)].data() + tileX;
                if (maxVariance[y * tilesPerRow] + maxVariance[qy * tilesPerRow] <=
                    kVarianceFloor) {
                  for (int i = 0; i < n; ++i) {
                    const float d = fp[i] - fq[i];
                    e[i] += d * d * kInverseFloor;
                  }
                  continue;
                }
                addFeatureTerm(e, fp, fq, guide.variance.row(k, y) + xs,
                               guide.variance.row(k, qy) + xs + dx, n);
              }
              // Colour range term, remembering t_c = 2Δ_c / den_c for the derivative.
              for (int c = 0; c < rangeChannels; ++c) {
                const float* __restrict cp = data.row(c, y) + xs;
                const float* __restrict cq = data.row(c, qy) + xs + dx;
                const float* __restrict vp = in.rangeVariance->row(c, y) + xs;
                const float* __restrict vq = in.rangeVariance->row(c, qy) + xs + dx;
                float* __restrict t = s.t[size_t(c)].data();
                for (int i = 0; i < n; ++i) {
                  const float d = cp[i] - cq[i];
                  const float den = twoSigmaC2 * (vp[i] + vq[i]) + kRangeEpsilon;
                  const float inv = 1.0f / den;
                  e[i] += d * d * inv;
                  t[i] = 2.0f * d * inv;
                }
              }
              fastExpNegated(e, wt, n);

              // Accumulate into every candidate whose window contains this offset.
              for (int cand = 0; cand < candidates; ++cand) {
                if (chebyshev > radius[size_t(cand)]) continue;
                const float g =
                    spatial[size_t(cand)][size_t((dy + maxRadius) * side + dx + maxRadius)];
                float* __restrict ws = s.weightSum[size_t(cand)].data() + base;
                for (int i = 0; i < n; ++i) ws[i] += g * wt[i];
                for (int c = 0; c < planes; ++c) {
                  const float* __restrict q = data.row(c, qy) + xs + dx;
                  float* __restrict acc = s.sums[size_t(cand * planes + c)].data() + base;
                  for (int i = 0; i < n; ++i) acc[i] += g * wt[i] * q[i];
                  if (!range) continue;
                  const float* __restrict t = s.t[size_t(c)].data();
                  float* __restrict a = s.rangeA[size_t(cand * planes + c)].data() + base;
                  float* __restrict b = s.rangeB[size_t(cand * planes + c)].data() + base;
                  for (int i = 0; i < n; ++i) {
                    const float gwt = g * wt[i] * t[i];
                    a[i] += gwt * q[i];
                    b[i] += gwt;
                  }
                }
              }
            }
          }
          // Store this tile.
          const int len = x1 - x0;
          for (int cand = 0; cand < candidates; ++cand) {
            std::copy_n(s.weightSum[size_t(cand)].data(), len,
                        out.weightSum[size_t(cand)].row(0, y) + x0);
            for (int c = 0; c < planes; ++c) {
              const size_t i = size_t(cand * planes + c);
              std::copy_n(s.sums[i].data(), len, out.sums[size_t(cand)].row(c, y) + x0);
              if (!range) continue;
              std::copy_n(s.rangeA[i].data(), len, out.rangeA[size_t(cand)].row(c, y) + x0);
              std::copy_n(s.rangeB[i].data(), len, out.rangeB[size_t(cand)].row(c, y) + x0);
            }
          }
        }
      });
}

void checkShapes(const PlanarImage& data, const FeatureGuide& guide) {
  if (guide.value.width() != data.width() || guide.value.height() != data.height() ||
      guide.variance.width() != data.width() || guide.variance.height() != data.height() ||
      guide.variance.channels() != guide.value.channels())
    throw std::invalid_argument("cross-bilateral: guide and image differ in size");
}

}  // namespace

std::vector<BilateralCandidate> crossBilateralCandidates(const PlanarImage& color,
                                                         const PlanarImage& colorVariance,
                                                         const FeatureGuide& guide,
                                                         std::span<const float> sigmaS,
                                                         float sigmaC) {
  checkShapes(color, guide);
  PassInput in{&color, &guide, std::vector<float>(sigmaS.begin(), sigmaS.end())};
  if (sigmaC > 0) {
    in.rangeVariance = &colorVariance;
    in.sigmaC = sigmaC;
  }
  PassOutput sums;
  runPass(in, sums);

  const int w = color.width(), h = color.height(), planes = color.channels();
  std::vector<BilateralCandidate> out;
  for (size_t cand = 0; cand < sigmaS.size(); ++cand) {
    BilateralCandidate result{PlanarImage(w, h, planes), PlanarImage(w, h, planes)};
    const float* weightSum = sums.weightSum[cand].plane(0);
    for (int c = 0; c < planes; ++c) {
      const float* sum = sums.sums[cand].plane(c);
      float* filtered = result.filtered.plane(c);
      float* derivative = result.derivative.plane(c);
      for (size_t i = 0; i < color.pixelCount(); ++i) {
        // Σw ≥ 1: the centre pixel is always in the window with weight 1.
        const float inverse = 1.0f / weightSum[i];
        filtered[i] = sum[i] * inverse;
        // ∂F/∂c(p) = w_p/W − (Σ w t c(q) − F Σ w t)/W, w_p = 1 (see header).
        derivative[i] = inverse;
        if (in.rangeVariance)
          derivative[i] -=
              (sums.rangeA[cand].plane(c)[i] - filtered[i] * sums.rangeB[cand].plane(c)[i]) *
              inverse;
      }
    }
    out.push_back(std::move(result));
  }
  return out;
}

PlanarImage crossBilateralSmooth(const PlanarImage& maps, const FeatureGuide& guide, float sigmaS) {
  checkShapes(maps, guide);
  PassOutput sums;
  runPass(PassInput{&maps, &guide, {sigmaS}}, sums);
  PlanarImage out(maps.width(), maps.height(), maps.channels());
  const float* weightSum = sums.weightSum[0].plane(0);
  for (int c = 0; c < maps.channels(); ++c)
    for (size_t i = 0; i < maps.pixelCount(); ++i)
      out.plane(c)[i] = sums.sums[0].plane(c)[i] / weightSum[i];
  return out;
}

}  // namespace chorus
