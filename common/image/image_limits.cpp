#include "common/image/image_limits.h"

namespace chorus {

std::string imageSizeProblem(int64_t width, int64_t height, int64_t channels) {
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  if (width < 1 || height < 1) return "is an empty image (" + size + " pixels)";
  if (channels < 1) return "has no channels";
  // Each factor is at most 2^28 or 2^31 before it is multiplied: no product overflows.
  if (width > kMaxImagePixels || height > kMaxImagePixels || width * height > kMaxImagePixels)
    return "is " + size + " pixels, more than the " + std::to_string(kMaxImagePixels) +
           " pixels chorus reads";
  if (channels > kMaxImageValues || width * height * channels > kMaxImageValues)
    return "is " + size + " pixels of " + std::to_string(channels) + " channels, more than the " +
           std::to_string(kMaxImageValues) + " values chorus reads";
  return "";
}

}  // namespace chorus
