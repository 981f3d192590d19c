#include "common/image/output_values.h"

#include <cmath>
#include <limits>

namespace chorus {

OutputRepairs repairForOutput(Image& image, bool signedValues) {
  constexpr float kMax = std::numeric_limits<float>::max();
  OutputRepairs repairs;
  for (float& v : image.values()) {
    if (std::isnan(v)) {
      v = 0.0f, ++repairs.nonFinite;
    } else if (std::isinf(v)) {
      v = v > 0 ? kMax : (signedValues ? -kMax : 0.0f), ++repairs.nonFinite;
    } else if (v < 0.0f && !signedValues) {
      v = 0.0f, ++repairs.negative;
    }
  }
  return repairs;
}

}  // namespace chorus
