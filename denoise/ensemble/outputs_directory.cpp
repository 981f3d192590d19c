#include "denoise/ensemble/outputs_directory.h"

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/image/exr_io.h"

namespace chorus {
namespace fs = std::filesystem;

namespace {

std::string pixelSizeText(const Image& image) {
  return std::to_string(image.width()) + "x" + std::to_string(image.height());
}

// A single-layer image as RGB, of the size of `like` (unless `like` is empty).
Image readRgb(const fs::path& file, const Image& like) {
  if (!fs::is_regular_file(file)) throw fileError(file, "no such file");
  Image image = readExrLayer(file);
  if (image.channels() == 4) image = image.channelRange(0, 3);
  if (image.channels() == 1) {
    Image rgb(image.width(), image.height(), 3);
    for (int c = 0; c < 3; ++c) rgb.setChannel(c, image);
    image = std::move(rgb);
  }
  if (image.channels() != 3)
    throw fileError(file, "has " + std::to_string(image.channels()) + " channels, expected 3");
  if (!like.empty() && !image.sameSize(like))
    throw fileError(file,
                    "is " + pixelSizeText(image) + " but color.exr is " + pixelSizeText(like));
  return image;
}

}  // namespace

bool isOutputsDirectory(const fs::path& dir) {
  for (const char* name : {"color.exr", "colorA.exr", "colorB.exr"})
    if (!fs::is_regular_file(dir / name)) return false;
  return true;
}

OutputsDirectory readOutputsDirectory(const fs::path& dir, std::span<const std::string> methods) {
  if (!fs::is_directory(dir)) throw fileError(dir, "no such directory");
  for (const std::string& m : methods) {
    if (m.empty() || m.find('/') != std::string::npos || m == "." || m == "..")
      throw Error("method name '" + m + "' is not a folder name");
    if (!fs::is_directory(dir / m)) throw fileError(dir / m, "missing method folder");
  }
  OutputsDirectory out;
  EnsembleGuides& g = out.guides;
  g.color = readRgb(dir / "color.exr", Image());
  g.colorA = readRgb(dir / "colorA.exr", g.color);
  g.colorB = readRgb(dir / "colorB.exr", g.color);
  g.albedo = readRgb(dir / "albedo.exr", g.color);
  g.normal = readRgb(dir / "normal.exr", g.color);
  for (const std::string& m : methods) {
    BaseOutputs base;
    base.name = m;
    base.full = readRgb(dir / m / (m + ".exr"), g.color);
    base.a = readRgb(dir / m / (m + "A.exr"), g.color);
    base.b = readRgb(dir / m / (m + "B.exr"), g.color);
    out.bases.push_back(std::move(base));
  }
  return out;
}

void writeOutputsDirectory(const fs::path& dir, const EnsembleGuides& guides,
                           std::span<const BaseOutputs> bases) {
  ensureDirectory(dir);
  writeExr(dir / "color.exr", guides.color);
  writeExr(dir / "colorA.exr", guides.colorA);
  writeExr(dir / "colorB.exr", guides.colorB);
  writeExr(dir / "albedo.exr", guides.albedo);
  writeExr(dir / "normal.exr", guides.normal);
  for (const BaseOutputs& base : bases) {
    ensureDirectory(dir / base.name);
    writeExr(dir / base.name / (base.name + ".exr"), base.full);
    writeExr(dir / base.name / (base.name + "A.exr"), base.a);
    writeExr(dir / base.name / (base.name + "B.exr"), base.b);
  }
}

}  // namespace chorus
