#pragma once
// The scene and render flags shared by `chorus render` and `chorus sweep`: resolution, seed,
// threads, depth, camera and the environment, and loading + building the scene they describe.
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "renderer/render.h"
#include "renderer/scene/scene.h"

namespace chorus::cli {

struct SceneOptions {
  // spp and splits are the caller's. The commands separate emission unless told not to
  // (--emission-samples 0).
  render::RenderOptions render = [] {
    render::RenderOptions o;
    o.separateEmission = true;
    return o;
  }();
  std::string background, env;
  float envRotate = 0, envIntensity = 1;

  // Adds --width --height --seed --threads --max-depth --camera --lens-radius --focus-distance
  // --emission-samples --background --env --env-rotate --env-intensity to `cmd`.
  void addFlags(CLI::App& cmd);
  render::EnvironmentDesc environment() const;
  // "default white (no lights in scene)", the --env file, "constant R,G,B" or "none".
  std::string environmentLabel(const render::Scene& scene) const;
};

// A scene loaded and built with its load/build times and the loader's warnings (already
// printed to stderr as "chorus: warning: FILE: ...").
struct LoadedScene {
  render::Scene scene;
  double loadSeconds = 0, buildSeconds = 0;
  std::vector<std::string> warnings;
};
LoadedScene loadScene(const std::string& path, const SceneOptions& options, bool quiet);

}  // namespace chorus::cli
