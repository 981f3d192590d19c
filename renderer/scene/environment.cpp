#include "renderer/scene/environment.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/regular_file.h"
#include "renderer/scene/radiance_hdr.h"
#include "renderer/scene/scene_limits.h"

namespace chorus::render {
namespace {

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

Image readExrRgb(const std::filesystem::path& path) {
  const std::vector<ExrLayer> layers = readExr(path);
  const ExrLayer* layer = findLayer(layers, "");
  if (!layer && layers.size() == 1) layer = &layers[0];
  if (!layer) throw fileError(path, "has no default RGB layer to use as an environment");
  const Image& image = layer->image;
  if (image.channels() >= 3) return image.channelRange(0, 3);
  Image rgb(image.width(), image.height(), 3);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < 3; ++c) rgb(x, y, c) = image(x, y, 0);
  return rgb;
}

bool inRadianceRange(float v) {
  return v >= 0 && v <= kMaxRadiance;  // NaN: false
}

}  // namespace

void checkEnvironment(const EnvironmentDesc& e) {
  if (!std::isfinite(e.rotationDegrees))
    throw Error("environment rotation " + shortNumber(e.rotationDegrees) +
                " is not a finite number of degrees");
  const std::string range = " must lie in [0, " + shortNumber(kMaxRadiance) + "]";
  if (!inRadianceRange(e.intensity))
    throw Error("environment intensity " + shortNumber(e.intensity) + range);
  for (int c = 0; c < 3; ++c)
    if (!inRadianceRange(e.radiance[c]))
      throw Error("environment radiance " + shortNumber(e.radiance[c]) + range);
}

Image loadEnvironmentImage(const std::filesystem::path& path) {
  requireRegularFile(path);
  const std::string ext = lowerExtension(path);
  Image image;
  if (ext == ".exr") {
    image = readExrRgb(path);
  } else if (ext == ".hdr" || ext == ".pic") {
    image = readRadianceHdr(path);
  } else {
    throw fileError(path, "environment maps must be Radiance .hdr or OpenEXR .exr files");
  }
  if (image.width() < 1 || image.height() < 1) throw fileError(path, "is an empty image");
  for (float& v : image.values()) v = std::isfinite(v) ? std::clamp(v, 0.0f, kMaxRadiance) : 0.0f;
  return image;
}

EnvironmentDesc environmentFromFile(const std::filesystem::path& path, float rotationDegrees,
                                    float intensity) {
  EnvironmentDesc e;
  e.kind = EnvironmentDesc::Kind::Map;
  e.source = path.string();
  e.rotationDegrees = rotationDegrees;
  e.intensity = intensity;
  checkEnvironment(e);
  e.map = std::make_shared<const Image>(loadEnvironmentImage(path));
  return e;
}

Rgb parseRgb(const std::string& text) {
  std::vector<float> values;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    try {
      size_t used = 0;
      const float v = std::stof(part, &used);
      if (used != part.size() || !std::isfinite(v) || v < 0) throw std::invalid_argument(part);
      values.push_back(v);
    } catch (const std::exception&) {
      throw Error("'" + text + "' is not a colour: expected R,G,B with non-negative numbers");
    }
  }
  if (values.size() == 1) return Rgb(values[0]);
  if (values.size() != 3)
    throw Error("'" + text + "' is not a colour: expected R,G,B with non-negative numbers");
  return {values[0], values[1], values[2]};
}

}  // namespace chorus::render
