#include "tests/support/highlight_region.h"

#include <algorithm>

#include "denoise/metrics/metrics.h"

namespace chorus::test {

std::vector<bool> highlightMask(const Image& reference) {
  const int w = reference.width(), h = reference.height();
  std::vector<bool> mask(size_t(w) * size_t(h), false);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool bright = false;
      for (int c = 0; c < reference.channels(); ++c) bright |= reference(x, y, c) > kHighlightLevel;
      if (!bright) continue;
      for (int v = std::max(0, y - kHighlightRadius); v <= std::min(h - 1, y + kHighlightRadius);
           ++v)
        for (int u = std::max(0, x - kHighlightRadius); u <= std::min(w - 1, x + kHighlightRadius);
             ++u)
          mask[size_t(v) * size_t(w) + size_t(u)] = true;
    }
  return mask;
}

double relMsePart(const Image& image, const Image& reference, const std::vector<bool>& mask,
                  bool inside) {
  const Image map = relMseMap(image, reference);
  double sum = 0;
  for (size_t i = 0; i < mask.size(); ++i)
    if (mask[i] == inside) sum += map.data()[i];
  return sum / double(mask.size());
}

}  // namespace chorus::test
