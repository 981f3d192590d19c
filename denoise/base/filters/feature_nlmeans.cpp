#include "denoise/base/filters/feature_nlmeans.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "denoise/base/filters/bordered_planes.h"
#include "denoise/base/filters/nlmeans_row_kernels.h"
#include "denoise/base/filters/pixel_rect.h"
#include "denoise/base/filters/rect_mask.h"
#include "denoise/util/float_lanes.h"
#include "denoise/util/padded_stride.h"
#include "denoise/util/parallel_rows.h"

namespace chorus {
namespace {

// Wide tiles: each row-kernel call covers 256 pixels (at 64 the per-call set-up of the many
// row pointers dominated: 64 × 64 → 256 × 32 took RDFC's second pass 2.1–2.3 → 1.6–1.8 s at 1024²
// with 2 threads, RDFC −5% and joint NL-means −17% in A/B runs), and the patch distances over
// the tile grown by f + box (5 for RDFC) are 1.36× the tile. In the AVX-512 build, which
// contracts FMAs in the vector loops only, a pixel's column within a row decides whether its
// value comes from the vector loop or the scalar tail, so the width changes results by rounding.
constexpr int kFeatureTileWidth = 256, kFeatureTileHeight = 32;
constexpr float kSymmetricLimit = 25.0f;  // refine only where both distances are below this
enum Kind { kPlus, kMinus, kSym };

// The pixels of kind (+: p + δ exists, −: p − δ, sym: both) form a rectangle of the image.
struct ValidRects {
  PixelRect rect[3];
  ValidRects(int w, int h, int dx, int dy) {
    rect[kPlus] = neighbourInside(w, h, dx, dy);
    rect[kMinus] = neighbourInside(w, h, -dx, -dy);
    rect[kSym] = rect[kPlus].intersect(rect[kMinus]);
  }
};

// dst (over `out`) = box mean of src (over `in`, which contains `out` grown by r) of radius r,
// each sum divided by the number of pixels of `valid` in the box (src is 0 outside `valid`).
void boxMean(const float* src, const PixelRect& in, float* dst, const PixelRect& out, int r,
             const PixelRect& valid, std::vector<float>& rowSums, std::vector<float>& invX) {
  const int ow = out.width(), iw = in.width();
  rowSums.resize(size_t(ow) * size_t(out.height() + 2 * r));
  for (int y = out.y0 - r; y < out.y1 + r; ++y)
    rows::horizontalBoxSum(ow, src + size_t(y - in.y0) * size_t(iw) + size_t(out.x0 - in.x0), r,
                           rowSums.data() + size_t(y - out.y0 + r) * size_t(ow));
  invX.resize(size_t(ow));
  for (int i = 0; i < ow; ++i) {
    const int n = boxOverlap(out.x0 + i, r, valid.x0, valid.x1);
    invX[size_t(i)] = n > 0 ? 1.0f / float(n) : 0.0f;
  }
  for (int y = out.y0; y < out.y1; ++y) {
    const int ny = boxOverlap(y, r, valid.y0, valid.y1);
    rows::verticalBoxMean(ow, rowSums.data() + size_t(y - out.y0) * size_t(ow), size_t(ow),
                          2 * r + 1, ny > 0 ? 1.0f / float(ny) : 0.0f, invX.data(),
                          dst + size_t(y - out.y0) * size_t(ow));
  }
}

struct TileMemory {
  std::vector<float> maskStore[3], featPlus, featMinus, termRow[3];
  std::vector<float> ones;        // a mask where every pair exists
  const float* mask[3] = {};      // this offset's validity masks over the tile
  const float* gridMask[3] = {};  // ... over the grid
  std::vector<float> ext[3], dist[3], gridMaskStore[3], gridPlus, gridMinus, rowSums, invX;
  std::vector<float> patchPlus, patchMinus, wPlus, wMinus;
  std::vector<float> weightSum, maxWeight;
  std::vector<float> acc;  // every data channel, one plane each (paddedPlaneStride apart)
};

class FeatureNlMeansKernel {
 public:
  FeatureNlMeansKernel(std::span<const Image* const> data, const PatchTerm* patch,
                       std::span<const FeatureTerm> features, const FeatureNlMeansParams& params);
  std::vector<Image> run() const;

 private:
  void runTile(const PixelRect& tile, TileMemory& m, std::vector<Image>& out) const;
  void featureWeights(const PixelRect& tile, int dx, int dy, TileMemory& m) const;
  void unrefinedFeatureWeights(const PixelRect& tile, int dx, int dy, TileMemory& m) const;
  void patchWeights(const PixelRect& tile, int dx, int dy, TileMemory& m) const;

  int width_ = 0, height_ = 0, pad_ = 0, dataChannels_ = 0;
  FeatureNlMeansParams params_;
  float refineMinWeight_;
  std::vector<int> dataBegin_;  // first plane of every data image in data_
  BorderedPlanes data_;
  // Patch term.
  bool hasPatch_ = false;
  int f_ = 0, box_ = 0, patchChannels_ = 0;
  bool patchCentreOnly_ = false;
  BorderedPlanes g_, vn_, vd_;
  BorderedPlanes invPair_, invSym_;  // centre-only: the reciprocals of the denominators
  // Feature terms: one plane per channel of every term.
  std::vector<int> termBegin_;
  std::vector<bool> termCentreOnly_;
  BorderedPlanes fValue_, fNum_, fDen_;
};

FeatureNlMeansKernel::FeatureNlMeansKernel(std::span<const Image* const> data,
                                           const PatchTerm* patch,
                                           std::span<const FeatureTerm> features,
                                           const FeatureNlMeansParams& params)
    : params_(params), refineMinWeight_(std::exp(-kSymmetricLimit)) {
  if (data.empty()) throw std::invalid_argument("featureNlMeans: no data");
  width_ = data[0]->width();
  height_ = data[0]->height();
  if (params.r < 0) throw std::invalid_argument("featureNlMeans: negative window radius");
  auto requireSize = [&](const Image* image, const char* what) {
    if (!image || image->width() != width_ || image->height() != height_)
      throw std::invalid_argument(std::string("featureNlMeans: ") + what +
                                  " missing or size differs");
  };
  for (const Image* d : data) requireSize(d, "data");
  if (patch) {
    requireSize(patch->guide, "guide");
    requireSize(patch->variance, "guide variance");
    if (!patch->guide->sameShape(*patch->variance) || patch->f < 0 || patch->weightBoxRadius < 0)
      throw std::invalid_argument("featureNlMeans: bad patch term");
    hasPatch_ = true;
    f_ = patch->f;
    box_ = patch->weightBoxRadius;
    patchCentreOnly_ = patch->centerOnlyDenominator;
    patchChannels_ = patch->guide->channels();
  }
  for (const FeatureTerm& t : features) {
    requireSize(t.value, "feature");
    requireSize(t.variance, "feature variance");
    if (!t.value->sameShape(*t.variance) ||
        (t.normalizingVariance && !t.value->sameShape(*t.normalizingVariance)))
      throw std::invalid_argument("featureNlMeans: feature shapes differ");
  }
  pad_ = params.r + f_ + box_ + 1;

  int planes = 0;
  for (const Image* d : data) {
    dataBegin_.push_back(planes);
    planes += d->channels();
  }
  dataBegin_.push_back(planes);
  dataChannels_ = planes;
  data_ = BorderedPlanes(width_, height_, planes, pad_);
  for (size_t i = 0; i < data.size(); ++i)
    for (int c = 0; c < data[i]->channels(); ++c) data_.set(dataBegin_[i] + c, *data[i], c);

  if (hasPatch_) {
    for (BorderedPlanes* p : {&g_, &vn_, &vd_})
      *p = BorderedPlanes(width_, height_, patchChannels_, pad_);
    for (int c = 0; c < patchChannels_; ++c) {
      g_.set(c, *patch->guide, c);
      vn_.set(c, *patch->variance, c, patch->alpha);
      vd_.set(c, *patch->variance, c, patch->k * patch->k);
    }
    if (patchCentreOnly_) {
      for (BorderedPlanes* p : {&invPair_, &invSym_})
        *p = BorderedPlanes(width_, height_, patchChannels_, pad_);
      for (int c = 0; c < patchChannels_; ++c)
        parallelRows(-pad_, height_ + pad_, [&](int y) {
          rows::centreReciprocals(width_ + 2 * pad_, vd_.row(c, y) - pad_,
                                  invPair_.mutableRow(c, y) - pad_,
                                  invSym_.mutableRow(c, y) - pad_);
        });
    }
  }
  int channels = 0;
  for (const FeatureTerm& t : features) {
    termBegin_.push_back(channels);
    termCentreOnly_.push_back(t.centerOnlyDenominator);
    channels += t.value->channels();
  }
  termBegin_.push_back(channels);
  for (BorderedPlanes* p : {&fValue_, &fNum_, &fDen_})
    *p = BorderedPlanes(width_, height_, channels, pad_);
  for (size_t j = 0; j < features.size(); ++j) {
    const FeatureTerm& t = features[j];
    const Image& den = t.normalizingVariance ? *t.normalizingVariance : *t.variance;
    for (int c = 0; c < t.value->channels(); ++c) {
      const int k = termBegin_[j] + c;
      fValue_.set(k, *t.value, c);
      fNum_.set(k, *t.variance, c, t.alpha);
      fDen_.set(k, den, c, t.k * t.k);
    }
  }
}

void FeatureNlMeansKernel::featureWeights(const PixelRect& tile, int dx, int dy,
                                          TileMemory& m) const {
  const int tw = tile.width(), x0 = tile.x0;
  const size_t area = size_t(tile.area());
  if (!params_.refineFeatures) {
    unrefinedFeatureWeights(tile, dx, dy, m);
    return;
  }
  std::fill(m.featPlus.begin(), m.featPlus.begin() + ptrdiff_t(area), 1.0f);
  std::fill(m.featMinus.begin(), m.featMinus.begin() + ptrdiff_t(area), 1.0f);
  for (int y = tile.y0; y < tile.y1; ++y) {
    const size_t row = size_t(y - tile.y0) * size_t(tw);
    for (size_t term = 0; term + 1 < termBegin_.size(); ++term) {
      for (auto& r : m.termRow) std::fill(r.begin(), r.begin() + tw, 0.0f);
      const bool centre = termCentreOnly_[term];
      for (int k = termBegin_[term]; k < termBegin_[term + 1]; ++k) {
        const float* den = fDen_.row(k, y) + x0;
        rows::addFeatureDistances(
            tw, fValue_.row(k, y) + x0, fValue_.row(k, y + dy) + x0 + dx,
            fValue_.row(k, y - dy) + x0 - dx, fNum_.row(k, y) + x0, fNum_.row(k, y + dy) + x0 + dx,
            fNum_.row(k, y - dy) + x0 - dx, den, centre ? den : fDen_.row(k, y + dy) + x0 + dx,
            centre ? den : fDen_.row(k, y - dy) + x0 - dx, centre ? 0.5f : 0.25f,
            m.termRow[kPlus].data(), m.termRow[kMinus].data(), m.termRow[kSym].data());
      }
      const float scale = 1.0f / float(termBegin_[term + 1] - termBegin_[term]);
      rows::minTermWeights(tw, scale, m.termRow[kPlus].data(), m.termRow[kMinus].data(),
                           m.termRow[kSym].data(), m.mask[kSym] + row, refineMinWeight_,
                           m.featPlus.data() + row, m.featMinus.data() + row);
    }
  }
  multiplyByMask(m.featPlus.data(), area, m.mask[kPlus], m.ones.data());
  multiplyByMask(m.featMinus.data(), area, m.mask[kMinus], m.ones.data());
}

void FeatureNlMeansKernel::unrefinedFeatureWeights(const PixelRect& tile, int dx, int dy,
                                                   TileMemory& m) const {
  const int tw = tile.width(), x0 = tile.x0;
  for (int y = tile.y0; y < tile.y1; ++y) {
    const size_t row = size_t(y - tile.y0) * size_t(tw);
    float* maxPlus = m.termRow[kSym].data();  // scratch: max over terms of D(p, p + δ)
    float* maxMinus = m.featMinus.data() + row;
    std::fill(maxPlus, maxPlus + tw, 0.0f);
    std::fill(maxMinus, maxMinus + tw, 0.0f);
    for (size_t term = 0; term + 1 < termBegin_.size(); ++term) {
      std::fill(m.termRow[kPlus].begin(), m.termRow[kPlus].begin() + tw, 0.0f);
      std::fill(m.termRow[kMinus].begin(), m.termRow[kMinus].begin() + tw, 0.0f);
      const bool centre = termCentreOnly_[term];
      for (int k = termBegin_[term]; k < termBegin_[term + 1]; ++k) {
        const float* den = fDen_.row(k, y) + x0;
        rows::addFeatureDistances(tw, fValue_.row(k, y) + x0, fValue_.row(k, y + dy) + x0 + dx,
                                  fValue_.row(k, y - dy) + x0 - dx, fNum_.row(k, y) + x0,
                                  fNum_.row(k, y + dy) + x0 + dx, fNum_.row(k, y - dy) + x0 - dx,
                                  den, centre ? den : fDen_.row(k, y + dy) + x0 + dx,
                                  centre ? den : fDen_.row(k, y - dy) + x0 - dx, 0.25f,
                                  m.termRow[kPlus].data(), m.termRow[kMinus].data(), nullptr);
      }
      const float scale = 1.0f / float(termBegin_[term + 1] - termBegin_[term]);
      rows::maxScaled(tw, scale, m.termRow[kPlus].data(), maxPlus);
      rows::maxScaled(tw, scale, m.termRow[kMinus].data(), maxMinus);
    }
    rows::maskedWeights(tw, maxPlus, m.mask[kPlus] + row, m.featPlus.data() + row);
    rows::maskedWeights(tw, maxMinus, m.mask[kMinus] + row, maxMinus);
  }
}

void FeatureNlMeansKernel::patchWeights(const PixelRect& tile, int dx, int dy,
                                        TileMemory& m) const {
  const ValidRects valid(width_, height_, dx, dy);
  const PixelRect grid = tile.grown(box_), ext = grid.grown(f_);
  const int ew = ext.width(), gw = grid.width();
  const size_t eArea = size_t(ext.area());
  const float share = 1.0f / float(patchChannels_);
  const int ox = ext.x0;
  for (int y = ext.y0; y < ext.y1; ++y) {
    const size_t e = size_t(y - ext.y0) * size_t(ew);
    for (int c = 0; c < patchChannels_; ++c) {
      if (patchCentreOnly_) {
        rows::addCentreColorDistances(
            ew, g_.row(c, y) + ox, g_.row(c, y + dy) + ox + dx, g_.row(c, y - dy) + ox - dx,
            vn_.row(c, y) + ox, vn_.row(c, y + dy) + ox + dx, vn_.row(c, y - dy) + ox - dx,
            invPair_.row(c, y) + ox, invSym_.row(c, y) + ox, share, c == 0, m.ext[kPlus].data() + e,
            m.ext[kMinus].data() + e, m.ext[kSym].data() + e);
        continue;
      }
      rows::addColorDistances(
          ew, g_.row(c, y) + ox, g_.row(c, y + dy) + ox + dx, g_.row(c, y - dy) + ox - dx,
          vn_.row(c, y) + ox, vn_.row(c, y + dy) + ox + dx, vn_.row(c, y - dy) + ox - dx,
          vd_.row(c, y) + ox, vd_.row(c, y + dy) + ox + dx, vd_.row(c, y - dy) + ox - dx, share,
          0.25f, c == 0, m.ext[kPlus].data() + e, m.ext[kMinus].data() + e, m.ext[kSym].data() + e,
          nullptr, nullptr, nullptr);
    }
  }
  // Patch means over the grid (the tile grown by the weight box), counting valid pixels only.
  for (int kind = 0; kind < 3; ++kind) {
    if (ext.intersect(valid.rect[kind]) != ext) {  // × 1 changes nothing (not even a NaN)
      fillRectMask(ext, valid.rect[kind], m.gridMaskStore[kind].data());  // scratch: ext mask
      for (size_t i = 0; i < eArea; ++i) m.ext[kind][i] *= m.gridMaskStore[kind][i];
    }
    boxMean(m.ext[kind].data(), ext, m.dist[kind].data(), grid, f_, valid.rect[kind], m.rowSums,
            m.invX);
    m.gridMask[kind] = rectMaskOrOnes(grid, valid.rect[kind], m.gridMaskStore[kind], m.ones.data());
  }
  for (int y = grid.y0; y < grid.y1; ++y) {
    const size_t r = size_t(y - grid.y0) * size_t(gw);
    rows::patchWeights(gw, m.dist[kPlus].data() + r, m.dist[kMinus].data() + r,
                       m.dist[kSym].data() + r, m.gridMask[kPlus] + r, m.gridMask[kMinus] + r,
                       m.gridMask[kSym] + r, refineMinWeight_, m.gridPlus.data() + r,
                       m.gridMinus.data() + r);
  }
  // "Patchwise": the weights themselves box-filtered over the valid pixels.
  if (box_ > 0) {
    boxMean(m.gridPlus.data(), grid, m.patchPlus.data(), tile, box_, valid.rect[kPlus], m.rowSums,
            m.invX);
    boxMean(m.gridMinus.data(), grid, m.patchMinus.data(), tile, box_, valid.rect[kMinus],
            m.rowSums, m.invX);
  } else {
    std::copy(m.gridPlus.begin(), m.gridPlus.begin() + ptrdiff_t(tile.area()), m.patchPlus.begin());
    std::copy(m.gridMinus.begin(), m.gridMinus.begin() + ptrdiff_t(tile.area()),
              m.patchMinus.begin());
  }
}

void FeatureNlMeansKernel::runTile(const PixelRect& tile, TileMemory& m,
                                   std::vector<Image>& out) const {
  const FlushDenormals flush;  // tiny weights times data would be denormal
  const size_t area = size_t(tile.area());
  const int tw = tile.width(), x0 = tile.x0;
  const size_t gridArea =
      size_t(kFeatureTileWidth + 2 * box_) * size_t(kFeatureTileHeight + 2 * box_);
  const size_t extArea =
      size_t(kFeatureTileWidth + 2 * (box_ + f_)) * size_t(kFeatureTileHeight + 2 * (box_ + f_));
  m.ones.assign(extArea, 1.0f);
  for (auto& v : m.termRow) v.resize(kFeatureTileWidth);
  for (auto& v : m.ext) v.resize(extArea);
  for (auto& v : m.dist) v.resize(gridArea);
  for (auto& v : m.gridMaskStore) v.resize(extArea);
  const size_t plane = paddedPlaneStride(area);  // every tile plane's allocation (staggered)
  for (auto* v : {&m.featPlus, &m.featMinus, &m.patchPlus, &m.patchMinus, &m.wPlus, &m.wMinus})
    v->resize(plane);
  m.gridPlus.resize(paddedPlaneStride(gridArea));
  m.gridMinus.resize(paddedPlaneStride(gridArea));
  m.weightSum.assign(plane, 0.0f);
  m.maxWeight.assign(plane, 0.0f);
  m.acc.assign(plane * size_t(dataChannels_), 0.0f);

  const int r = params_.r;
  for (int dy = 0; dy <= r; ++dy)
    for (int dx = dy == 0 ? 1 : -r; dx <= r; ++dx) {
      const ValidRects valid(width_, height_, dx, dy);
      for (int kind = 0; kind < 3; ++kind)
        m.mask[kind] = rectMaskOrOnes(tile, valid.rect[kind], m.maskStore[kind], m.ones.data());
      // Without feature terms the feature weights are the masks (1 × mask).
      const float* wPlus = m.mask[kPlus];
      const float* wMinus = m.mask[kMinus];
      if (termBegin_.size() > 1) {
        featureWeights(tile, dx, dy, m);
        wPlus = m.featPlus.data();
        wMinus = m.featMinus.data();
      }
      if (hasPatch_) {
        patchWeights(tile, dx, dy, m);
        rows::minWeights(int(area), m.patchPlus.data(), wPlus, m.wPlus.data());
        rows::minWeights(int(area), m.patchMinus.data(), wMinus, m.wMinus.data());
        wPlus = m.wPlus.data();
        wMinus = m.wMinus.data();
      }
      for (int y = tile.y0; y < tile.y1; ++y) {
        const size_t row = size_t(y - tile.y0) * size_t(tw);
        rows::accumulateWeightSums(tw, wPlus + row, wMinus + row, m.weightSum.data() + row,
                                   m.maxWeight.data() + row);
        for (int k = 0; k < dataChannels_; ++k)
          rows::accumulateData(tw, wPlus + row, wMinus + row, data_.row(k, y + dy) + x0 + dx,
                               data_.row(k, y - dy) + x0 - dx,
                               m.acc.data() + size_t(k) * plane + row);
      }
    }

  for (int y = tile.y0; y < tile.y1; ++y)
    for (int x = tile.x0; x < tile.x1; ++x) {
      const size_t i = size_t(y - tile.y0) * size_t(tw) + size_t(x - x0);
      const float centre = std::max(m.maxWeight[i], params_.minCenterWeight);
      const float total = m.weightSum[i] + centre;
      for (size_t d = 0; d + 1 < dataBegin_.size(); ++d)
        for (int c = 0; c < dataBegin_[d + 1] - dataBegin_[d]; ++c) {
          const int k = dataBegin_[d] + c;
          out[d](x, y, c) = (m.acc[size_t(k) * plane + i] + centre * data_.row(k, y)[x]) / total;
        }
    }
}

std::vector<Image> FeatureNlMeansKernel::run() const {
  std::vector<Image> out;
  for (size_t d = 0; d + 1 < dataBegin_.size(); ++d)
    out.emplace_back(width_, height_, dataBegin_[d + 1] - dataBegin_[d]);
  std::vector<PixelRect> tiles;
  for (int y = 0; y < height_; y += kFeatureTileHeight)
    for (int x = 0; x < width_; x += kFeatureTileWidth)
      tiles.push_back({x, y, std::min(width_, x + kFeatureTileWidth),
                       std::min(height_, y + kFeatureTileHeight)});
  tbb::enumerable_thread_specific<TileMemory> memory;
  tbb::parallel_for(size_t(0), tiles.size(),
                    [&](size_t t) { runTile(tiles[t], memory.local(), out); });
  return out;
}

}  // namespace

std::vector<Image> featureNlMeans(std::span<const Image* const> data, const PatchTerm* patch,
                                  std::span<const FeatureTerm> features,
                                  const FeatureNlMeansParams& params) {
  return FeatureNlMeansKernel(data, patch, features, params).run();
}

}  // namespace chorus
