#include "denoise/base/buffer_variance.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "denoise/base/filters/box_filter.h"
#include "denoise/util/parallel_rows.h"

namespace chorus {
namespace {

void requireSameShape(const Image& a, const Image& b, const char* what) {
  if (!a.sameShape(b)) throw std::invalid_argument(std::string(what) + ": shapes differ");
}

bool known(const std::vector<uint8_t>* mask, size_t pixel) {
  return !mask || (*mask)[pixel] != 0;
}

}  // namespace

Image finiteOr(const Image& image, float replacement) {
  Image out = image;
  float* values = out.data();
  parallelChunks(out.size(), [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k)
      values[k] = std::isfinite(values[k]) ? values[k] : replacement;
  });
  return out;
}

std::vector<uint8_t> finiteMask(std::initializer_list<const Image*> images) {
  const Image& first = **images.begin();
  std::vector<uint8_t> mask(first.pixelCount(), 1);
  for (const Image* image : images) {
    if (!image->sameSize(first)) throw std::invalid_argument("finiteMask: sizes differ");
    const int channels = image->channels();
    for (size_t i = 0; i < mask.size(); ++i)
      for (int c = 0; c < channels; ++c)
        if (!std::isfinite(image->data()[i * size_t(channels) + size_t(c)])) mask[i] = 0;
  }
  return mask;
}

Image meanOf(const Image& a, const Image& b) {
  requireSameShape(a, b, "meanOf");
  Image out(a.width(), a.height(), a.channels());
  parallelChunks(a.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) out.data()[i] = 0.5f * (a.data()[i] + b.data()[i]);
  });
  return out;
}

Image squaredDifference(const Image& a, const Image& b, float scale) {
  requireSameShape(a, b, "squaredDifference");
  Image out(a.width(), a.height(), a.channels());
  parallelChunks(a.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const float d = a.data()[i] - b.data()[i];
      const float v = d * d * scale;
      out.data()[i] = std::isfinite(v) ? v : 0.0f;
    }
  });
  return out;
}

Image completedVariance(const Image& sampleVariance, const Image& twoBuffer) {
  requireSameShape(sampleVariance, twoBuffer, "completedVariance");
  Image out(sampleVariance.width(), sampleVariance.height(), sampleVariance.channels());
  parallelChunks(out.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const float s = sampleVariance.data()[i], t = twoBuffer.data()[i];
      const bool measured = std::isfinite(s) && s >= 0.0f && (s > 0.0f || !(t > 0.0f));
      out.data()[i] = measured ? s : (std::isfinite(t) ? std::max(t, 0.0f) : 0.0f);
    }
  });
  return out;
}

Image rescaledVariance(const Image& sampleVariance, const Image& twoBuffer, int radius,
                       const std::vector<uint8_t>* mask) {
  requireSameShape(sampleVariance, twoBuffer, "rescaledVariance");
  const int channels = sampleVariance.channels();
  Image sample = finiteOr(sampleVariance, 0.0f), buffer = finiteOr(twoBuffer, 0.0f);
  if (mask)
    for (size_t i = 0; i < sample.pixelCount(); ++i)
      for (int c = 0; c < channels; ++c) {
        const size_t k = i * size_t(channels) + size_t(c);
        if (!known(mask, i)) sample.data()[k] = buffer.data()[k] = 0.0f;
      }
  const Image sampleBox = boxFilter(sample, radius), bufferBox = boxFilter(buffer, radius);
  Image out(sample.width(), sample.height(), channels);
  parallelChunks(out.size(), [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      const float v = sample.data()[k] * bufferBox.data()[k] / (1e-10f + sampleBox.data()[k]);
      out.data()[k] = std::isfinite(v) && v > 0.0f ? v : 0.0f;
    }
  });
  return out;
}

Image smooth3Tap(const Image& image, float sideWeight, const std::vector<uint8_t>* mask) {
  const int w = image.width(), h = image.height(), channels = image.channels();
  auto pass = [&](const Image& in, int sx, int sy) {
    Image out(w, h, channels);
    parallelRows(0, h, [&](int y) {
      for (int x = 0; x < w; ++x) {
        const size_t centre = size_t(y) * size_t(w) + size_t(x);
        for (int c = 0; c < channels; ++c) {
          float sum = known(mask, centre) ? in(x, y, c) : 0.0f;
          float weight = known(mask, centre) ? 1.0f : 0.0f;
          for (int side : {-1, 1}) {
            const int qx = x + side * sx, qy = y + side * sy;
            if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
            if (!known(mask, size_t(qy) * size_t(w) + size_t(qx))) continue;
            sum += sideWeight * in(qx, qy, c);
            weight += sideWeight;
          }
          out(x, y, c) = weight > 0.0f ? sum / weight : 0.0f;
        }
      }
    });
    return out;
  };
  const Image finite = finiteOr(image, 0.0f);
  return pass(pass(finite, 1, 0), 0, 1);
}

Image squaredGradient(const Image& image, const std::vector<uint8_t>* mask) {
  const int w = image.width(), h = image.height(), channels = image.channels();
  const Image f = finiteOr(image, 0.0f);
  Image out(w, h, channels);
  auto axis = [&](int x, int y, int c, int sx, int sy) {
    const int ax = x - sx, ay = y - sy, bx = x + sx, by = y + sy;
    if (ax < 0 || ay < 0 || bx >= w || by >= h) return 0.0f;
    if (!known(mask, size_t(ay) * size_t(w) + size_t(ax)) ||
        !known(mask, size_t(by) * size_t(w) + size_t(bx)))
      return 0.0f;
    const float ga = 0.5f * (f(ax, ay, c) - f(x, y, c)), gb = 0.5f * (f(bx, by, c) - f(x, y, c));
    return std::min(ga * ga, gb * gb);
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) out(x, y, c) = axis(x, y, c, 1, 0) + axis(x, y, c, 0, 1);
  return out;
}

}  // namespace chorus
