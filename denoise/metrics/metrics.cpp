#include "denoise/metrics/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "common/error.h"

namespace chorus {

namespace {

void checkShapes(const Image& image, const Image& reference) {
  if (!image.sameShape(reference))
    throw Error("image is " + std::to_string(image.width()) + "x" + std::to_string(image.height()) +
                "x" + std::to_string(image.channels()) + " but the reference is " +
                std::to_string(reference.width()) + "x" + std::to_string(reference.height()) + "x" +
                std::to_string(reference.channels()));
  if (image.empty()) throw Error("cannot compare empty images");
}

template <typename PerValue>
double meanOver(const Image& image, const Image& reference, PerValue perValue) {
  checkShapes(image, reference);
  double sum = 0;
  for (size_t i = 0; i < image.size(); ++i)
    sum += perValue(double(image.data()[i]), double(reference.data()[i]));
  return sum / double(image.size());
}

double displayValue(double v) {
  return std::pow(std::clamp(v, 0.0, 1.0), 1.0 / 2.2);
}

// Normalised 1-D Gaussian taps of the SSIM window.
std::vector<double> gaussianTaps(int size, double sigma) {
  std::vector<double> taps(static_cast<size_t>(size));
  double sum = 0;
  for (int i = 0; i < size; ++i) {
    const double d = i - (size - 1) / 2.0;
    taps[size_t(i)] = std::exp(-d * d / (2 * sigma * sigma));
    sum += taps[size_t(i)];
  }
  for (double& t : taps) t /= sum;
  return taps;
}

// Separable "valid" convolution of a w×h plane with taps wx (horizontal) and wy (vertical).
std::vector<double> filterValid(const std::vector<double>& plane, int w, int h,
                                const std::vector<double>& wx, const std::vector<double>& wy) {
  const int kx = int(wx.size()), ky = int(wy.size());
  const int ow = w - kx + 1, oh = h - ky + 1;
  std::vector<double> rows(size_t(ow) * size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < ow; ++x) {
      double s = 0;
      for (int i = 0; i < kx; ++i)
        s += wx[size_t(i)] * plane[size_t(y) * size_t(w) + size_t(x + i)];
      rows[size_t(y) * size_t(ow) + size_t(x)] = s;
    }
  std::vector<double> out(size_t(ow) * size_t(oh));
  for (int y = 0; y < oh; ++y)
    for (int x = 0; x < ow; ++x) {
      double s = 0;
      for (int j = 0; j < ky; ++j)
        s += wy[size_t(j)] * rows[size_t(y + j) * size_t(ow) + size_t(x)];
      out[size_t(y) * size_t(ow) + size_t(x)] = s;
    }
  return out;
}

}  // namespace

double mse(const Image& image, const Image& reference) {
  return meanOver(image, reference, [](double x, double r) { return (x - r) * (x - r); });
}

double relMse(const Image& image, const Image& reference, double epsilon) {
  return meanOver(image, reference,
                  [epsilon](double x, double r) { return (x - r) * (x - r) / (r * r + epsilon); });
}

double psnr(const Image& image, const Image& reference) {
  const double e = mse(image, reference);
  return e > 0 ? 10.0 * std::log10(1.0 / e) : std::numeric_limits<double>::infinity();
}

double smape(const Image& image, const Image& reference, double epsilon) {
  return meanOver(image, reference, [epsilon](double x, double r) {
    return std::abs(x - r) / (std::abs(x) + std::abs(r) + epsilon);
  });
}

double ssim(const Image& image, const Image& reference) {
  checkShapes(image, reference);
  constexpr double kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03, kSigma = 1.5;
  const int w = image.width(), h = image.height(), channels = image.channels();
  const std::vector<double> wx = gaussianTaps(std::min(11, w), kSigma);
  const std::vector<double> wy = gaussianTaps(std::min(11, h), kSigma);
  const size_t n = image.pixelCount();
  double total = 0;
  size_t windows = 0;
  for (int c = 0; c < channels; ++c) {
    std::vector<double> x(n), y(n), xx(n), yy(n), xy(n);
    for (size_t i = 0; i < n; ++i) {
      x[i] = displayValue(image.data()[i * size_t(channels) + size_t(c)]);
      y[i] = displayValue(reference.data()[i * size_t(channels) + size_t(c)]);
      xx[i] = x[i] * x[i];
      yy[i] = y[i] * y[i];
      xy[i] = x[i] * y[i];
    }
    const auto mx = filterValid(x, w, h, wx, wy), my = filterValid(y, w, h, wx, wy);
    const auto mxx = filterValid(xx, w, h, wx, wy), myy = filterValid(yy, w, h, wx, wy);
    const auto mxy = filterValid(xy, w, h, wx, wy);
    for (size_t i = 0; i < mx.size(); ++i) {
      const double vx = mxx[i] - mx[i] * mx[i], vy = myy[i] - my[i] * my[i];
      const double cxy = mxy[i] - mx[i] * my[i];
      total += ((2 * mx[i] * my[i] + kC1) * (2 * cxy + kC2)) /
               ((mx[i] * mx[i] + my[i] * my[i] + kC1) * (vx + vy + kC2));
    }
    windows += mx.size();
  }
  return total / double(windows);
}

double dssim(const Image& image, const Image& reference) {
  return (1.0 - ssim(image, reference)) / 2.0;
}

ImageMetrics computeMetrics(const Image& image, const Image& reference) {
  ImageMetrics m;
  m.mse = mse(image, reference);
  m.relMse = relMse(image, reference);
  m.psnr = psnr(image, reference);
  m.ssim = ssim(image, reference);
  m.dssim = (1.0 - m.ssim) / 2.0;
  m.smape = smape(image, reference);
  return m;
}

Image relMseMap(const Image& image, const Image& reference, double epsilon) {
  checkShapes(image, reference);
  Image map(image.width(), image.height(), 1);
  const int channels = image.channels();
  for (size_t p = 0; p < image.pixelCount(); ++p) {
    double sum = 0;
    for (int c = 0; c < channels; ++c) {
      const double x = image.data()[p * size_t(channels) + size_t(c)];
      const double r = reference.data()[p * size_t(channels) + size_t(c)];
      sum += (x - r) * (x - r) / (r * r + epsilon);
    }
    map.data()[p] = float(sum / channels);
  }
  return map;
}

}  // namespace chorus
