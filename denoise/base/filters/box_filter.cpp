#include "denoise/base/filters/box_filter.h"

#include <algorithm>

#include "denoise/base/filters/planar_image.h"

namespace chorus {
namespace {

// Radii up to this sum their taps directly; beyond, running sums are cheaper.
constexpr int kMaxDirectRadius = 4;

// out[i] = mean of in[j] for j in [i - r, i + r] ∩ [0, n).
void boxRowDirect(const float* in, float* out, int n, int r) {
  const float inv = 1.0f / float(2 * r + 1);
  const int interiorBegin = std::min(r, n), interiorEnd = std::max(interiorBegin, n - r);
  // Taps in ascending order for every pixel (also the clipped ones below), x innermost so that
  // the loop vectorises.
  for (int x = interiorBegin; x < interiorEnd; ++x) out[x] = in[x - r];
  for (int j = -r + 1; j <= r; ++j)
    for (int x = interiorBegin; x < interiorEnd; ++x) out[x] += in[x + j];
  for (int x = interiorBegin; x < interiorEnd; ++x) out[x] *= inv;
  auto clipped = [&](int x) {
    const int a = std::max(0, x - r), b = std::min(n - 1, x + r);
    float s = 0.0f;
    for (int j = a; j <= b; ++j) s += in[j];
    out[x] = s / float(b - a + 1);
  };
  for (int x = 0; x < interiorBegin; ++x) clipped(x);
  for (int x = interiorEnd; x < n; ++x) clipped(x);
}

void boxRowRunning(const float* in, float* out, int n, int r) {
  double s = 0.0;
  for (int j = 0; j < std::min(r, n); ++j) s += in[j];
  for (int x = 0; x < n; ++x) {
    if (x + r < n) s += in[x + r];
    const int a = std::max(0, x - r), b = std::min(n - 1, x + r);
    out[x] = float(s / double(b - a + 1));
    if (x - r >= 0) s -= in[x - r];
  }
}

}  // namespace

void boxFilterPlane(const float* src, float* dst, int width, int height, int radius,
                    std::vector<float>& tmp) {
  if (width <= 0 || height <= 0) return;
  const size_t w = size_t(width);
  tmp.resize(w * size_t(height));
  if (radius <= 0) {
    if (dst != src) std::copy(src, src + w * size_t(height), dst);
    return;
  }
  // Row pass into tmp.
  for (int y = 0; y < height; ++y) {
    if (radius <= kMaxDirectRadius)
      boxRowDirect(src + size_t(y) * w, tmp.data() + size_t(y) * w, width, radius);
    else
      boxRowRunning(src + size_t(y) * w, tmp.data() + size_t(y) * w, width, radius);
  }
  // Column pass: each output row is the mean of the clipped run of tmp rows.
  if (radius <= kMaxDirectRadius) {
    for (int y = 0; y < height; ++y) {
      const int a = std::max(0, y - radius), b = std::min(height - 1, y + radius);
      const float inv = 1.0f / float(b - a + 1);
      float* out = dst + size_t(y) * w;
      const float* first = tmp.data() + size_t(a) * w;
      for (size_t x = 0; x < w; ++x) out[x] = first[x];
      for (int j = a + 1; j <= b; ++j) {
        const float* in = tmp.data() + size_t(j) * w;
        for (size_t x = 0; x < w; ++x) out[x] += in[x];
      }
      for (size_t x = 0; x < w; ++x) out[x] *= inv;
    }
    return;
  }
  std::vector<double> sums(w, 0.0);
  for (int j = 0; j < std::min(radius, height); ++j)
    for (size_t x = 0; x < w; ++x) sums[x] += tmp[size_t(j) * w + x];
  for (int y = 0; y < height; ++y) {
    if (y + radius < height)
      for (size_t x = 0; x < w; ++x) sums[x] += tmp[size_t(y + radius) * w + x];
    const int a = std::max(0, y - radius), b = std::min(height - 1, y + radius);
    const double inv = 1.0 / double(b - a + 1);
    for (size_t x = 0; x < w; ++x) dst[size_t(y) * w + x] = float(sums[x] * inv);
    if (y - radius >= 0)
      for (size_t x = 0; x < w; ++x) sums[x] -= tmp[size_t(y - radius) * w + x];
  }
}

Image boxFilter(const Image& image, int radius) {
  PlanarImage planes(image);
  std::vector<float> tmp;
  for (int c = 0; c < planes.channels(); ++c)
    boxFilterPlane(planes.plane(c), planes.plane(c), planes.width(), planes.height(), radius, tmp);
  return planes.toImage();
}

}  // namespace chorus
