#include "denoise/base/filters/nlmeans_weights.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "denoise/base/filters/box_filter.h"
#include "denoise/base/filters/fast_exp.h"

namespace chorus {
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
    t.guide = PlanarImage(g);
    t.varianceNum = PlanarImage(v);
    t.varianceDen = PlanarImage(vd);
    const float numScale = term.alpha * term.s, denScale = term.k * term.k * term.s;
    const size_t n = t.guide.pixelCount();
    for (int c = 0; c < g.channels(); ++c) {
      float* gp = t.guide.plane(c);
      float* vn = t.varianceNum.plane(c);
      float* vdp = t.varianceDen.plane(c);
      for (size_t i = 0; i < n; ++i) {
        // Missing statistics: the pixel matches nothing (its distance becomes the clamp).
        if (!std::isfinite(gp[i]) || !std::isfinite(vn[i]) || !std::isfinite(vdp[i])) {
          gp[i] = std::numeric_limits<float>::quiet_NaN();
          vn[i] = vdp[i] = 0.0f;
          continue;
        }
        vn[i] = std::max(0.0f, vn[i]) * numScale;
        vdp[i] = std::max(0.0f, vdp[i]) * denScale;
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
  return t.channels == ChannelWeights::AverageDistance ? 1 : t.guide.channels();
}

void NlMeansWeights::distanceRow(const PreparedTerm& t, int c, int y, int x0, int w, int dx, int dy,
                                 bool accumulate, bool symmetric, float* out) {
  const float eps = t.epsilon, clamp = t.distanceClamp;
  const bool centerOnly = t.centerOnlyDenominator;
  float* __restrict o = out;
  const float* __restrict gp = t.guide.row(c, y) + x0;
  const float* __restrict np = t.varianceNum.row(c, y) + x0;
  const float* __restrict dp = t.varianceDen.row(c, y) + x0;
  const float* __restrict g1 = t.guide.row(c, y + dy) + x0 + dx;
  const float* __restrict n1 = t.varianceNum.row(c, y + dy) + x0 + dx;
  const float* __restrict d1 = t.varianceDen.row(c, y + dy) + x0 + dx;
  if (!symmetric) {
    for (int x = 0; x < w; ++x) {
      const float diff = gp[x] - g1[x];
      const float num = diff * diff - (np[x] + std::min(np[x], n1[x]));
      const float den = (centerOnly ? dp[x] + dp[x] : dp[x] + d1[x]) + eps;
      float d = num / den;
      d = d <= clamp ? d : clamp;  // also maps NaN (missing statistics) to the clamp
      o[x] = accumulate ? o[x] + d : d;
    }
    return;
  }
  const float* __restrict g2 = t.guide.row(c, y - dy) + x0 - dx;
  const float* __restrict n2 = t.varianceNum.row(c, y - dy) + x0 - dx;
  const float* __restrict d2 = t.varianceDen.row(c, y - dy) + x0 - dx;
  for (int x = 0; x < w; ++x) {
    // Distance from p to the mean of its two neighbours; its variance is (V1 + V2) / 4.
    const float diff = gp[x] - 0.5f * (g1[x] + g2[x]);
    const float num =
        diff * diff - (np[x] + 0.25f * (std::min(np[x], n1[x]) + std::min(np[x], n2[x])));
    const float den = (centerOnly ? dp[x] + dp[x] : dp[x] + 0.25f * (d1[x] + d2[x])) + eps;
    float d = num / den;
    d = d <= clamp ? d : clamp;
    o[x] = accumulate ? o[x] + d : d;
  }
}

void NlMeansWeights::pixelDistances(const PreparedTerm& t, const PixelRect& e, int dx, int dy,
                                    bool average, bool symmetric, float* out) const {
  const int w = e.width(), channels = t.guide.channels();
  const size_t area = size_t(e.area());
  for (int c = 0; c < channels; ++c)
    for (int y = e.y0; y < e.y1; ++y)
      distanceRow(t, c, y, e.x0, w, dx, dy, average && c > 0, symmetric,
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
  const int planes = average ? 1 : t.guide.channels();
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
  const int channels = t.guide.channels();
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
    const int planes = t.channels == ChannelWeights::AverageDistance ? 1 : t.guide.channels();
    scratch.patchDistance.resize(area * size_t(planes));
    termPatchDistance(t, region, dx, dy, false, scratch, scratch.patchDistance.data());
    const int wPlanes = termWeightChannels(t.channels, t.guide.channels());
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
  std::fill(out, out + tArea * size_t(weightChannels_), 0.0f);
  const PixelRect valid =
      PixelRect::image(width_, height_).intersect(neighbourInside(width_, height_, dx, dy));
  const PixelRect r = tile.intersect(valid);
  if (r.empty()) return;
  const PixelRect e = r.grown(t.f).intersect(valid);
  const bool average = t.channels == ChannelWeights::AverageDistance;
  const int channels = t.guide.channels(), planes = average ? 1 : channels, f = t.f;
  const int ring = 2 * f + 1, rw = r.width(), ew = e.width();
  const size_t stride = size_t(box_kernels::roundUp4(rw));
  const size_t paddedSize = size_t(box_kernels::roundUp4(rw + 2 * f) + 4);

  // Scratch: one row of pixel distances, a zero-padded row, the row means of the last 2f + 1
  // rows (a ring), one row of patch distances and the inverse counts of both axes.
  std::vector<float>& buf = scratch.pixelDistance;
  buf.resize(size_t(planes) * size_t(ew) + paddedSize +
             (size_t(ring) + 1) * size_t(planes) * stride + stride + size_t(e.height()));
  float* rowDistance = buf.data();
  float* padded = rowDistance + size_t(planes) * size_t(ew);
  float* ringRows = padded + paddedSize;
  float* patch = ringRows + size_t(ring) * size_t(planes) * stride;
  float* invX = patch + size_t(planes) * stride;
  float* invY = invX + stride;
  std::fill(padded, padded + paddedSize, 0.0f);
  for (int x = 0; x < rw; ++x) {
    const int px = r.x0 - e.x0 + x;
    invX[x] = 1.0f / float(std::min(ew - 1, px + f) - std::max(0, px - f) + 1);
  }
  for (int x = rw; x < int(stride); ++x) invX[x] = 0.0f;
  for (int y = 0; y < e.height(); ++y)
    invY[y] = 1.0f / float(std::min(e.height() - 1, y + f) - std::max(0, y - f) + 1);
  auto ringRow = [&](int y, int c) {
    return ringRows + (size_t((y - e.y0) % ring) * size_t(planes) + size_t(c)) * stride;
  };
  const int copyBegin = std::max(e.x0, r.x0 - f), copyEnd = std::min(e.x1, r.x1 + f);

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
    auto finish = [&](float* w, int n) {
      expNonPositiveInPlace(w, size_t(n));
      for (int x = 0; x < n; ++x) w[x] = w[x] < threshold ? 0.0f : w[x];
    };
    if (t.channels == ChannelWeights::PerChannel) {
      for (int c = 0; c < planes; ++c) {
        float* w = row + size_t(c) * tArea;
        const float* d = patch + size_t(c) * stride;
        for (int x = 0; x < rw; ++x) w[x] = -std::min(std::max(d[x], 0.0f), kMaxExpArgument);
        finish(w, rw);
      }
      return;
    }
    float* m = patch;  // MinOverChannels: max_c D_c, in channel order
    for (int c = 1; c < planes; ++c)
      for (int x = 0; x < rw; ++x) m[x] = std::max(m[x], patch[size_t(c) * stride + size_t(x)]);
    for (int x = 0; x < rw; ++x) row[x] = -std::min(std::max(m[x], 0.0f), kMaxExpArgument);
    finish(row, rw);
  };

  for (int y = e.y0; y < e.y1; ++y) {
    for (int c = 0; c < channels; ++c)
      distanceRow(t, c, y, e.x0, ew, dx, dy, average && c > 0, false,
                  rowDistance + (average ? 0 : size_t(c) * size_t(ew)));
    if (average && channels > 1) {
      const float inv = 1.0f / float(channels);
      for (int x = 0; x < ew; ++x) rowDistance[x] *= inv;
    }
    for (int c = 0; c < planes; ++c) {
      const float* src = rowDistance + size_t(c) * size_t(ew);
      if (f == 0) {
        std::copy(src + (r.x0 - e.x0), src + (r.x0 - e.x0) + rw, ringRow(y, c));
        continue;
      }
      std::copy(src + (copyBegin - e.x0), src + (copyEnd - e.x0),
                padded + (copyBegin - (r.x0 - f)));
      box_kernels::rowSums(padded, ringRow(y, c), rw, f, invX);
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
    const int planes = t.channels == ChannelWeights::AverageDistance ? 1 : t.guide.channels();
    const int wPlanes = termWeightChannels(t.channels, t.guide.channels());
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
