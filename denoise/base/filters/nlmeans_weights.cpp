#include "denoise/base/filters/nlmeans_weights.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "denoise/base/filters/box_filter.h"
#include "denoise/base/filters/fast_exp.h"
#include "denoise/util/simd_clones.h"

// The row kernels are built for AVX-512F, AVX2 and the baseline (simd_clones.h), without
// contraction into FMA: every build gives the same bits. After the includes, and the kernels
// use no std::min/max: GCC does not inline across different optimisation options.
#pragma GCC optimize("fp-contract=off")

namespace chorus {
namespace {

// The rows a pixel distance reads: guide g, α s V (n) and k² s Vd (d) at p, at p + δ (1) and,
// for the symmetric distance, at p − δ (2).
struct DistanceRows {
  const float *gp, *np, *dp, *g1, *n1, *d1, *g2 = nullptr, *n2 = nullptr, *d2 = nullptr;
};

// d(p, p + δ) for w pixels (see nlmeans_weights.h), clamped; stored, or added to out. Values
// w … wVector − 1 are written as 0 (whole vectors: the planes' margins make the reads safe).
CHORUS_SIMD_CLONES void pairDistanceRow(const DistanceRows& rows, int w, int wVector, float eps,
                                        float clamp, bool centerOnly, bool accumulate,
                                        float* out) {
  float* __restrict o = out;
  const float* __restrict gp = rows.gp;
  const float* __restrict np = rows.np;
  const float* __restrict dp = rows.dp;
  const float* __restrict g1 = rows.g1;
  const float* __restrict n1 = rows.n1;
  const float* __restrict d1 = rows.d1;
  for (int x = 0; x < wVector; ++x) {
    const float diff = gp[x] - g1[x];
    const float num = diff * diff - (np[x] + (np[x] < n1[x] ? np[x] : n1[x]));
    const float den = (centerOnly ? dp[x] + dp[x] : dp[x] + d1[x]) + eps;
    float d = num / den;
    d = d <= clamp ? d : clamp;  // also maps NaN (missing statistics) to the clamp
    d = accumulate ? o[x] + d : d;
    o[x] = x < w ? d : 0.0f;
  }
}

// The distance from p to the mean of p + δ and p − δ; its variance is (V1 + V2) / 4.
CHORUS_SIMD_CLONES void symmetricDistanceRow(const DistanceRows& rows, int w, float eps,
                                             float clamp, bool centerOnly, bool accumulate,
                                             float* out) {
  float* __restrict o = out;
  const float* __restrict gp = rows.gp;
  const float* __restrict np = rows.np;
  const float* __restrict dp = rows.dp;
  const float* __restrict g1 = rows.g1;
  const float* __restrict n1 = rows.n1;
  const float* __restrict d1 = rows.d1;
  const float* __restrict g2 = rows.g2;
  const float* __restrict n2 = rows.n2;
  const float* __restrict d2 = rows.d2;
  for (int x = 0; x < w; ++x) {
    const float diff = gp[x] - 0.5f * (g1[x] + g2[x]);
    const float min1 = np[x] < n1[x] ? np[x] : n1[x], min2 = np[x] < n2[x] ? np[x] : n2[x];
    const float num = diff * diff - (np[x] + 0.25f * (min1 + min2));
    const float den = (centerOnly ? dp[x] + dp[x] : dp[x] + 0.25f * (d1[x] + d2[x])) + eps;
    float d = num / den;
    d = d <= clamp ? d : clamp;
    o[x] = accumulate ? o[x] + d : d;
  }
}

// m = max(m, d) over n values (MinOverChannels: min_c exp(−max(0, D_c)) = exp(−max(0, max_c D_c))).
CHORUS_SIMD_CLONES void maxRow(float* m, const float* d, int n) {
  float* __restrict a = m;
  const float* __restrict b = d;
  for (int x = 0; x < n; ++x) a[x] = a[x] < b[x] ? b[x] : a[x];
}

// w = exp(−max(0, D)) over n values (D clamped to kMaxExpArgument first), then 0 below
// `threshold`. Separate loops, so that each vectorises.
CHORUS_SIMD_CLONES void weightRow(const float* distance, int n, float threshold, float* weights) {
  const float* __restrict d = distance;
  float* __restrict w = weights;
  for (int x = 0; x < n; ++x) {
    const float v = d[x] < 0.0f ? 0.0f : d[x];  // as std::min(std::max(d, 0), kMax)
    w[x] = -(kMaxExpArgument < v ? kMaxExpArgument : v);
  }
  expNonPositiveInPlace(w, size_t(n));
  if (threshold > 0.0f)  // weights are ≥ 0: no threshold, nothing to zero
    for (int x = 0; x < n; ++x) w[x] = w[x] < threshold ? 0.0f : w[x];
}

}  // namespace

NlMeansWeights::NlMeansWeights(std::span<const NlMeansTerm> terms, const NlMeansParams& params)
    : params_(params) {
  if (terms.empty()) throw std::invalid_argument("NlMeansWeights: no terms");
  if (params.r < 0 || params.weightBoxRadius < 0)
    throw std::invalid_argument("NlMeansWeights: negative radius");
  const Image& first = *terms[0].guide;
  width_ = first.width();
  height_ = first.height();
  int perChannel = 0;
  for (const NlMeansTerm& term : terms) {
    if (!term.guide || !term.variance)
      throw std::invalid_argument("NlMeansWeights: term without guide or variance");
    const Image& g = *term.guide;
    const Image& v = *term.variance;
    const Image& vd = term.denominatorVariance ? *term.denominatorVariance : v;
    if (!g.sameSize(first) || !g.sameShape(v) || !g.sameShape(vd))
      throw std::invalid_argument("NlMeansWeights: guide/variance shapes differ");
    if (term.f < 0) throw std::invalid_argument("NlMeansWeights: negative patch radius");
    if (term.channels == ChannelWeights::PerChannel) {
      if (perChannel != 0 && perChannel != g.channels())
        throw std::invalid_argument("NlMeansWeights: per-channel terms with different channels");
      perChannel = g.channels();
    }

    PreparedTerm t;
    t.f = term.f;
    t.channels = term.channels;
    t.epsilon = term.epsilon;
    t.distanceClamp = term.distanceClamp;
    t.centerOnlyDenominator = term.centerOnlyDenominator;
    t.symmetric = term.symmetricRefinement;
    t.refineMinWeight = std::isfinite(term.symmetricDistanceLimit)
                            ? std::exp(-std::max(0.0f, term.symmetricDistanceLimit))
                            : 0.0f;
    const int C = g.channels();
    t.guideChannels = C;
    t.planes = PaddedPlanes(width_, height_, 3 * C, kRowVector);
    const float numScale = term.alpha * term.s, denScale = term.k * term.k * term.s;
    for (int c = 0; c < C; ++c)
      for (int y = 0; y < height_; ++y) {
        float* gp = t.planes.plane(c) + t.planes.index(0, y);
        float* vn = t.planes.plane(C + c) + t.planes.index(0, y);
        float* vdp = t.planes.plane(2 * C + c) + t.planes.index(0, y);
        for (int x = 0; x < width_; ++x) {
          gp[x] = g(x, y, c);
          vn[x] = v(x, y, c);
          vdp[x] = vd(x, y, c);
          // Missing statistics: the pixel matches nothing (its distance becomes the clamp).
          if (!std::isfinite(gp[x]) || !std::isfinite(vn[x]) || !std::isfinite(vdp[x])) {
            gp[x] = std::numeric_limits<float>::quiet_NaN();
            vn[x] = vdp[x] = 0.0f;
            continue;
          }
          vn[x] = std::max(0.0f, vn[x]) * numScale;
          vdp[x] = std::max(0.0f, vdp[x]) * denScale;
        }
      }
    anySymmetric_ = anySymmetric_ || t.symmetric;
    terms_.push_back(std::move(t));
  }
  weightChannels_ = perChannel == 0 ? 1 : perChannel;
  fused_ = terms_.size() == 1 && !anySymmetric_ && params_.weightBoxRadius == 0 &&
           terms_[0].f <= box_kernels::kMaxDirectRadius;
}

int NlMeansWeights::distanceChannels(int term) const {
  const PreparedTerm& t = terms_.at(size_t(term));
  return t.channels == ChannelWeights::AverageDistance ? 1 : t.guideChannels;
}

void NlMeansWeights::distanceRow(const PreparedTerm& t, int c, int y, int x0, int w, int wVector,
                                 int dx, int dy, bool accumulate, bool symmetric, float* out) {
  DistanceRows rows{.gp = t.guideRow(c, y) + x0,
                    .np = t.numRow(c, y) + x0,
                    .dp = t.denRow(c, y) + x0,
                    .g1 = t.guideRow(c, y + dy) + x0 + dx,
                    .n1 = t.numRow(c, y + dy) + x0 + dx,
                    .d1 = t.denRow(c, y + dy) + x0 + dx};
  if (!symmetric) {
    pairDistanceRow(rows, w, wVector, t.epsilon, t.distanceClamp, t.centerOnlyDenominator,
                    accumulate, out);
    return;
  }
  rows.g2 = t.guideRow(c, y - dy) + x0 - dx;
  rows.n2 = t.numRow(c, y - dy) + x0 - dx;
  rows.d2 = t.denRow(c, y - dy) + x0 - dx;
  symmetricDistanceRow(rows, w, t.epsilon, t.distanceClamp, t.centerOnlyDenominator, accumulate,
                       out);
}

void NlMeansWeights::pixelDistances(const PreparedTerm& t, const PixelRect& e, int dx, int dy,
                                    bool average, bool symmetric, float* out) const {
  const int w = e.width(), channels = t.guideChannels;
  const size_t area = size_t(e.area());
  for (int c = 0; c < channels; ++c)
    for (int y = e.y0; y < e.y1; ++y)
      distanceRow(t, c, y, e.x0, w, w, dx, dy, average && c > 0, symmetric,
                  out + (average ? 0 : size_t(c) * area) + size_t(y - e.y0) * size_t(w));
  if (average && channels > 1) {
    const float inv = 1.0f / float(channels);
    for (size_t i = 0; i < area; ++i) out[i] *= inv;
  }
}

void NlMeansWeights::termPatchDistance(const PreparedTerm& t, const PixelRect& region, int dx,
                                       int dy, bool symmetric, NlMeansScratch& scratch,
                                       float* out) const {
  if (region.empty()) return;
  PixelRect e = region.grown(t.f)
                    .intersect(PixelRect::image(width_, height_))
                    .intersect(neighbourInside(width_, height_, dx, dy));
  if (symmetric) e = e.intersect(neighbourInside(width_, height_, -dx, -dy));
  const bool average = t.channels == ChannelWeights::AverageDistance;
  const int planes = average ? 1 : t.guideChannels;
  const size_t eArea = size_t(e.area());
  scratch.pixelDistance.resize(eArea * size_t(planes));
  pixelDistances(t, e, dx, dy, average, symmetric, scratch.pixelDistance.data());
  const size_t rArea = size_t(region.area());
  const PixelRect crop = region.shifted(-e.x0, -e.y0);
  for (int c = 0; c < planes; ++c)
    boxFilterCrop(scratch.pixelDistance.data() + size_t(c) * eArea, e.width(), e.height(), t.f,
                  crop, out + size_t(c) * rArea, scratch.boxTmp);
}

void NlMeansWeights::patchDistance(int term, const PixelRect& region, int dx, int dy,
                                   NlMeansScratch& scratch, float* out) const {
  const PixelRect valid = neighbourInside(width_, height_, dx, dy);
  if (region.intersect(valid) != region)
    throw std::invalid_argument("patchDistance: region has pixels whose neighbour is outside");
  termPatchDistance(terms_.at(size_t(term)), region, dx, dy, false, scratch, out);
}

void NlMeansWeights::symmetricPatchDistance(int term, const PixelRect& region, int dx, int dy,
                                            NlMeansScratch& scratch, float* out) const {
  const PixelRect valid = neighbourInside(width_, height_, dx, dy)
                              .intersect(neighbourInside(width_, height_, -dx, -dy));
  if (region.intersect(valid) != region)
    throw std::invalid_argument(
        "symmetricPatchDistance: region has pixels whose neighbours are outside");
  termPatchDistance(terms_.at(size_t(term)), region, dx, dy, true, scratch, out);
}

void NlMeansWeights::termWeights(const PreparedTerm& t, const float* distance, size_t area,
                                 float* out) const {
  // First −min(max(0, D), kMaxExpArgument) (weights are exp of it), then the exponential, in
  // separate loops so that both vectorise.
  const int channels = t.guideChannels;
  switch (t.channels) {
    case ChannelWeights::PerChannel:
      for (size_t i = 0; i < area * size_t(channels); ++i)
        out[i] = -std::min(std::max(distance[i], 0.0f), kMaxExpArgument);
      expNonPositiveInPlace(out, area * size_t(channels));
      break;
    case ChannelWeights::MinOverChannels:
      // min_c exp(−max(0, D_c)) = exp(−max(0, max_c D_c))
      for (size_t i = 0; i < area; ++i) out[i] = distance[i];
      for (int c = 1; c < channels; ++c)
        for (size_t i = 0; i < area; ++i) out[i] = std::max(out[i], distance[size_t(c) * area + i]);
      for (size_t i = 0; i < area; ++i) out[i] = -std::min(std::max(out[i], 0.0f), kMaxExpArgument);
      expNonPositiveInPlace(out, area);
      break;
    case ChannelWeights::AverageDistance:
      for (size_t i = 0; i < area; ++i)
        out[i] = -std::min(std::max(distance[i], 0.0f), kMaxExpArgument);
      expNonPositiveInPlace(out, area);
      break;
  }
}

namespace {

int termWeightChannels(ChannelWeights mode, int guideChannels) {
  return mode == ChannelWeights::PerChannel ? guideChannels : 1;
}

// combined = min(combined, term), broadcasting a one-plane term over every plane.
void minInto(float* combined, int combinedPlanes, const float* term, int termPlanes, size_t area) {
  for (int c = 0; c < combinedPlanes; ++c) {
    const float* src = term + (termPlanes == 1 ? 0 : size_t(c) * area);
    float* dst = combined + size_t(c) * area;
    for (size_t i = 0; i < area; ++i) dst[i] = std::min(dst[i], src[i]);
  }
}

}  // namespace

void NlMeansWeights::combinedWeights(const PixelRect& region, int dx, int dy,
                                     NlMeansScratch& scratch, float* out) const {
  const size_t area = size_t(region.area());
  std::fill(out, out + area * size_t(weightChannels_), 1.0f);
  for (const PreparedTerm& t : terms_) {
    const int planes = t.channels == ChannelWeights::AverageDistance ? 1 : t.guideChannels;
    scratch.patchDistance.resize(area * size_t(planes));
    termPatchDistance(t, region, dx, dy, false, scratch, scratch.patchDistance.data());
    const int wPlanes = termWeightChannels(t.channels, t.guideChannels);
    scratch.termPlus.resize(area * size_t(wPlanes));
    termWeights(t, scratch.patchDistance.data(), area, scratch.termPlus.data());
    minInto(out, weightChannels_, scratch.termPlus.data(), wPlanes, area);
  }
}

void NlMeansWeights::finishWeights(float* weights, const PixelRect& region, const PixelRect& tile,
                                   NlMeansScratch& scratch, float* out) const {
  const size_t rArea = size_t(region.area()), tArea = size_t(tile.area());
  const int b = params_.weightBoxRadius;
  const float threshold = params_.weightThreshold;
  const PixelRect inside = tile.intersect(region);
  for (int c = 0; c < weightChannels_; ++c) {
    float* plane = weights + size_t(c) * rArea;
    if (b > 0 && !region.empty())
      boxFilterPlane(plane, plane, region.width(), region.height(), b, scratch.boxTmp);
    float* dst = out + size_t(c) * tArea;
    std::fill(dst, dst + tArea, 0.0f);
    for (int y = inside.y0; y < inside.y1; ++y) {
      const float* src = plane + size_t(y - region.y0) * size_t(region.width());
      float* row = dst + size_t(y - tile.y0) * size_t(tile.width());
      for (int x = inside.x0; x < inside.x1; ++x) {
        const float w = src[x - region.x0];
        row[x - tile.x0] = w < threshold ? 0.0f : w;
      }
    }
  }
}

void NlMeansWeights::fusedOffsetWeights(const PreparedTerm& t, const PixelRect& tile, int dx,
                                        int dy, NlMeansScratch& scratch, float* out) const {
  const size_t tArea = size_t(tile.area());
  const PixelRect valid =
      PixelRect::image(width_, height_).intersect(neighbourInside(width_, height_, dx, dy));
  const PixelRect r = tile.intersect(valid);
  // Weight 0 where the neighbour (or p) is outside the image: the tile minus r.
  const size_t tw = size_t(tile.width());
  for (int c = 0; c < weightChannels_; ++c) {
    float* plane = out + size_t(c) * tArea;
    if (r.empty()) {
      std::fill(plane, plane + tArea, 0.0f);
      continue;
    }
    std::fill(plane, plane + size_t(r.y0 - tile.y0) * tw, 0.0f);
    std::fill(plane + size_t(r.y1 - tile.y0) * tw, plane + tArea, 0.0f);
    if (r.x0 == tile.x0 && r.x1 == tile.x1) continue;
    for (int y = r.y0; y < r.y1; ++y) {
      float* row = plane + size_t(y - tile.y0) * tw;
      std::fill(row, row + (r.x0 - tile.x0), 0.0f);
      std::fill(row + (r.x1 - tile.x0), row + tw, 0.0f);
    }
  }
  if (r.empty()) return;
  const PixelRect e = r.grown(t.f).intersect(valid);
  const bool average = t.channels == ChannelWeights::AverageDistance;
  const int channels = t.guideChannels, planes = average ? 1 : channels, f = t.f;
  const int ring = 2 * f + 1, rw = r.width(), ew = e.width();
  const size_t stride = size_t(box_kernels::roundUp4(rw));
  // The distances of a row go straight into a zero-padded row (pixel x at x − (r.x0 − f)), one
  // per plane, in whole vectors (the planes' margins make the reads safe); the row sums read
  // them only once every plane's row is written, so the stores have left the store buffer.
  const int lead = e.x0 - (r.x0 - f);  // zeros left of e
  const int ewVector = (ew + kRowVector - 1) / kRowVector * kRowVector;
  const size_t paddedSize =
      std::max(size_t(lead + ewVector), size_t(box_kernels::roundUp4(rw + 2 * f) + 4));

  // Scratch: the zero-padded distance rows, the row means of the last 2f + 1 rows (a ring), one
  // row of patch distances and the inverse counts of both axes.
  std::vector<float>& buf = scratch.pixelDistance;
  buf.resize(size_t(planes) * paddedSize + (size_t(ring) + 1) * size_t(planes) * stride + stride +
             size_t(e.height()));
  float* padded = buf.data();
  float* ringRows = padded + size_t(planes) * paddedSize;
  float* patch = ringRows + size_t(ring) * size_t(planes) * stride;
  float* invX = patch + size_t(planes) * stride;
  float* invY = invX + stride;
  std::fill(padded, padded + size_t(planes) * paddedSize, 0.0f);
  // 1 / (true count) of the clipped box: a count is at most 2f + 1, so a table of those.
  float inverse[2 * box_kernels::kMaxDirectRadius + 2];
  for (int k = 1; k <= 2 * f + 1; ++k) inverse[k] = 1.0f / float(k);
  for (int x = 0; x < rw; ++x) {
    const int px = r.x0 - e.x0 + x;
    invX[x] = inverse[std::min(ew - 1, px + f) - std::max(0, px - f) + 1];
  }
  for (int x = rw; x < int(stride); ++x) invX[x] = 0.0f;
  for (int y = 0; y < e.height(); ++y)
    invY[y] = inverse[std::min(e.height() - 1, y + f) - std::max(0, y - f) + 1];
  auto ringRow = [&](int y, int c) {
    return ringRows + (size_t((y - e.y0) % ring) * size_t(planes) + size_t(c)) * stride;
  };

  // One output row of weights from the ring rows [yo − f, yo + f] ∩ e.
  const float threshold = params_.weightThreshold;
  auto emit = [&](int yo) {
    const int a = std::max(e.y0, yo - f), b = std::min(e.y1 - 1, yo + f);
    const float* rows[2 * box_kernels::kMaxDirectRadius + 1];
    for (int c = 0; c < planes; ++c) {
      float* dst = patch + size_t(c) * stride;
      if (f == 0) {
        std::copy(ringRow(yo, c), ringRow(yo, c) + rw, dst);
        continue;
      }
      for (int j = a; j <= b; ++j) rows[j - a] = ringRow(j, c);
      box_kernels::columnSums(rows, b - a + 1, invY[yo - e.y0], dst, rw);
    }
    float* row = out + size_t(yo - tile.y0) * size_t(tile.width()) + size_t(r.x0 - tile.x0);
    if (t.channels == ChannelWeights::PerChannel) {
      for (int c = 0; c < planes; ++c)
        weightRow(patch + size_t(c) * stride, rw, threshold, row + size_t(c) * tArea);
      return;
    }
    for (int c = 1; c < planes; ++c) maxRow(patch, patch + size_t(c) * stride, rw);
    weightRow(patch, rw, threshold, row);
  };

  for (int y = e.y0; y < e.y1; ++y) {
    for (int c = 0; c < channels; ++c)
      distanceRow(t, c, y, e.x0, ew, ewVector, dx, dy, average && c > 0, false,
                  padded + (average ? 0 : size_t(c) * paddedSize) + lead);
    if (average && channels > 1) {
      const float inv = 1.0f / float(channels);
      for (int x = lead; x < lead + ew; ++x) padded[x] *= inv;
    }
    for (int c = 0; c < planes; ++c) {
      const float* src = padded + size_t(c) * paddedSize;
      if (f == 0)
        std::copy(src, src + rw, ringRow(y, c));
      else
        box_kernels::rowSums(src, ringRow(y, c), rw, f, invX);
    }
    const int yo = y - f;
    if (yo >= r.y0 && yo < r.y1) emit(yo);
  }
  for (int yo = std::max(r.y0, e.y1 - f); yo < r.y1; ++yo) emit(yo);
}

void NlMeansWeights::offsetPair(const PixelRect& tile, int dx, int dy, NlMeansScratch& scratch,
                                float* plus, float* minus) const {
  if (fused_) {
    fusedOffsetWeights(terms_[0], tile, dx, dy, scratch, plus);
    fusedOffsetWeights(terms_[0], tile, -dx, -dy, scratch, minus);
    return;
  }
  const PixelRect grown =
      tile.grown(params_.weightBoxRadius).intersect(PixelRect::image(width_, height_));
  const PixelRect rp = grown.intersect(neighbourInside(width_, height_, dx, dy));
  const PixelRect rm = grown.intersect(neighbourInside(width_, height_, -dx, -dy));
  const size_t pArea = size_t(rp.area()), mArea = size_t(rm.area());
  const int wch = weightChannels_;
  scratch.plus.assign(pArea * size_t(wch), 1.0f);
  scratch.minus.assign(mArea * size_t(wch), 1.0f);

  for (const PreparedTerm& t : terms_) {
    const int planes = t.channels == ChannelWeights::AverageDistance ? 1 : t.guideChannels;
    const int wPlanes = termWeightChannels(t.channels, t.guideChannels);
    scratch.patchDistance.resize(std::max(pArea, mArea) * size_t(planes));
    scratch.termPlus.resize(pArea * size_t(wPlanes));
    scratch.termMinus.resize(mArea * size_t(wPlanes));
    termPatchDistance(t, rp, dx, dy, false, scratch, scratch.patchDistance.data());
    termWeights(t, scratch.patchDistance.data(), pArea, scratch.termPlus.data());
    termPatchDistance(t, rm, -dx, -dy, false, scratch, scratch.patchDistance.data());
    termWeights(t, scratch.patchDistance.data(), mArea, scratch.termMinus.data());

    const PixelRect rs = rp.intersect(rm);
    if (t.symmetric && !rs.empty()) {
      const size_t sArea = size_t(rs.area());
      scratch.patchDistance.resize(sArea * size_t(planes));
      scratch.termSymmetric.resize(sArea * size_t(wPlanes));
      termPatchDistance(t, rs, dx, dy, true, scratch, scratch.patchDistance.data());
      termWeights(t, scratch.patchDistance.data(), sArea, scratch.termSymmetric.data());
      const float minW = t.refineMinWeight;
      for (int c = 0; c < wPlanes; ++c) {
        float* wp = scratch.termPlus.data() + size_t(c) * pArea;
        float* wm = scratch.termMinus.data() + size_t(c) * mArea;
        const float* ws = scratch.termSymmetric.data() + size_t(c) * sArea;
        for (int y = rs.y0; y < rs.y1; ++y) {
          float* w1 = wp + size_t(y - rp.y0) * size_t(rp.width()) + (rs.x0 - rp.x0);
          float* w2 = wm + size_t(y - rm.y0) * size_t(rm.width()) + (rs.x0 - rm.x0);
          const float* wsRow = ws + size_t(y - rs.y0) * size_t(rs.width());
          for (int x = 0; x < rs.width(); ++x) {
            if (!(w1[x] >= minW && w2[x] >= minW)) continue;
            const float sum = w1[x] + w2[x], s = wsRow[x];
            const float a =
                sum > 0.0f ? std::clamp(s / sum - 1.0f, 0.0f, 1.0f) : (s > 0.0f ? 1.0f : 0.0f);
            w1[x] = a * s + (1.0f - a) * w1[x];
            w2[x] = a * s + (1.0f - a) * w2[x];
          }
        }
      }
    }
    minInto(scratch.plus.data(), wch, scratch.termPlus.data(), wPlanes, pArea);
    minInto(scratch.minus.data(), wch, scratch.termMinus.data(), wPlanes, mArea);
  }
  finishWeights(scratch.plus.data(), rp, tile, scratch, plus);
  finishWeights(scratch.minus.data(), rm, tile, scratch, minus);
}

void NlMeansWeights::center(const PixelRect& tile, NlMeansScratch& scratch, float* out) const {
  const size_t tArea = size_t(tile.area());
  const size_t n = tArea * size_t(weightChannels_);
  switch (params_.center) {
    case CenterWeight::One:
      std::fill(out, out + n, 1.0f);
      return;
    case CenterWeight::MaxOfNeighbours:
      std::fill(out, out + n, params_.minCenterWeight);
      return;
    case CenterWeight::Computed: {
      const PixelRect region =
          tile.grown(params_.weightBoxRadius).intersect(PixelRect::image(width_, height_));
      scratch.plus.resize(size_t(region.area()) * size_t(weightChannels_));
      combinedWeights(region, 0, 0, scratch, scratch.plus.data());
      finishWeights(scratch.plus.data(), region, tile, scratch, out);
      for (size_t i = 0; i < n; ++i) out[i] = std::max(out[i], params_.minCenterWeight);
      return;
    }
  }
}

}  // namespace chorus
