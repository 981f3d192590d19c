#pragma once
// The largest images chorus reads (EXR and Radiance HDR; stb_image holds texture images to the
// same 2^28 RGBA pixels with its own 2^30-byte limit), checked from the file's header before
// anything is allocated: a 40-byte header may claim 2^31 × 2^31 pixels. The limits are far
// above real images (a 16K × 16K texture or a 32K × 8K panorama is 2^28 pixels; a 4K
// render.exr with 64 channels is 2^29 values) and keep one image under 8 GiB of floats.
#include <cstdint>
#include <string>

namespace chorus {

inline constexpr int64_t kMaxImagePixels = int64_t(1) << 28;
inline constexpr int64_t kMaxImageValues = int64_t(1) << 31;  // pixels × channels

// "" when a width × height × channels image is within the limits (and not empty); otherwise
// the problem as a phrase for an error message ("is 100000x100000 pixels, more than …").
std::string imageSizeProblem(int64_t width, int64_t height, int64_t channels);

}  // namespace chorus
