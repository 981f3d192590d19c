#include "denoise/base/min_weights_filter.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>

#include "denoise/base/filters/planar_image.h"

namespace chorus {
namespace {

constexpr int kTile = 64;

struct TileMemory {
  NlMeansScratch scratch;
  std::vector<float> plus, minus, setPlus, setMinus, weightSum, maxWeight;
  std::vector<std::vector<float>> acc;
};

}  // namespace

std::vector<Image> nlMeansFilterMin(std::span<const Image* const> dataImages,
                                    std::span<const NlMeansWeights* const> weights,
                                    float minCenterWeight) {
  if (weights.empty()) throw std::invalid_argument("nlMeansFilterMin: no weights");
  const NlMeansWeights& first = *weights[0];
  const int width = first.width(), height = first.height(), r = first.params().r;
  for (const NlMeansWeights* w : weights)
    if (w->width() != width || w->height() != height || w->weightChannels() != 1 ||
        w->params().r != r)
      throw std::invalid_argument("nlMeansFilterMin: weight sets differ in size, channels or r");
  std::vector<PlanarImage> data;
  for (const Image* image : dataImages) {
    if (image->width() != width || image->height() != height)
      throw std::invalid_argument("nlMeansFilterMin: data and weights sizes differ");
    data.emplace_back(*image);
  }
  std::vector<PlanarImage> filtered;
  for (const PlanarImage& u : data) filtered.emplace_back(width, height, u.channels());

  std::vector<PixelRect> tiles;
  for (int y = 0; y < height; y += kTile)
    for (int x = 0; x < width; x += kTile)
      tiles.push_back({x, y, std::min(width, x + kTile), std::min(height, y + kTile)});

  tbb::enumerable_thread_specific<TileMemory> memory;
  tbb::parallel_for(size_t(0), tiles.size(), [&](size_t t) {
    const PixelRect& tile = tiles[t];
    TileMemory& m = memory.local();
    const size_t area = size_t(tile.area());
    const int tw = tile.width();
    m.plus.resize(area);
    m.minus.resize(area);
    m.setPlus.resize(area);
    m.setMinus.resize(area);
    m.weightSum.assign(area, 0.0f);
    m.maxWeight.assign(area, 0.0f);
    m.acc.resize(data.size());
    for (size_t d = 0; d < data.size(); ++d)
      m.acc[d].assign(area * size_t(data[d].channels()), 0.0f);

    auto accumulate = [&](int dx, int dy, const float* w) {
      const PixelRect inside = tile.intersect(neighbourInside(width, height, dx, dy));
      for (int y = inside.y0; y < inside.y1; ++y) {
        const size_t row = size_t(y - tile.y0) * size_t(tw);
        for (int x = inside.x0; x < inside.x1; ++x) {
          const size_t i = row + size_t(x - tile.x0);
          m.weightSum[i] += w[i];
          m.maxWeight[i] = std::max(m.maxWeight[i], w[i]);
        }
        for (size_t d = 0; d < data.size(); ++d)
          for (int c = 0; c < data[d].channels(); ++c) {
            const float* __restrict src = data[d].row(c, y + dy) + dx;
            float* __restrict acc = m.acc[d].data() + size_t(c) * area + row - size_t(tile.x0);
            const float* __restrict wr = w + row - size_t(tile.x0);
            for (int x = inside.x0; x < inside.x1; ++x) acc[x] += wr[x] * src[x];
          }
      }
    };

    for (int dy = 0; dy <= r; ++dy)
      for (int dx = dy == 0 ? 1 : -r; dx <= r; ++dx) {
        weights[0]->offsetPair(tile, dx, dy, m.scratch, m.plus.data(), m.minus.data());
        for (size_t k = 1; k < weights.size(); ++k) {
          weights[k]->offsetPair(tile, dx, dy, m.scratch, m.setPlus.data(), m.setMinus.data());
          for (size_t i = 0; i < area; ++i) {
            m.plus[i] = std::min(m.plus[i], m.setPlus[i]);
            m.minus[i] = std::min(m.minus[i], m.setMinus[i]);
          }
        }
        accumulate(dx, dy, m.plus.data());
        accumulate(-dx, -dy, m.minus.data());
      }

    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x) {
        const size_t i = size_t(y - tile.y0) * size_t(tw) + size_t(x - tile.x0);
        const float centre = std::max(m.maxWeight[i], minCenterWeight);
        const float total = m.weightSum[i] + centre;
        for (size_t d = 0; d < data.size(); ++d)
          for (int c = 0; c < data[d].channels(); ++c)
            filtered[d](x, y, c) =
                (m.acc[d][size_t(c) * area + i] + centre * data[d](x, y, c)) / total;
      }
  });

  std::vector<Image> out;
  for (const PlanarImage& f : filtered) out.push_back(f.toImage());
  return out;
}

}  // namespace chorus
