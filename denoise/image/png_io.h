#pragma once
// 8-bit sRGB PNG output (through stb_image_write).
#include <filesystem>

#include "denoise/image/image.h"
#include "denoise/image/tonemap.h"

namespace chorus {

// Writes a 1- (grey), 3- (RGB) or 4-channel (RGBA, alpha written linearly) image as an 8-bit
// PNG through `options`, atomically. Throws chorus::Error naming the file.
void writePng(const std::filesystem::path& path, const Image& image,
              const DisplayOptions& options = {});

}  // namespace chorus
