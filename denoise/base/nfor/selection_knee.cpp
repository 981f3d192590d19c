#include "denoise/base/nfor/selection_knee.h"

#include <algorithm>
#include <cmath>

namespace chorus {

void kneeBrightErrors(Image& mse0, Image& mse1, const Image& colour, const Image& level,
                      float knee) {
  if (!(knee > 0) || colour.size() == 0) return;
  double sum = 0;
  for (size_t e = 0; e < colour.size(); ++e)
    if (std::isfinite(colour.data()[e])) sum += std::abs(double(colour.data()[e]));
  const double unit = double(knee) * sum / double(colour.size());
  if (!(unit > 0) || !std::isfinite(unit)) return;
  for (size_t e = 0; e < level.size(); ++e) {
    const double r = double(level.data()[e]) / unit;
    if (!(r * r > 1.0)) continue;  // below the knee, or not finite
    mse0.data()[e] = float(double(mse0.data()[e]) / (r * r));
    mse1.data()[e] = float(double(mse1.data()[e]) / (r * r));
  }
}

}  // namespace chorus
