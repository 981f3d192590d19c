#include "denoise/buffers/tungsten_dir.h"

#include <nlohmann/json.hpp>

#include <fstream>

#include "common/error.h"
#include "common/image/exr_io.h"

namespace chorus {
namespace fs = std::filesystem;

bool isTungstenDirectory(const fs::path& dir) {
  for (const char* name : {"color.exr", "colorA.exr", "colorB.exr", "colorVariance.exr"})
    if (!fs::is_regular_file(dir / name)) return false;
  return true;
}

namespace {

Image readBuffer(const fs::path& file, int channels, int width, int height) {
  Image image = readExrLayer(file);
  if (channels == 3 && image.channels() == 4) image = image.channelRange(0, 3);
  if (image.channels() != channels)
    throw fileError(file, "has " + std::to_string(image.channels()) + " channels, expected " +
                              std::to_string(channels));
  if (width > 0 && (image.width() != width || image.height() != height))
    throw fileError(file, "is " + std::to_string(image.width()) + "x" +
                              std::to_string(image.height()) + ", color.exr is " +
                              std::to_string(width) + "x" + std::to_string(height));
  return image;
}

float sppFromMeta(const fs::path& dir) {
  const fs::path meta = dir / "meta.json";
  if (!fs::is_regular_file(meta)) return 0.0f;
  try {
    std::ifstream in(meta);
    const auto j = nlohmann::json::parse(in);
    return j.contains("spp") ? j.at("spp").get<float>() : 0.0f;
  } catch (const std::exception& e) {
    throw fileError(meta, std::string("cannot parse: ") + e.what());
  }
}

}  // namespace

DenoiseInput readTungstenDirectory(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw fileError(dir, "no such directory");
  const Image color = readBuffer(dir / "color.exr", 3, 0, 0);
  const int w = color.width(), h = color.height();
  const float spp = sppFromMeta(dir);

  DenoiseInput input;
  input.halves.emplace();
  input.whole.sampleCount = Image(w, h, 1, spp);
  for (auto& half : *input.halves) half.sampleCount = Image(w, h, 1, spp / 2);
  for (Quantity q : kAllQuantities) {
    const std::string name(quantityName(q));
    const int channels = channelCount(q);
    MeanVariance& whole = input.whole.get(q);
    whole.mean = readBuffer(dir / (name + ".exr"), channels, w, h);
    whole.varianceOfMean = readBuffer(dir / (name + "Variance.exr"), channels, w, h);
    Image halfVariance = whole.varianceOfMean;
    for (float& v : halfVariance.values()) v *= 2.0f;
    const char* suffixes[2] = {"A.exr", "B.exr"};
    for (int k = 0; k < 2; ++k) {
      MeanVariance& half = (*input.halves)[size_t(k)].get(q);
      half.mean = readBuffer(dir / (name + suffixes[k]), channels, w, h);
      half.varianceOfMean = halfVariance;
    }
  }
  return input;
}

}  // namespace chorus
