#include "common/image/finite_pixels.h"

#include <cmath>
#include <string>

#include "common/error.h"

namespace chorus {

namespace {
bool pixelIsFinite(const Image& image, int x, int y) {
  const float* p = image.pixel(x, y);
  for (int c = 0; c < image.channels(); ++c)
    if (!std::isfinite(p[c])) return false;
  return true;
}
}  // namespace

size_t nonFinitePixelCount(const Image& image) {
  size_t count = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) count += pixelIsFinite(image, x, y) ? 0 : 1;
  return count;
}

void requireFinitePixels(const Image& image, const std::filesystem::path& file) {
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      if (!pixelIsFinite(image, x, y))
        throw fileError(file, std::to_string(nonFinitePixelCount(image)) +
                                  " pixel(s) are NaN or infinite (the first at x " +
                                  std::to_string(x) + ", y " + std::to_string(y) +
                                  "): metrics need finite values");
}

}  // namespace chorus
