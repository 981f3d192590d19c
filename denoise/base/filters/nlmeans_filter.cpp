#include "denoise/base/filters/nlmeans_filter.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>

#include "denoise/planes/planar_image.h"
#include "denoise/util/simd_clones.h"

// The accumulation kernel is built for AVX-512F, AVX2 and the baseline (simd_clones.h), without
// contraction into FMA, so that every build gives the same bits. After the includes: GCC does
// not inline across different optimisation options.
#pragma GCC optimize("fp-contract=off")

namespace chorus {
namespace {

// Wide tiles, as feature_nlmeans.cpp: at 64 × 64 the row calls were too short for their set-up
// (nlm −7…−11%, NFOR −9…−21% at 256 × 32 in A/B runs; bit-identical, no contraction here).
constexpr int kTileWidth = 256, kTileHeight = 32;

std::vector<PixelRect> makeTiles(int width, int height) {
  std::vector<PixelRect> tiles;
  for (int y = 0; y < height; y += kTileHeight)
    for (int x = 0; x < width; x += kTileWidth)
      tiles.push_back({x, y, std::min(width, x + kTileWidth), std::min(height, y + kTileHeight)});
  return tiles;
}

struct TileBuffers {
  NlMeansScratch scratch;
  std::vector<float> plus, minus, center, weightSum, maxWeight;
  std::vector<std::vector<float>> acc;  // per data image: channels planes of the tile
};

// sum[x] += w[x] for x < n.
CHORUS_SIMD_CLONES void addRow(float* sum, const float* w, int n) {
  float* __restrict s = sum;
  const float* __restrict wr = w;
  for (int x = 0; x < n; ++x) s[x] += wr[x];
}

// acc[x] += w[x] · src[x] for x < n.
CHORUS_SIMD_CLONES void addProductRow(float* acc, const float* w, const float* src, int n) {
  float* __restrict a = acc;
  const float* __restrict wr = w;
  const float* __restrict sr = src;
  for (int x = 0; x < n; ++x) a[x] += wr[x] * sr[x];
}

// acc += w · u(p + δ) and wsum += w for the pixels p of the tile whose neighbour is `valid`.
void accumulate(const PixelRect& tile, const PixelRect& valid, int dx, int dy, const float* w,
                int weightChannels, const std::vector<PlanarImage>& data, TileBuffers& buf,
                bool trackMax) {
  const PixelRect inside = tile.intersect(valid);
  const size_t tArea = size_t(tile.area());
  const int tw = tile.width();
  for (int wc = 0; wc < weightChannels; ++wc) {
    const float* wPlane = w + size_t(wc) * tArea;
    float* sum = buf.weightSum.data() + size_t(wc) * tArea;
    float* maxW = buf.maxWeight.data() + size_t(wc) * tArea;
    for (int y = inside.y0; y < inside.y1; ++y) {
      const size_t begin = size_t(y - tile.y0) * size_t(tw) + size_t(inside.x0 - tile.x0);
      const size_t end = begin + size_t(inside.width());
      addRow(sum + begin, wPlane + begin, inside.width());
      if (trackMax)
        for (size_t i = begin; i < end; ++i) maxW[i] = std::max(maxW[i], wPlane[i]);
    }
  }
  for (size_t d = 0; d < data.size(); ++d) {
    const PlanarImage& u = data[d];
    for (int c = 0; c < u.channels(); ++c) {
      const float* wPlane = w + size_t(weightChannels == 1 ? 0 : c) * tArea;
      float* acc = buf.acc[d].data() + size_t(c) * tArea;
      for (int y = inside.y0; y < inside.y1; ++y) {
        const size_t rowOffset = size_t(y - tile.y0) * size_t(tw);
        const size_t at = rowOffset + size_t(inside.x0 - tile.x0);
        addProductRow(acc + at, wPlane + at, u.row(c, y + dy) + dx + inside.x0, inside.width());
      }
    }
  }
}

}  // namespace

NlMeansFilterResult nlMeansFilterAll(std::span<const Image* const> dataImages,
                                     const NlMeansWeights& weights) {
  const int width = weights.width(), height = weights.height();
  const int wch = weights.weightChannels();
  std::vector<PlanarImage> data;
  for (const Image* image : dataImages) {
    if (image->width() != width || image->height() != height)
      throw std::invalid_argument("nlMeansFilter: data and guide sizes differ");
    if (wch > 1 && image->channels() != wch)
      throw std::invalid_argument("nlMeansFilter: per-channel weights need matching channels");
    data.emplace_back(*image);
  }
  NlMeansFilterResult result;
  std::vector<PlanarImage> filtered;
  for (const PlanarImage& u : data) filtered.emplace_back(width, height, u.channels());
  PlanarImage weightSum(width, height, wch), centerWeight(width, height, wch);

  const std::vector<PixelRect> tiles = makeTiles(width, height);
  const bool maxCenter = weights.params().center == CenterWeight::MaxOfNeighbours;
  tbb::enumerable_thread_specific<TileBuffers> buffers;
  tbb::parallel_for(size_t(0), tiles.size(), [&](size_t tileIndex) {
    const PixelRect& tile = tiles[tileIndex];
    TileBuffers& buf = buffers.local();
    const size_t tArea = size_t(tile.area());
    buf.plus.resize(tArea * size_t(wch));
    buf.minus.resize(tArea * size_t(wch));
    buf.center.resize(tArea * size_t(wch));
    buf.weightSum.assign(tArea * size_t(wch), 0.0f);
    buf.maxWeight.assign(tArea * size_t(wch), 0.0f);
    buf.acc.resize(data.size());
    for (size_t d = 0; d < data.size(); ++d)
      buf.acc[d].assign(tArea * size_t(data[d].channels()), 0.0f);

    weights.center(tile, buf.scratch, buf.center.data());
    const PixelRect all = PixelRect::image(width, height);
    if (!maxCenter) accumulate(tile, all, 0, 0, buf.center.data(), wch, data, buf, false);
    weights.forEachOffsetPair([&](int dx, int dy) {
      weights.offsetPair(tile, dx, dy, buf.scratch, buf.plus.data(), buf.minus.data());
      accumulate(tile, neighbourInside(width, height, dx, dy), dx, dy, buf.plus.data(), wch, data,
                 buf, maxCenter);
      accumulate(tile, neighbourInside(width, height, -dx, -dy), -dx, -dy, buf.minus.data(), wch,
                 data, buf, maxCenter);
    });
    if (maxCenter) {
      for (size_t i = 0; i < buf.center.size(); ++i)
        buf.center[i] = std::max(buf.center[i], buf.maxWeight[i]);
      accumulate(tile, all, 0, 0, buf.center.data(), wch, data, buf, false);
    }

    // Normalise and write the tile out.
    for (int y = tile.y0; y < tile.y1; ++y) {
      for (int x = tile.x0; x < tile.x1; ++x) {
        const size_t i = size_t(y - tile.y0) * size_t(tile.width()) + size_t(x - tile.x0);
        for (int wc = 0; wc < wch; ++wc) {
          weightSum(x, y, wc) = buf.weightSum[size_t(wc) * tArea + i];
          centerWeight(x, y, wc) = buf.center[size_t(wc) * tArea + i];
        }
        for (size_t d = 0; d < data.size(); ++d) {
          for (int c = 0; c < data[d].channels(); ++c) {
            const float wsum = buf.weightSum[size_t(wch == 1 ? 0 : c) * tArea + i];
            filtered[d](x, y, c) =
                wsum > 0.0f ? buf.acc[d][size_t(c) * tArea + i] / wsum : data[d](x, y, c);
          }
        }
      }
    }
  });

  for (const PlanarImage& f : filtered) result.filtered.push_back(f.toImage());
  result.weightSum = weightSum.toImage();
  result.centerWeight = centerWeight.toImage();
  return result;
}

Image nlMeansFilter(const Image& data, const NlMeansWeights& weights) {
  const Image* images[] = {&data};
  return std::move(nlMeansFilterAll(images, weights).filtered[0]);
}

Image nlMeans(const Image& data, const NlMeansTerm& term, const NlMeansParams& params) {
  return nlMeansFilter(data, NlMeansWeights(term, params));
}

}  // namespace chorus
