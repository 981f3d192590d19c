#pragma once
// 8-bit sRGB PNG output (zlib): to a file, or to memory (for data URIs).
#include <cstdint>
#include <filesystem>
#include <vector>

#include "common/image/image.h"
#include "common/image/tonemap.h"

namespace chorus {

// Encodes a 1- (grey), 3- (RGB) or 4-channel (RGBA, alpha written linearly) image as an 8-bit
// PNG through `options`. Throws chorus::Error for other channel counts or an empty image.
std::vector<uint8_t> encodePng(const Image& image, const DisplayOptions& options = {});

// encodePng, written atomically. Throws chorus::Error naming the file.
void writePng(const std::filesystem::path& path, const Image& image,
              const DisplayOptions& options = {});

}  // namespace chorus
