#include "denoise/base/rdfc/rdfc_candidates.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "denoise/base/buffer_variance.h"
#include "denoise/base/filters/bordered_planes.h"
#include "denoise/base/filters/nlmeans_row_kernels.h"
#include "denoise/base/filters/pixel_rect.h"
#include "denoise/base/filters/rect_mask.h"
#include "denoise/base/filters/sure.h"
#include "denoise/util/float_lanes.h"
#include "denoise/util/padded_stride.h"
#include "denoise/util/parallel_rows.h"

namespace chorus {
namespace {

// Wide, short tiles: each row-kernel call covers 256 pixels, which spreads the per-call overhead,
// and the rows read at p ± δ for one dy (in every plane) stay in L2 across the dx loop
// (candidates 24.6 CPU s/Mpx at 128 × 16, 21.8 at 256 × 8, 22.0 at 512 × 8, 23.1 at 128 × 8 and
// at 256 × 4 on the synthetic 512² case). 16 rows: the margin rows' colour distances and patch
// sums favour taller tiles (−2.6% instructions from 16 to 32), but the tile's ~80 planes then
// outgrow L2 (32 rows 2–4% slower in A/B runs, 8 rows 1–3%).
constexpr int kCandidateTileWidth = 256, kCandidateTileHeight = 16;
constexpr float kSymmetricLimit = 25.0f;  // refine only where both distances are below this
constexpr int kColor = 2;                 // FIRST and SECOND have a colour term
enum Kind { kPlus, kMinus, kSym };

struct TileMemory {
  // Validity masks of this offset: plus, minus, sym, behind (p−δ, p−2δ), ahead (p+δ, p+2δ);
  // `ones` where every pixel of the tile has its pair.
  std::vector<float> maskStore[5], ones;
  const float* mask[5] = {};
  std::vector<float> featPlus[2], featMinus[2];  // feature weights, τ sets FIRST/SECOND, THIRD
  std::vector<float> ext[3];                     // colour pixel distances over the grown tile
  std::vector<float> rowSums, invCountX;         // box filter: horizontal sums, 1 / x counts
  std::vector<float> innerSums, invY, running;   // the narrower patch's sums, 1 / y counts
  std::vector<float> dist[kColor][3], invCountStore[kColor][3];
  std::vector<float> fullInvCountX[kColor], fullInvCount[kColor];  // boxes inside the image
  const float* invCount[kColor][3] = {};                           // 1 / box counts of this offset
  std::vector<float> slope[3][3], nearSlope[3][3];                 // [channel][kind]
  // Accumulators, per candidate: Σw, max w, Σ w b1 (3 planes), Σ w b2 (3 planes); per colour
  // candidate and channel of y(p): Σ ∂w, Σ ∂w y(q), ∂(max w).
  std::vector<float> weightSum[3], maxWeight[3], acc[3];
  std::vector<float> derivativeSum[kColor], derivativeAcc[kColor], maxDerivative[kColor];
  size_t planeStride = 0;  // between the planes of acc and of the derivative sums
};

class CandidateKernel {
 public:
  CandidateKernel(const Image& b1, const Image& b2, const Image& variance,
                  const std::vector<RdfcFeature>& features, const RdfcCandidateParams& params);
  std::array<RdfcCandidate, 3> run() const;

 private:
  struct Outputs {
    std::array<Image, 3> buffer1, buffer2, derivative;
  };
  void runTile(const PixelRect& tile, TileMemory& m, Outputs& out) const;
  void masks(const PixelRect& tile, int dx, int dy, TileMemory& m) const;
  void featureWeights(const PixelRect& tile, int dx, int dy, TileMemory& m) const;
  void colorDistances(const PixelRect& tile, int dx, int dy, TileMemory& m) const;
  void accumulate(const PixelRect& tile, int dx, int dy, TileMemory& m) const;
  void finishTile(const PixelRect& tile, const TileMemory& m, Outputs& out) const;

  int width_, height_, pad_, grow_;
  RdfcCandidateParams params_;
  int patch_[kColor];
  float refineMinWeight_;
  Image guide_, variance_;
  BorderedPlanes b1_, b2_, g_, vn_, vd_;
  // Features: one plane per channel of every feature, its term's channel range. The
  // denominators of the two τ sets are max(k_f² max(Var, G), floor) (k_f² is positive, so
  // scaling commutes with the max): one plane for both, a floor per term and set.
  BorderedPlanes fValue_, fNum_, fDen_;
  std::vector<int> termBegin_;
  std::vector<float> termFloor_[2];
};

CandidateKernel::CandidateKernel(const Image& b1, const Image& b2, const Image& variance,
                                 const std::vector<RdfcFeature>& features,
                                 const RdfcCandidateParams& params)
    : width_(b1.width()),
      height_(b1.height()),
      params_(params),
      patch_{params.fFirst, params.fSecond},
      refineMinWeight_(std::exp(-kSymmetricLimit)),
      variance_(variance) {
  if (!b1.sameShape(b2) || !b1.sameShape(variance) || b1.channels() != 3)
    throw std::invalid_argument("rdfcCandidates: buffers and variance must be RGB of one size");
  if (params.r < 1 || params.fFirst < 0 || params.fSecond < 0)
    throw std::invalid_argument("rdfcCandidates: bad radius");
  grow_ = std::max(params.fFirst, params.fSecond);
  pad_ = 2 * params.r + grow_ + 1;
  guide_ = meanOf(b1, b2);
  for (BorderedPlanes* p : {&b1_, &b2_, &g_, &vn_, &vd_})
    *p = BorderedPlanes(width_, height_, 3, pad_);
  for (int c = 0; c < 3; ++c) {
    b1_.set(c, b1, c, 1.0f);
    b2_.set(c, b2, c, 1.0f);
    g_.set(c, guide_, c, 1.0f);
    vn_.set(c, variance, c, 1.0f);  // α = 1
    vd_.set(c, variance, c, params.kc * params.kc);
  }

  int channels = 0;
  for (const RdfcFeature& f : features) {
    if (f.value.channels() < 1 || f.value.channels() > 4)
      throw std::invalid_argument("rdfcCandidates: features have 1 to 4 channels");
    termBegin_.push_back(channels);
    channels += f.value.channels();
  }
  termBegin_.push_back(channels);
  for (BorderedPlanes* p : {&fValue_, &fNum_, &fDen_})
    *p = BorderedPlanes(width_, height_, channels, pad_);
  const float kf2 = params.kf * params.kf;
  for (size_t j = 0; j < features.size(); ++j) {
    const RdfcFeature& f = features[j];
    // Vn without the τ floor: RDFC's normalizing variance with τ = 0 (kNeutralVariance where
    // unknown, which stays above every floor).
    const Image unfloored = f.normalizingVariance(0.0f);
    for (int c = 0; c < f.value.channels(); ++c) {
      const int k = termBegin_[j] + c;
      fValue_.set(k, f.value, c, 1.0f);
      fNum_.set(k, f.variance, c, 1.0f);  // α = 1
      fDen_.set(k, unfloored, c, kf2);
    }
    termFloor_[0].push_back(kf2 * (params.tauFirstSecond * f.tauScale));
    termFloor_[1].push_back(kf2 * (params.tauThird * f.tauScale));
  }
}

void CandidateKernel::masks(const PixelRect& tile, int dx, int dy, TileMemory& m) const {
  const PixelRect plus = neighbourInside(width_, height_, dx, dy);
  const PixelRect minus = neighbourInside(width_, height_, -dx, -dy);
  const PixelRect valid[5] = {plus, minus, plus.intersect(minus),
                              minus.intersect(neighbourInside(width_, height_, -2 * dx, -2 * dy)),
                              plus.intersect(neighbourInside(width_, height_, 2 * dx, 2 * dy))};
  for (int k = 0; k < 5; ++k)
    m.mask[k] = rectMaskOrOnes(tile, valid[k], m.maskStore[k], m.ones.data());
}

void CandidateKernel::featureWeights(const PixelRect& tile, int dx, int dy, TileMemory& m) const {
  const int tw = tile.width(), x0 = tile.x0;
  const size_t area = size_t(tile.area());
  for (int set = 0; set < 2; ++set) {
    std::fill(m.featPlus[set].begin(), m.featPlus[set].begin() + ptrdiff_t(area), 1.0f);
    std::fill(m.featMinus[set].begin(), m.featMinus[set].begin() + ptrdiff_t(area), 1.0f);
  }
  const size_t stride = fValue_.planeStride();
  for (int y = tile.y0; y < tile.y1; ++y) {
    const size_t row = size_t(y - tile.y0) * size_t(tw);
    for (size_t term = 0; term + 1 < termBegin_.size(); ++term) {
      const int k = termBegin_[term];
      rows::featureTermWeights(
          tw, termBegin_[term + 1] - k, stride, fValue_.row(k, y) + x0,
          fValue_.row(k, y + dy) + x0 + dx, fValue_.row(k, y - dy) + x0 - dx, fNum_.row(k, y) + x0,
          fNum_.row(k, y + dy) + x0 + dx, fNum_.row(k, y - dy) + x0 - dx, fDen_.row(k, y) + x0,
          fDen_.row(k, y + dy) + x0 + dx, fDen_.row(k, y - dy) + x0 - dx, termFloor_[0][term],
          termFloor_[1][term], m.mask[kSym] + row, refineMinWeight_, m.featPlus[0].data() + row,
          m.featMinus[0].data() + row, m.featPlus[1].data() + row, m.featMinus[1].data() + row);
    }
  }
  for (int set = 0; set < 2; ++set) {
    multiplyByMask(m.featPlus[set].data(), area, m.mask[kPlus], m.ones.data());
    multiplyByMask(m.featMinus[set].data(), area, m.mask[kMinus], m.ones.data());
  }
}

void CandidateKernel::colorDistances(const PixelRect& tile, int dx, int dy, TileMemory& m) const {
  const int tw = tile.width(), th = tile.height(), G = grow_;
  const int ex0 = tile.x0 - G, ey0 = tile.y0 - G, ew = tw + 2 * G, eh = th + 2 * G;
  for (int ey = 0; ey < eh; ++ey) {
    const int y = ey0 + ey;
    const bool tileRow = y >= tile.y0 && y < tile.y1;
    for (int c = 0; c < 3; ++c) {
      // Segments of the grown row: left margin, tile columns (with the slopes), right margin.
      const int bounds[4] = {ex0, tile.x0, tile.x1, ex0 + ew};
      for (int seg = 0; seg < 3; ++seg) {
        const int xa = bounds[seg], n = bounds[seg + 1] - xa;
        if (n <= 0) continue;
        const size_t e = size_t(ey) * size_t(ew) + size_t(xa - ex0);
        const bool withSlope = tileRow && seg == 1;
        const size_t t = size_t(y - tile.y0) * size_t(tw);
        rows::addColorDistances(
            n, g_.row(c, y) + xa, g_.row(c, y + dy) + xa + dx, g_.row(c, y - dy) + xa - dx,
            vn_.row(c, y) + xa, vn_.row(c, y + dy) + xa + dx, vn_.row(c, y - dy) + xa - dx,
            vd_.row(c, y) + xa, vd_.row(c, y + dy) + xa + dx, vd_.row(c, y - dy) + xa - dx,
            1.0f / 3.0f, 0.25f, c == 0, m.ext[kPlus].data() + e, m.ext[kMinus].data() + e,
            m.ext[kSym].data() + e, withSlope ? m.slope[c][kPlus].data() + t : nullptr,
            withSlope ? m.slope[c][kMinus].data() + t : nullptr,
            withSlope ? m.slope[c][kSym].data() + t : nullptr);
      }
    }
  }
  // Pixels whose pair does not exist contribute nothing to the patch sums. Valid pixels of each
  // kind form a rectangle [loX, hiX) × [loY, hiY).
  const int W = width_, H = height_, adx = std::abs(dx), ady = std::abs(dy);
  const int loX[3] = {std::max(0, -dx), std::max(0, dx), adx};
  const int hiX[3] = {std::min(W, W - dx), std::min(W, W + dx), W - adx};
  const int loY[3] = {std::max(0, -dy), std::max(0, dy), ady};
  const int hiY[3] = {std::min(H, H - dy), std::min(H, H + dy), H - ady};
  for (int kind = 0; kind < 3; ++kind)
    for (int ey = 0; ey < eh; ++ey) {
      float* row = m.ext[kind].data() + size_t(ey) * size_t(ew);
      const int y = ey0 + ey;
      if (y < loY[kind] || y >= hiY[kind]) {
        std::fill(row, row + ew, 0.0f);
        continue;
      }
      const int a = std::clamp(loX[kind] - ex0, 0, ew), b = std::clamp(hiX[kind] - ex0, 0, ew);
      std::fill(row, row + a, 0.0f);
      std::fill(row + std::max(a, b), row + ew, 0.0f);
    }

  // Patch means for both patch radii: box sums over the valid pixels × 1 / their count. Where
  // every box of the tile lies inside the valid pixels, the counts are those of the full patch
  // (planes filled once per tile).
  auto patchMeans = [&](int s, int kind, const float* sums, size_t stride) {
    const int f = patch_[s];
    const bool full = tile.x0 - f >= loX[kind] && tile.x1 + f <= hiX[kind] &&
                      tile.y0 - f >= loY[kind] && tile.y1 + f <= hiY[kind];
    const float* invX = m.fullInvCountX[s].data();
    if (!full) {
      for (int i = 0; i < tw; ++i) {
        const int nx = boxOverlap(tile.x0 + i, f, loX[kind], hiX[kind]);
        m.invCountX[size_t(i)] = nx > 0 ? 1.0f / float(nx) : 0.0f;
      }
      invX = m.invCountX.data();
    }
    m.invCount[s][kind] = full ? m.fullInvCount[s].data() : m.invCountStore[s][kind].data();
    for (int y = tile.y0; y < tile.y1; ++y) {
      const int ny = boxOverlap(y, f, loY[kind], hiY[kind]);
      const float invY = ny > 0 ? 1.0f / float(ny) : 0.0f;
      m.invY[size_t(y - tile.y0)] = invY;
      if (!full) {
        float* inv = m.invCountStore[s][kind].data() + size_t(y - tile.y0) * size_t(tw);
        for (int i = 0; i < tw; ++i) inv[i] = invY * invX[i];
      }
    }
    // The 7-row boxes slide down the tile; 3 rows are summed directly (as cheap).
    if (2 * f + 1 > 3) {
      rows::runningBoxMeans(tw, th, sums, stride, 2 * f + 1, m.invY.data(), invX, m.running.data(),
                            m.dist[s][kind].data(), size_t(tw));
      return;
    }
    for (int y = tile.y0; y < tile.y1; ++y)
      rows::verticalBoxMean(tw, sums + size_t(y - tile.y0) * stride, stride, 2 * f + 1,
                            m.invY[size_t(y - tile.y0)], invX,
                            m.dist[s][kind].data() + size_t(y - tile.y0) * size_t(tw));
  };
  auto extRow = [&](int kind, int y, int x) {
    return m.ext[kind].data() + size_t(y - ey0) * size_t(ew) + size_t(x - ex0);
  };
  // With the default radii 1 and 3, the 7-wide sums are the 3-wide ones at ∓2 plus the centre.
  const int f0 = patch_[0];
  const bool widen = patch_[1] == 2 * f0 + 1;
  for (int kind = 0; kind < 3; ++kind) {
    if (widen) {
      const int k = f0 + 1, iw = tw + 2 * k;
      const size_t innerStride = size_t(iw);
      // Inner (radius f0) sums over every grown row, k columns wider on each side.
      for (int y = ey0; y < ey0 + eh; ++y)
        rows::horizontalBoxSum(iw, extRow(kind, y, tile.x0 - k), f0,
                               m.innerSums.data() + size_t(y - ey0) * innerStride);
      patchMeans(0, kind, m.innerSums.data() + size_t(tile.y0 - f0 - ey0) * innerStride + size_t(k),
                 innerStride);
      for (int y = ey0; y < ey0 + eh; ++y)
        rows::widenBoxSum(tw, extRow(kind, y, tile.x0),
                          m.innerSums.data() + size_t(y - ey0) * innerStride + size_t(k), f0,
                          m.rowSums.data() + size_t(y - ey0) * size_t(tw));
      patchMeans(1, kind, m.rowSums.data() + size_t(tile.y0 - patch_[1] - ey0) * size_t(tw),
                 size_t(tw));
      continue;
    }
    for (int s = 0; s < kColor; ++s) {
      const int f = patch_[s];
      // Horizontal sums for the rows [tile.y0 − f, tile.y1 + f), tile columns.
      for (int y = tile.y0 - f; y < tile.y1 + f; ++y)
        rows::horizontalBoxSum(tw, extRow(kind, y, tile.x0), f,
                               m.rowSums.data() + size_t(y - tile.y0 + f) * size_t(tw));
      patchMeans(s, kind, m.rowSums.data(), size_t(tw));
    }
  }

  // Slopes where p is a neighbour in its own patch sums (offsets within the larger patch).
  if (adx > G || ady > G) return;
  for (int y = tile.y0; y < tile.y1; ++y) {
    const size_t row = size_t(y - tile.y0) * size_t(tw);
    const int x0 = tile.x0;
    for (int c = 0; c < 3; ++c)
      rows::nearColorSlopes(
          tw, g_.row(c, y) + x0, g_.row(c, y + dy) + x0 + dx, g_.row(c, y - dy) + x0 - dx,
          g_.row(c, y + 2 * dy) + x0 + 2 * dx, g_.row(c, y - 2 * dy) + x0 - 2 * dx,
          vd_.row(c, y) + x0, vd_.row(c, y + dy) + x0 + dx, vd_.row(c, y - dy) + x0 - dx,
          vd_.row(c, y + 2 * dy) + x0 + 2 * dx, vd_.row(c, y - 2 * dy) + x0 - 2 * dx,
          m.mask[kPlus] + row, m.mask[kMinus] + row, m.mask[3] + row, m.mask[4] + row,
          m.nearSlope[c][kPlus].data() + row, m.nearSlope[c][kMinus].data() + row,
          m.nearSlope[c][kSym].data() + row);
  }
}

void CandidateKernel::accumulate(const PixelRect& tile, int dx, int dy, TileMemory& m) const {
  const int tw = tile.width(), x0 = tile.x0;
  const int adx = std::abs(dx), ady = std::abs(dy);
  for (int y = tile.y0; y < tile.y1; ++y) {
    const size_t row = size_t(y - tile.y0) * size_t(tw);
    rows::CandidateSums sums;
    for (int c = 0; c < 3; ++c) {
      sums.dataPlus[c] = b1_.row(c, y + dy) + x0 + dx;
      sums.dataPlus[3 + c] = b2_.row(c, y + dy) + x0 + dx;
      sums.dataMinus[c] = b1_.row(c, y - dy) + x0 - dx;
      sums.dataMinus[3 + c] = b2_.row(c, y - dy) + x0 - dx;
    }
    sums.accStride = m.planeStride;
    auto candidateSums = [&](int s) {
      sums.weightSum = m.weightSum[s].data() + row;
      sums.maxWeight = m.maxWeight[s].data() + row;
      sums.acc = m.acc[s].data() + row;
      return sums;
    };
    // THIRD: the feature weights alone.
    rows::accumulateCandidate(tw, m.featPlus[1].data() + row, m.featMinus[1].data() + row,
                              candidateSums(2));

    for (int s = 0; s < kColor; ++s) {
      rows::ColorCandidateRow r;
      for (int kind = 0; kind < 3; ++kind) {
        r.dist[kind] = m.dist[s][kind].data() + row;
        r.invCount[kind] = m.invCount[s][kind] + row;
        r.mask[kind] = m.mask[kind] + row;
      }
      r.featPlus = m.featPlus[0].data() + row;
      r.featMinus = m.featMinus[0].data() + row;
      // p is also a neighbour in its own patch sums for offsets within the patch.
      const bool near = adx <= patch_[s] && ady <= patch_[s];
      for (int c = 0; c < 3; ++c) {
        for (int kind = 0; kind < 3; ++kind) {
          r.slope[c][kind] = m.slope[c][kind].data() + row;
          r.nearSlope[c][kind] = near ? m.nearSlope[c][kind].data() + row : nullptr;
        }
        r.guidePlus[c] = g_.row(c, y + dy) + x0 + dx;
        r.guideMinus[c] = g_.row(c, y - dy) + x0 - dx;
      }
      r.derivativeSum = m.derivativeSum[s].data() + row;
      r.derivativeAcc = m.derivativeAcc[s].data() + row;
      r.maxDerivative = m.maxDerivative[s].data() + row;
      r.derivativeStride = m.planeStride;
      rows::accumulateColorCandidate(tw, r, refineMinWeight_, candidateSums(s));
    }
  }
}

void CandidateKernel::finishTile(const PixelRect& tile, const TileMemory& m, Outputs& out) const {
  const size_t stride = m.planeStride;
  for (int y = tile.y0; y < tile.y1; ++y)
    for (int x = tile.x0; x < tile.x1; ++x) {
      const size_t i = size_t(y - tile.y0) * size_t(tile.width()) + size_t(x - tile.x0);
      for (int s = 0; s < 3; ++s) {
        const float centre = std::max(m.maxWeight[s][i], kRdfcMinCenterWeight);
        const float total = m.weightSum[s][i] + centre;
        float mean[3];
        for (int c = 0; c < 3; ++c) {
          const float* acc = m.acc[s].data() + i;
          const float f1 = (acc[size_t(c) * stride] + centre * b1_.row(c, y)[x]) / total;
          const float f2 = (acc[size_t(3 + c) * stride] + centre * b2_.row(c, y)[x]) / total;
          out.buffer1[size_t(s)](x, y, c) = f1;
          out.buffer2[size_t(s)](x, y, c) = f2;
          mean[c] = 0.5f * (f1 + f2);
        }
        // ∂F_c/∂y_c = (∂A − F ∂S) / S with A = Σ w y(q) + w_centre y(p), S = Σ w + w_centre.
        const float fallback = centre / total;
        float der[3] = {fallback, fallback, fallback};
        if (s < kColor) {
          bool valid = true;
          for (int c = 0; c < 3 && valid; ++c) {
            const size_t k = size_t(c) * stride + i;
            const float dCentre =
                m.maxWeight[s][i] >= kRdfcMinCenterWeight ? m.maxDerivative[s][k] : 0.0f;
            const float dSum = m.derivativeSum[s][k] + dCentre;
            const float dAcc = m.derivativeAcc[s][k] + dCentre * guide_(x, y, c) + centre;
            der[c] = (dAcc - mean[c] * dSum) / total;
            valid = std::isfinite(der[c]) &&
                    (!params_.derivativeFallback || (der[c] >= 0.0f && der[c] <= 1.0f));
          }
          if (!valid) der[0] = der[1] = der[2] = fallback;
        }
        for (int c = 0; c < 3; ++c) out.derivative[size_t(s)](x, y, c) = der[c];
      }
    }
}

void CandidateKernel::runTile(const PixelRect& tile, TileMemory& m, Outputs& out) const {
  const FlushDenormals flush;  // tiny weights times data would be denormal
  const size_t area = size_t(tile.area());
  const size_t grownArea =
      size_t(kCandidateTileWidth + 2 * grow_) * size_t(kCandidateTileHeight + 2 * grow_);
  m.planeStride = paddedPlaneStride(area);
  const size_t plane = m.planeStride;  // every plane's allocation, so that they too are staggered
  m.ones.assign(area, 1.0f);
  for (int set = 0; set < 2; ++set) {
    m.featPlus[set].resize(plane);
    m.featMinus[set].resize(plane);
  }
  for (auto& v : m.ext) v.resize(grownArea);
  m.rowSums.resize(size_t(kCandidateTileWidth) * size_t(kCandidateTileHeight + 2 * grow_));
  m.invCountX.resize(kCandidateTileWidth);
  m.innerSums.resize(size_t(kCandidateTileWidth + 2 * grow_ + 2) *
                     size_t(kCandidateTileHeight + 2 * grow_));
  m.invY.resize(kCandidateTileHeight);
  m.running.resize(kCandidateTileWidth);
  for (int s = 0; s < kColor; ++s) {
    const float inv = 1.0f / float(2 * patch_[s] + 1);
    m.fullInvCountX[s].assign(kCandidateTileWidth, inv);
    m.fullInvCount[s].assign(plane, inv * inv);
  }
  for (int s = 0; s < kColor; ++s)
    for (int kind = 0; kind < 3; ++kind) {
      m.dist[s][kind].resize(plane);
      m.invCountStore[s][kind].resize(plane);
    }
  for (int c = 0; c < 3; ++c)
    for (int kind = 0; kind < 3; ++kind) {
      m.slope[c][kind].resize(plane);
      m.nearSlope[c][kind].resize(plane);
    }
  for (int s = 0; s < 3; ++s) {
    m.weightSum[s].assign(plane, 0.0f);
    m.maxWeight[s].assign(plane, 0.0f);
    m.acc[s].assign(6 * plane, 0.0f);
  }
  for (int s = 0; s < kColor; ++s) {
    m.derivativeSum[s].assign(3 * plane, 0.0f);
    m.derivativeAcc[s].assign(3 * plane, 0.0f);
    m.maxDerivative[s].assign(3 * plane, 0.0f);
  }
  for (int dy = 0; dy <= params_.r; ++dy)
    for (int dx = dy == 0 ? 1 : -params_.r; dx <= params_.r; ++dx) {
      masks(tile, dx, dy, m);
      featureWeights(tile, dx, dy, m);
      colorDistances(tile, dx, dy, m);
      accumulate(tile, dx, dy, m);
    }
  finishTile(tile, m, out);
}

std::array<RdfcCandidate, 3> CandidateKernel::run() const {
  std::vector<PixelRect> tiles;
  for (int y = 0; y < height_; y += kCandidateTileHeight)
    for (int x = 0; x < width_; x += kCandidateTileWidth)
      tiles.push_back({x, y, std::min(width_, x + kCandidateTileWidth),
                       std::min(height_, y + kCandidateTileHeight)});
  Outputs out;
  for (int s = 0; s < 3; ++s) {
    out.buffer1[size_t(s)] = Image(width_, height_, 3);
    out.buffer2[size_t(s)] = Image(width_, height_, 3);
    out.derivative[size_t(s)] = Image(width_, height_, 3);
  }
  tbb::enumerable_thread_specific<TileMemory> memory;
  tbb::parallel_for(size_t(0), tiles.size(),
                    [&](size_t t) { runTile(tiles[t], memory.local(), out); });

  std::array<RdfcCandidate, 3> result;
  for (int s = 0; s < 3; ++s) {
    RdfcCandidate& cand = result[size_t(s)];
    cand.buffer1 = std::move(out.buffer1[size_t(s)]);
    cand.buffer2 = std::move(out.buffer2[size_t(s)]);
    cand.derivative = std::move(out.derivative[size_t(s)]);
    cand.mean = Image(width_, height_, 3);
    cand.sure = Image(width_, height_, 1);
    parallelRows(0, height_, [&](int y) {
      for (int x = 0; x < width_; ++x) {
        float sum = 0.0f;
        for (int c = 0; c < 3; ++c) {
          const float f = 0.5f * (cand.buffer1(x, y, c) + cand.buffer2(x, y, c));
          cand.mean(x, y, c) = f;
          sum += sureTerm(f, guide_(x, y, c), variance_(x, y, c), cand.derivative(x, y, c));
        }
        cand.sure(x, y, 0) = std::isfinite(sum) ? sum / 3.0f : std::numeric_limits<float>::max();
      }
    });
  }
  return result;
}

}  // namespace

std::array<RdfcCandidate, 3> rdfcCandidates(const Image& buffer1, const Image& buffer2,
                                            const Image& colorVariance,
                                            const std::vector<RdfcFeature>& features,
                                            const RdfcCandidateParams& params) {
  return CandidateKernel(buffer1, buffer2, colorVariance, features, params).run();
}

}  // namespace chorus
