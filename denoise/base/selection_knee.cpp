#include "denoise/base/selection_knee.h"

#include <cmath>

namespace chorus {

double kneeLevel(std::span<const float> colour, float knee) {
  if (!(knee > 0) || colour.empty()) return 0.0;
  double sum = 0;
  for (float v : colour)
    if (std::isfinite(v)) sum += std::abs(double(v));
  const double level = double(knee) * sum / double(colour.size());
  return level > 0 && std::isfinite(level) ? level : 0.0;
}

double kneeDivisor(double level, double kneeLevel) {
  if (!(kneeLevel > 0)) return 1.0;
  const double r = level / kneeLevel;
  return r * r > 1.0 ? r * r : 1.0;  // below the knee, or not finite: 1
}

std::vector<float> kneeDivisors(const Image& rgb, double kneeLevel) {
  std::vector<float> divisors(rgb.pixelCount(), 1.0f);
  if (!(kneeLevel > 0)) return divisors;
  for (size_t i = 0; i < divisors.size(); ++i)
    divisors[i] = float(kneeDivisor(rgbLevel(rgb, i), kneeLevel));
  return divisors;
}

void divideByPixel(Image& rgb, std::span<const float> divisors) {
  for (size_t k = 0; k < rgb.size(); ++k) rgb.data()[k] /= divisors[k / 3];
}

Image kneedVariance(Image variance, const Image& guide, double kneeLevel) {
  if (kneeLevel > 0) divideByPixel(variance, kneeDivisors(guide, kneeLevel));
  return variance;
}

}  // namespace chorus
