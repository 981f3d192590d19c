#include "denoise/ensemble/weight_filter.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "denoise/ensemble/planar_filter.h"

namespace chorus {
namespace {

// Calls body(p0, p1) for blocks of pixel indices in parallel (element-wise conversions).
template <typename Body>
void forPixelBlocks(size_t pixels, const Body& body) {
  constexpr size_t kBlock = 16384;
  tbb::parallel_for(size_t(0), (pixels + kBlock - 1) / kBlock, [&](size_t block) {
    body(block * kBlock, std::min(pixels, (block + 1) * kBlock));
  });
}

// Planar copy of an interleaved image: plane c holds channel c, row-major.
std::vector<float> toPlanes(const Image& image) {
  const size_t pixels = image.pixelCount();
  const int channels = image.channels();
  std::vector<float> planes(pixels * size_t(channels));
  const float* src = image.data();
  forPixelBlocks(pixels, [&](size_t p0, size_t p1) {
    for (size_t p = p0; p < p1; ++p)
      for (int c = 0; c < channels; ++c) {
        const float v = src[p * size_t(channels) + size_t(c)];
        planes[size_t(c) * pixels + p] = std::isfinite(v) ? v : 0.0f;
      }
  });
  return planes;
}

// Separable Gaussian blur with clipped, renormalised borders (double accumulation). Each sum
// adds its taps in the order of the offset d (ascending) and its weight is the sum of the taps
// used, in the same order; the loops run over whole rows per offset so that they vectorise.
Image gaussianBlur(const Image& image, int radius, float sigma) {
  const int w = image.width(), h = image.height(), channels = image.channels();
  const size_t rowLength = size_t(w) * size_t(channels);
  std::vector<double> taps(size_t(2 * radius + 1));
  for (int d = -radius; d <= radius; ++d)
    taps[size_t(d + radius)] = std::exp(-0.5 * d * d / (double(sigma) * sigma));
  // The weight of a pixel at position i of n: the taps whose neighbour is inside.
  const auto weightsFor = [&](int n) {
    std::vector<double> weights(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
      double weight = 0;
      for (int d = std::max(-radius, -i); d <= std::min(radius, n - 1 - i); ++d)
        weight += taps[size_t(d + radius)];
      weights[size_t(i)] = weight;
    }
    return weights;
  };
  const std::vector<double> weightX = weightsFor(w), weightY = weightsFor(h);
  Image horizontal(w, h, channels), out(w, h, channels);
  tbb::parallel_for(0, h, [&](int y) {
    std::vector<double> sum(rowLength, 0.0);
    const float* src = image.data() + size_t(y) * rowLength;
    for (int d = -radius; d <= radius; ++d) {
      const double tap = taps[size_t(d + radius)];
      const int x0 = std::max(0, -d), x1 = std::min(w, w - d);
      const size_t e0 = size_t(x0) * size_t(channels),
                   e1 = size_t(std::max(x0, x1)) * size_t(channels);
      const ptrdiff_t shift = ptrdiff_t(d) * channels;
      for (size_t e = e0; e < e1; ++e) sum[e] += tap * src[ptrdiff_t(e) + shift];
    }
    float* dst = horizontal.data() + size_t(y) * rowLength;
    for (size_t e = 0; e < rowLength; ++e) dst[e] = float(sum[e] / weightX[e / size_t(channels)]);
  });
  tbb::parallel_for(0, h, [&](int y) {
    std::vector<double> sum(rowLength, 0.0);
    for (int d = std::max(-radius, -y); d <= std::min(radius, h - 1 - y); ++d) {
      const double tap = taps[size_t(d + radius)];
      const float* src = horizontal.data() + size_t(y + d) * rowLength;
      for (size_t e = 0; e < rowLength; ++e) sum[e] += tap * src[e];
    }
    float* dst = out.data() + size_t(y) * rowLength;
    const double weight = weightY[size_t(y)];
    for (size_t e = 0; e < rowLength; ++e) dst[e] = float(sum[e] / weight);
  });
  return out;
}

// The guide from z and a per-element estimate of a half blend's variance, halfVariance(e)
// (in z's units; divided by s² here).
template <typename HalfVariance>
ColorGuide colorGuide(const Image& blend, const HalfVariance& halfVarianceAt,
                      const WeightFilterOptions& options) {
  double sum = 0;
  size_t count = 0;
  for (float v : blend.values())
    if (std::isfinite(v)) sum += std::abs(double(v)), ++count;
  double scale = count > 0 ? sum / double(count) : 1.0;
  if (!(scale > 0.0) || !std::isfinite(scale)) scale = 1.0;

  ColorGuide guide;
  guide.color = Image(blend.width(), blend.height(), blend.channels());
  Image halfVariance(blend.width(), blend.height(), blend.channels());
  const int channels = blend.channels();
  forPixelBlocks(blend.pixelCount(), [&](size_t p0, size_t p1) {
    for (size_t e = p0 * size_t(channels); e < p1 * size_t(channels); ++e) {
      const double z = blend.data()[e] / scale;
      guide.color.data()[e] = std::isfinite(z) ? float(std::clamp(z, -1e6, 1e6)) : 0.0f;
      const double v = halfVarianceAt(e) / scale / scale;
      halfVariance.data()[e] = std::isfinite(v) ? float(std::min(v, 1e12)) : 1e12f;
    }
  });
  guide.variance =
      gaussianBlur(halfVariance, options.varianceBlurRadius, options.varianceBlurSigma);
  if (options.relativeTolerance > 0)
    forPixelBlocks(blend.pixelCount(), [&](size_t p0, size_t p1) {
      for (size_t e = p0 * size_t(channels); e < p1 * size_t(channels); ++e) {
        const double tolerance = options.relativeTolerance * guide.color.data()[e];
        guide.variance.data()[e] =
            float(std::min(1e12, double(guide.variance.data()[e]) + tolerance * tolerance));
      }
    });
  return guide;
}

}  // namespace

ColorGuide makeColorGuide(const Image& blend, const Image& blendA, const Image& blendB,
                          const WeightFilterOptions& options) {
  if (!blend.sameShape(blendA) || !blend.sameShape(blendB))
    throw Error("makeColorGuide: the blends differ in shape");
  return colorGuide(
      blend,
      [&](size_t e) {
        const double d = double(blendA.data()[e]) - blendB.data()[e];
        return 0.5 * d * d;
      },
      options);
}

ColorGuide makeColorGuide(const Image& blend, std::span<const Image> heldOutBlends,
                          const WeightFilterOptions& options) {
  if (heldOutBlends.size() != 4) throw Error("makeColorGuide: expected four held-out blends");
  for (const Image& image : heldOutBlends)
    if (!blend.sameShape(image)) throw Error("makeColorGuide: the blends differ in shape");
  return colorGuide(
      blend,
      [&](size_t e) {
        // z^(−k) − z̄ = (x̄ − x_k)/3 for a linear blend: Σ_k (z^(−k) − z̄)² estimates 3/9 of a
        // quarter's variance, i.e. 2/3 of a half's.
        double mean = 0, sum = 0;
        for (const Image& z : heldOutBlends) mean += 0.25 * z.data()[e];
        for (const Image& z : heldOutBlends) sum += (z.data()[e] - mean) * (z.data()[e] - mean);
        return 1.5 * sum;
      },
      options);
}

std::vector<Image> crossBilateralFilter(std::span<const Image> maps, const ColorGuide& guide,
                                        const Image& normal, const Image& albedo,
                                        const WeightFilterOptions& options) {
  if (maps.empty()) return {};
  const int w = maps[0].width(), h = maps[0].height();
  for (const Image* image : {&guide.color, &guide.variance, &normal, &albedo})
    if (image->width() != w || image->height() != h || image->channels() != 3)
      throw Error("crossBilateralFilter: guides must be RGB of the maps' size");
  const size_t pixels = size_t(w) * size_t(h);

  PlanarGuides guides;
  guides.width = w;
  guides.height = h;
  guides.normal = toPlanes(normal);
  guides.albedo = toPlanes(albedo);
  guides.color = toPlanes(guide.color);
  guides.variance = toPlanes(guide.variance);
  BilateralKernel kernel;
  kernel.radius = std::max(0, options.radius);
  kernel.kSpatial = 0.5f / (options.sigmaSpatial * options.sigmaSpatial);
  kernel.kColor = 0.5f / (options.sigmaColor * options.sigmaColor);
  kernel.kNormal = 0.5f / (options.sigmaNormal * options.sigmaNormal);
  kernel.kAlbedo = 0.5f / (options.sigmaAlbedo * options.sigmaAlbedo);

  std::vector<std::vector<float>> mapPlanes;
  std::vector<const float*> in;
  for (const Image& map : maps) {
    if (map.width() != w || map.height() != h)
      throw Error("crossBilateralFilter: maps differ in size");
    mapPlanes.push_back(toPlanes(map));
    for (int c = 0; c < map.channels(); ++c)
      in.push_back(mapPlanes.back().data() + size_t(c) * pixels);
  }
  std::vector<float> outPlanes(in.size() * pixels);
  std::vector<float*> out;
  for (size_t j = 0; j < in.size(); ++j) out.push_back(outPlanes.data() + j * pixels);
  // Tall tasks: the filter evaluates the kernel pairs that straddle a task's top edge twice.
  constexpr int kRowsPerTask = 64;
  tbb::parallel_for(0, (h + kRowsPerTask - 1) / kRowsPerTask, [&](int task) {
    const int y0 = task * kRowsPerTask, y1 = std::min(h, y0 + kRowsPerTask);
    std::vector<float*> rowsOut;
    for (float* plane : out) rowsOut.push_back(plane + size_t(y0) * size_t(w));
    filterPlaneRows(guides, kernel, in, 0, y0, y1, rowsOut);
  });

  std::vector<Image> result;
  size_t j = 0;
  for (const Image& map : maps) {
    const int channels = map.channels();
    Image image(w, h, channels);
    forPixelBlocks(pixels, [&](size_t p0, size_t p1) {
      for (size_t p = p0; p < p1; ++p)
        for (int c = 0; c < channels; ++c)
          image.data()[p * size_t(channels) + size_t(c)] = out[j + size_t(c)][p];
    });
    j += size_t(channels);
    result.push_back(std::move(image));
  }
  return result;
}

std::vector<Image> renormalizeWeights(std::span<const Image> weights,
                                      std::span<const BaseMask> valid,
                                      std::span<const Image> fallback, bool nonNegative) {
  std::vector<Image> out(weights.begin(), weights.end());
  if (weights.empty()) return out;
  const int n = int(weights.size());
  const int channels = weights[0].channels();
  const size_t pixels = weights[0].pixelCount();
  tbb::parallel_for(size_t(0), pixels, [&](size_t p) {
    for (int c = 0; c < channels; ++c) {
      const size_t e = p * size_t(channels) + size_t(c);
      double sum = 0.0;
      for (int i = 0; i < n; ++i) {
        float& v = out[size_t(i)].data()[e];
        if (!((valid[p] >> i) & 1u) || !std::isfinite(v)) v = 0.0f;
        if (nonNegative && v < 0.0f) v = 0.0f;
        sum += v;
      }
      const bool usable = std::isfinite(sum) && (nonNegative ? sum > 0.0 : std::abs(sum) > 1e-6);
      for (int i = 0; i < n; ++i) {
        float& v = out[size_t(i)].data()[e];
        v = usable ? float(v / sum) : fallback[size_t(i)].data()[e];
      }
    }
  });
  return out;
}

}  // namespace chorus
