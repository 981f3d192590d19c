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

void kneeBrightErrors(Image& mse0, Image& mse1, const Image& colour, const Image& level,
                      float knee) {
  const double unit = kneeLevel({colour.data(), colour.size()}, knee);
  if (!(unit > 0)) return;
  for (size_t e = 0; e < level.size(); ++e) {
    const double d = kneeDivisor(double(level.data()[e]), unit);
    if (d == 1.0) continue;
    mse0.data()[e] = float(double(mse0.data()[e]) / d);
    mse1.data()[e] = float(double(mse1.data()[e]) / d);
  }
}

}  // namespace chorus
