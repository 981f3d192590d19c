#include "denoise/base/filters/collaborative_regression.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "denoise/image/planar_image.h"
#include "denoise/base/filters/simd_quad.h"

namespace chorus {
namespace {

constexpr int kTileSize = 32;
constexpr int kLanes = 8;  // partial sums per dot product (vectorised, fixed summation order)

inline float laneSum(Quad lo, Quad hi) {
  return ((lo[0] + hi[0]) + (lo[1] + hi[1])) + ((lo[2] + hi[2]) + (lo[3] + hi[3]));
}

// Σ_i w[i] a[i] b[i] over n (a multiple of kLanes) values, lanes summed in a fixed order.
float weightedDot(const float* w, const float* a, const float* b, int n) {
  Quad lo = {}, hi = {};
  for (int i = 0; i < n; i += kLanes) {
    lo += loadQuad(w + i) * loadQuad(a + i) * loadQuad(b + i);
    hi += loadQuad(w + i + 4) * loadQuad(a + i + 4) * loadQuad(b + i + 4);
  }
  return laneSum(lo, hi);
}

// Four weighted dot products Σ w·a·b_k sharing w·a.
void weightedDot4(const float* w, const float* a, const float* b0, const float* b1, const float* b2,
                  const float* b3, int n, float* out) {
  Quad l0 = {}, h0 = {}, l1 = {}, h1 = {}, l2 = {}, h2 = {}, l3 = {}, h3 = {};
  for (int i = 0; i < n; i += kLanes) {
    const Quad lo = loadQuad(w + i) * loadQuad(a + i);
    const Quad hi = loadQuad(w + i + 4) * loadQuad(a + i + 4);
    l0 += lo * loadQuad(b0 + i);
    h0 += hi * loadQuad(b0 + i + 4);
    l1 += lo * loadQuad(b1 + i);
    h1 += hi * loadQuad(b1 + i + 4);
    l2 += lo * loadQuad(b2 + i);
    h2 += hi * loadQuad(b2 + i + 4);
    l3 += lo * loadQuad(b3 + i);
    h3 += hi * loadQuad(b3 + i + 4);
  }
  out[0] = laneSum(l0, h0);
  out[1] = laneSum(l1, h1);
  out[2] = laneSum(l2, h2);
  out[3] = laneSum(l3, h3);
}

struct TileResult {
  PixelRect extent;         // the tile grown by r, clipped: every pixel its windows touch
  std::vector<float> acc;   // C planes over extent
  std::vector<float> wsum;  // one plane over extent
};

struct ThreadState {
  NlMeansScratch scratch;
  std::vector<float> table;  // weights [tile pixel][offset]
  std::vector<float> plus, minus, center;
  std::vector<float> columns;      // (d + C) columns of the compacted window, stride `stride`
  std::vector<float> predictions;  // C columns of window predictions
  std::vector<float> rowWeights;   // w_q of each window row
};

class Regression {
 public:
  Regression(const Image& image, const Image& features, const NlMeansWeights& weights,
             const GramTolerances& tol)
      : u_(image),
        f_(features),
        weights_(weights),
        tol_(tol),
        width_(image.width()),
        height_(image.height()),
        r_(weights.params().r),
        side_(2 * r_ + 1),
        channels_(image.channels()),
        m_(features.channels()),
        d_(3 + m_),
        stride_((side_ * side_ + kLanes - 1) / kLanes * kLanes) {
    for (int j = 0; j < m_; ++j) {
      float* plane = f_.plane(j);
      for (size_t i = 0; i < f_.pixelCount(); ++i)
        if (!std::isfinite(plane[i])) plane[i] = 0.0f;
    }
  }

  Image run() {
    std::vector<PixelRect> tiles;
    for (int y = 0; y < height_; y += kTileSize)
      for (int x = 0; x < width_; x += kTileSize)
        tiles.push_back({x, y, std::min(width_, x + kTileSize), std::min(height_, y + kTileSize)});
    std::vector<TileResult> results(tiles.size());
    tbb::enumerable_thread_specific<ThreadState> states;
    tbb::parallel_for(size_t(0), tiles.size(),
                      [&](size_t t) { regressTile(tiles[t], states.local(), results[t]); });
    return gather(tiles, results);
  }

 private:
  int offsetIndex(int dx, int dy) const { return (dy + r_) * side_ + (dx + r_); }

  // Planes of the weight table are this far apart: a little more than the tile, so that the
  // (2r+1)² weights of one centre do not all fall into the same cache set.
  static size_t planeStride(const PixelRect& tile) { return size_t(tile.area()) + 16; }

  // Weights of every offset for every centre of the tile: plane offsetIndex(δ) holds w_δ(p).
  void fillWeightTable(const PixelRect& tile, ThreadState& st) const {
    const size_t stride = planeStride(tile), offsets = size_t(side_ * side_);
    st.table.resize(stride * offsets);
    float* table = st.table.data();
    weights_.center(tile, st.scratch, table + size_t(offsetIndex(0, 0)) * stride);
    weights_.forEachOffsetPair([&](int dx, int dy) {
      weights_.offsetPair(tile, dx, dy, st.scratch, table + size_t(offsetIndex(dx, dy)) * stride,
                          table + size_t(offsetIndex(-dx, -dy)) * stride);
    });
  }

  void regressTile(const PixelRect& tile, ThreadState& st, TileResult& out) const {
    fillWeightTable(tile, st);
    out.extent = tile.grown(r_).intersect(PixelRect::image(width_, height_));
    const size_t extArea = size_t(out.extent.area());
    out.acc.assign(extArea * size_t(channels_), 0.0f);
    out.wsum.assign(extArea, 0.0f);
    const int columns = d_ + channels_;
    st.columns.assign(size_t(columns) * size_t(stride_), 0.0f);
    st.predictions.assign(size_t(channels_) * size_t(stride_), 0.0f);
    st.rowWeights.assign(size_t(stride_), 0.0f);
    for (int py = tile.y0; py < tile.y1; ++py)
      for (int px = tile.x0; px < tile.x1; ++px) regressPixel(tile, px, py, st, out);
  }

  void regressPixel(const PixelRect& tile, int px, int py, ThreadState& st, TileResult& out) const {
    const size_t area = planeStride(tile);
    const float* w = st.table.data() + size_t(py - tile.y0) * size_t(tile.width()) +
                     size_t(px - tile.x0);  // w_δ(p) = w[offsetIndex(δ) · planeStride]
    float* cols = st.columns.data();
    auto col = [&](int a) { return cols + size_t(a) * size_t(stride_); };
    float* wRow = st.rowWeights.data();

    // The window is the rectangle [qx0, qx1] × [qy0, qy1]; its pixels become consecutive rows
    // of the design matrix, window row by window row. Rows with w = 0 stay: they add exactly 0.
    float fp[kMaxGramSize];
    for (int j = 0; j < m_; ++j) fp[j] = f_(px, py, j);
    const int qx0 = std::max(0, px - r_), qx1 = std::min(width_ - 1, px + r_);
    const int qy0 = std::max(0, py - r_), qy1 = std::min(height_ - 1, py + r_);
    const int len = qx1 - qx0 + 1;
    int n = 0;
    for (int qy = qy0; qy <= qy1; ++qy, n += len) {
      const float* wDy = w + size_t(offsetIndex(qx0 - px, qy - py)) * area;
      for (int i = 0; i < len; ++i) {
        wRow[n + i] = wDy[size_t(i) * area];
        col(1)[n + i] = float(qx0 - px + i);
      }
      std::fill(col(2) + n, col(2) + n + len, float(qy - py));
      const size_t rowStart = size_t(qy) * size_t(width_) + size_t(qx0);
      for (int j = 0; j < m_; ++j) {
        const float* src = f_.plane(j) + rowStart;
        float* dst = col(3 + j) + n;
        for (int i = 0; i < len; ++i) dst[i] = src[i] - fp[j];
      }
      for (int c = 0; c < channels_; ++c)
        std::copy(u_.plane(c) + rowStart, u_.plane(c) + rowStart + len, col(d_ + c) + n);
    }
    const int padded = (n + kLanes - 1) / kLanes * kLanes;
    for (int i = n; i < padded; ++i) {
      wRow[i] = 0.0f;
      for (int a = 1; a < d_ + channels_; ++a) col(a)[i] = 0.0f;
    }
    std::fill(col(0), col(0) + padded, 1.0f);

    // Weighted Gram matrix and right-hand sides: G_ab = Σ w x_a x_b, B_ac = Σ w x_a u_c.
    double gram[kMaxGramSize * kMaxGramSize] = {};
    double rhs[kMaxGramSize * kMaxGramRhs] = {};
    gramProducts(wRow, cols, padded, gram, rhs);
    double beta[kMaxGramSize * kMaxGramRhs];
    solveGramPivoted(gram, rhs, d_, channels_, beta, tol_);

    // Predict every window pixel and accumulate it with its weight.
    predict(beta, cols, padded, st.predictions.data());
    const PixelRect& ext = out.extent;
    const size_t extArea = size_t(ext.area());
    for (int qy = qy0, i0 = 0; qy <= qy1; ++qy, i0 += len) {
      const size_t at = size_t(qy - ext.y0) * size_t(ext.width()) + size_t(qx0 - ext.x0);
      for (int c = 0; c < channels_; ++c) {
        const float* pred = st.predictions.data() + size_t(c) * size_t(stride_) + i0;
        float* __restrict acc = out.acc.data() + size_t(c) * extArea + at;
        for (int i = 0; i < len; ++i) acc[i] += wRow[i0 + i] * pred[i];
      }
      float* __restrict wsum = out.wsum.data() + at;
      for (int i = 0; i < len; ++i) wsum[i] += wRow[i0 + i];
    }
  }

  // G (d × d, upper triangle) and B (d × C) from the window columns: each weighted column
  // w · x_a is formed once per four-column block and shared by the four dot products.
  void gramProducts(const float* w, const float* cols, int n, double* gram, double* rhs) const {
    auto col = [&](int a) { return cols + size_t(a) * size_t(stride_); };
    const int total = d_ + channels_;
    for (int a = 0; a < d_; ++a) {
      auto store = [&](int b, float v) {
        if (b < d_)
          gram[a * d_ + b] = v;
        else
          rhs[a * channels_ + (b - d_)] = v;
      };
      int b = a;
      for (; b + 4 <= total; b += 4) {
        float sums[4];
        weightedDot4(w, col(a), col(b), col(b + 1), col(b + 2), col(b + 3), n, sums);
        for (int k = 0; k < 4; ++k) store(b + k, sums[k]);
      }
      for (; b < total; ++b) store(b, weightedDot(w, col(a), col(b), n));
    }
  }

  // Predictions x_qᵀ β for every window row, channel c into out + c · stride; each column is
  // loaded once for all channels.
  void predict(const double* beta, const float* cols, int n, float* out) const {
    float b[kMaxGramSize][kMaxGramRhs];
    for (int a = 0; a < d_; ++a)
      for (int c = 0; c < channels_; ++c) b[a][c] = float(beta[a * channels_ + c]);
    for (int i = 0; i < n; i += 4) {
      Quad p[kMaxGramRhs];
      for (int c = 0; c < channels_; ++c) p[c] = splatQuad(b[0][c]);
      for (int a = 1; a < d_; ++a) {
        const Quad xa = loadQuad(cols + size_t(a) * size_t(stride_) + size_t(i));
        for (int c = 0; c < channels_; ++c) p[c] += splatQuad(b[a][c]) * xa;
      }
      for (int c = 0; c < channels_; ++c)
        storeQuad(out + size_t(c) * size_t(stride_) + size_t(i), p[c]);
    }
  }

  // out(q) = Σ_tiles acc / Σ_tiles wsum, tiles summed in index order for every pixel.
  Image gather(const std::vector<PixelRect>& tiles, const std::vector<TileResult>& results) const {
    Image result(width_, height_, channels_);
    const int bands = (height_ + kTileSize - 1) / kTileSize;
    tbb::parallel_for(0, bands, [&](int band) {
      const PixelRect rows{0, band * kTileSize, width_, std::min(height_, (band + 1) * kTileSize)};
      std::vector<float> acc(size_t(rows.area()) * size_t(channels_), 0.0f);
      std::vector<float> wsum(size_t(rows.area()), 0.0f);
      for (size_t t = 0; t < tiles.size(); ++t) {
        const TileResult& tr = results[t];
        const PixelRect overlap = tr.extent.intersect(rows);
        for (int y = overlap.y0; y < overlap.y1; ++y)
          for (int x = overlap.x0; x < overlap.x1; ++x) {
            const size_t src =
                size_t(y - tr.extent.y0) * size_t(tr.extent.width()) + size_t(x - tr.extent.x0);
            const size_t dst = size_t(y - rows.y0) * size_t(width_) + size_t(x);
            wsum[dst] += tr.wsum[src];
            for (int c = 0; c < channels_; ++c)
              acc[dst * size_t(channels_) + size_t(c)] +=
                  tr.acc[size_t(c) * size_t(tr.extent.area()) + src];
          }
      }
      for (int y = rows.y0; y < rows.y1; ++y)
        for (int x = 0; x < width_; ++x) {
          const size_t i = size_t(y - rows.y0) * size_t(width_) + size_t(x);
          for (int c = 0; c < channels_; ++c)
            result(x, y, c) =
                wsum[i] > 0.0f ? acc[i * size_t(channels_) + size_t(c)] / wsum[i] : u_(x, y, c);
        }
    });
    return result;
  }

  PlanarImage u_, f_;
  const NlMeansWeights& weights_;
  GramTolerances tol_;
  int width_, height_, r_, side_, channels_, m_, d_, stride_;
};

}  // namespace

Image collaborativeRegression(const Image& image, const Image& features,
                              const NlMeansWeights& weights, const GramTolerances& tolerances) {
  if (weights.weightChannels() != 1)
    throw std::invalid_argument("collaborativeRegression: needs scalar weights");
  if (!image.sameSize(features) || image.width() != weights.width() ||
      image.height() != weights.height())
    throw std::invalid_argument("collaborativeRegression: image/feature/weight sizes differ");
  if (image.channels() > kMaxGramRhs || 3 + features.channels() > kMaxGramSize)
    throw std::invalid_argument("collaborativeRegression: too many channels or features");
  return Regression(image, features, weights, tolerances).run();
}

}  // namespace chorus
