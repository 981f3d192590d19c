#include "denoise/buffers/tungsten_dir.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/json_nesting.h"
#include "common/regular_file.h"

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

// Sample counts are stored as float images: whole numbers are exact up to 2^24, far beyond any
// render's samples per pixel.
constexpr double kMaxSpp = double(1 << 24);
// meta.json is a few hundred bytes of flat JSON; the limits only keep a hostile one bounded.
constexpr uint64_t kMaxMetaBytes = 1 << 20;
constexpr int kMaxMetaNesting = 32;

// meta.json's "spp" (0 when the file or the key is absent: unknown).
float sppFromMeta(const fs::path& dir) {
  const fs::path meta = dir / "meta.json";
  std::error_code ec;
  if (!fs::exists(meta, ec)) return 0.0f;
  const std::vector<unsigned char> bytes = readRegularFile(meta, kMaxMetaBytes);
  if (jsonNestsDeeperThan(bytes, kMaxMetaNesting))
    throw fileError(meta,
                    "nests JSON more than " + std::to_string(kMaxMetaNesting) + " levels deep");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(bytes.begin(), bytes.end());
  } catch (const std::exception& e) {
    std::string what = e.what();
    if (const size_t nl = what.find('\n'); nl != std::string::npos) what.resize(nl);
    throw fileError(meta, "cannot parse: " + what);
  }
  if (!j.is_object() || !j.contains("spp")) return 0.0f;
  const nlohmann::json& value = j.at("spp");
  const double spp = value.is_number() ? value.get<double>() : -1.0;
  if (!(spp >= 1 && spp <= kMaxSpp && spp == std::floor(spp)))
    throw fileError(meta, "\"spp\" is " + value.dump().substr(0, 40) +
                              ", not a whole number of samples from 1 to " +
                              std::to_string(int64_t(kMaxSpp)));
  return float(spp);
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
