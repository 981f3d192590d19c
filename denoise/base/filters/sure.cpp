#include "denoise/base/filters/sure.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "denoise/base/buffer_variance.h"

namespace chorus {

Image sureMap(const Image& filtered, const Image& noisy, const Image& variance,
              const Image& derivative) {
  if (!filtered.sameShape(noisy) || !filtered.sameShape(variance) ||
      !(filtered.sameShape(derivative) ||
        (filtered.sameSize(derivative) && derivative.channels() == 1)))
    throw std::invalid_argument("sureMap: images differ in shape");
  const int channels = filtered.channels();
  const bool sharedDerivative = derivative.channels() == 1 && channels != 1;
  Image out(filtered.width(), filtered.height(), 1);
  for (int y = 0; y < filtered.height(); ++y)
    for (int x = 0; x < filtered.width(); ++x) {
      double sum = 0;
      for (int c = 0; c < channels; ++c) {
        const float dFdy = finiteOrZero(derivative(x, y, sharedDerivative ? 0 : c));
        sum += sureTerm(finiteOrZero(filtered(x, y, c)), finiteOrZero(noisy(x, y, c)),
                        finiteOrZero(variance(x, y, c)), dFdy);
      }
      const float value = float(sum / channels);
      out(x, y, 0) = std::isfinite(value) ? value : std::numeric_limits<float>::max();
    }
  return out;
}

}  // namespace chorus
