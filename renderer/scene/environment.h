#pragma once
// The environment around the scene: nothing (black), a constant radiance (`--background`), or
// an equirectangular map (`--env FILE.hdr|.exr`, `--env-rotate`, `--env-intensity`).
//
// Map orientation (glTF world, +Y up): row 0 of the image is straight up (+Y), the bottom row
// straight down; the centre column u = 0.5 faces −Z (where a default glTF camera looks), and u
// grows toward +X, so the panorama is not mirrored seen from inside. `rotationDegrees` turns it
// about +Y (counter-clockwise seen from above).
#include <filesystem>
#include <memory>
#include <string>

#include "common/image/image.h"
#include "renderer/math/vec.h"

namespace chorus::render {

struct EnvironmentDesc {
  enum class Kind { None, Constant, Map };
  Kind kind = Kind::None;
  Rgb radiance{0.0f};                // Constant
  std::shared_ptr<const Image> map;  // Map: linear RGB, 3 channels
  std::string source;                // file name (Map), for messages and stats
  float rotationDegrees = 0.0f;
  float intensity = 1.0f;  // multiplies radiance or the map

  static EnvironmentDesc constant(Rgb radiance) {
    EnvironmentDesc e;
    e.kind = Kind::Constant;
    e.radiance = radiance;
    return e;
  }
};

// Throws chorus::Error unless the environment can be rendered: a finite rotation (NaN turned
// every map lookup into index INT_MIN), an intensity and a constant radiance that are finite
// and within [0, kMaxRadiance] (scene_limits.h). buildScene() checks its environment with this.
void checkEnvironment(const EnvironmentDesc& environment);

// Reads a Radiance .hdr (radiance_hdr.h) or OpenEXR (its default or only RGB layer) file as
// linear RGB. Non-finite or negative texels become 0, texels above kMaxRadiance become
// kMaxRadiance. Throws chorus::Error naming the file.
Image loadEnvironmentImage(const std::filesystem::path& path);

// loadEnvironmentImage wrapped in an EnvironmentDesc of kind Map (checked by checkEnvironment
// before the file is read).
EnvironmentDesc environmentFromFile(const std::filesystem::path& path, float rotationDegrees = 0,
                                    float intensity = 1);

// Parses "R,G,B" (or one value for grey) into a radiance; throws chorus::Error otherwise.
Rgb parseRgb(const std::string& text);

}  // namespace chorus::render
