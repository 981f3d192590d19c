#pragma once
// OpenEXR input and output with named layers.
//
// Channel naming (so that tev, oiiotool and other viewers show one layer at a time): a layer
// named L with C channels is stored as channels "L.<suffix>", suffixes by channel count:
//   1 → Y,  2 → X Y (written as "L.X", "L.Y"),  3 → R G B,  4 → R G B A,  more → 0 1 2 …
// The layer named "" (the default layer) uses the bare suffixes ("R", "G", "B"), which is what
// single-layer files from other tools contain. Layer names may contain dots ("sub0.color");
// the suffix is always the part after the last dot.
#include <filesystem>
#include <string>
#include <vector>

#include "common/image/image.h"

namespace chorus {

struct ExrLayer {
  std::string name;
  Image image;
};

enum class ExrPixelType { Half, Float };

// Writes all layers (same size) to `path`, atomically. Throws chorus::Error naming the file.
void writeExr(const std::filesystem::path& path, const std::vector<ExrLayer>& layers,
              ExrPixelType type = ExrPixelType::Float);
void writeExr(const std::filesystem::path& path, const Image& image,
              ExrPixelType type = ExrPixelType::Float);

// Reads every layer of a scanline or tiled EXR (half, float or uint channels → float), in the
// order of first appearance. Throws chorus::Error naming the file for a missing, non-EXR,
// truncated or otherwise unreadable file.
std::vector<ExrLayer> readExr(const std::filesystem::path& path);

// Reads one layer; "" is the default layer. When `name` is "" and the file has no default
// layer but exactly one layer, that layer is returned. Throws chorus::Error listing the
// available layers when the requested one is missing.
Image readExrLayer(const std::filesystem::path& path, const std::string& name = "");

// The default layer as RGB (an alpha channel is dropped), e.g. a reference image. Throws
// chorus::Error naming the file when it is not RGB or RGBA.
Image readRgbExr(const std::filesystem::path& path);

// Finds a layer in an already read file (nullptr when absent).
const ExrLayer* findLayer(const std::vector<ExrLayer>& layers, const std::string& name);

}  // namespace chorus
