#include "tools/chorus/scene_options.h"

#include <iostream>

#include "common/error.h"

#include "common/stopwatch.h"
#include "common/thread_limit.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/gltf_loader.h"
#include "tools/chorus/flag_checks.h"

namespace chorus::cli {

using namespace chorus::render;

namespace {

// Far beyond the cameras of any scene; the index only has to stay an int.
constexpr int64_t kMaxCameraIndex = 1'000'000;
// Lens radii and focus distances: far beyond any scene's size (float keeps ~7 digits there).
constexpr double kMaxSceneLength = 1e12;
// Emission-pass rays per pixel: far beyond what resolves an edge.
constexpr int64_t kMaxEmissionSamples = 65536;

// --background: parseRgb's R,G,B (or grey) with non-negative components, each at most
// kMaxRadianceScale.
CLI::Validator radianceColour() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        try {
          const Rgb rgb = parseRgb(text);
          if (rgb.maxComponent() > kMaxRadianceScale)
            return "'" + text + "' is brighter than 1e+06 in some channel";
        } catch (const Error& e) {
          return e.what();
        }
        return {};
      },
      "R,G,B");
}

}  // namespace

void SceneOptions::addFlags(CLI::App& cmd) {
  cmd.add_option("--width", render.width, "Image width (default: from the camera)")
      ->transform(integerIn(1, kMaxImageSide));
  cmd.add_option("--height", render.height, "Image height (default: 512, or from --width)")
      ->transform(integerIn(1, kMaxImageSide));
  cmd.add_option("--seed", render.seed, "Sampler seed")
      ->capture_default_str()
      ->transform(anyUnsigned64());
  cmd.add_option("--threads", render.threads, "Worker threads (0: all cores)")
      ->capture_default_str()
      ->transform(integerIn(0, kMaxThreads));
  cmd.add_option("--max-depth", render.maxDepth, "Maximum bounces per path")
      ->capture_default_str()
      ->transform(integerIn(1, kMaxDepth));
  cmd.add_option("--roulette-depth", render.rouletteStartDepth,
                 "Russian roulette from this bounce on (above --max-depth: never; the expected "
                 "image is the same, only the noise and the time per sample change)")
      ->capture_default_str()
      ->transform(integerIn(0, kMaxDepth + 1));
  cmd.add_option_function<std::string>(
         "--tracer",
         [this](const std::string& name) {
           render.tracer = name == "lanes"      ? RenderOptions::Tracer::Lanes
                           : name == "one-path" ? RenderOptions::Tracer::OnePath
                                                : RenderOptions::Tracer::Automatic;
         },
         "Path tracer: auto (four paths at a time in SIMD lanes when at least half the surface "
         "area has an untextured material), lanes or one-path; the images are the same")
      ->check(CLI::IsMember({"auto", "lanes", "one-path"}))
      ->default_str("auto");
  cmd.add_option("--camera", render.camera, "Camera index (glTF camera nodes in order)")
      ->capture_default_str()
      ->transform(integerIn(0, kMaxCameraIndex));
  cmd.add_option("--lens-radius", render.lensRadius,
                 "Depth of field: radius of the thin lens in scene units (0: a pinhole)")
      ->capture_default_str()
      ->transform(finiteIn(0, kMaxSceneLength));
  cmd.add_option("--focus-distance", render.focusDistance,
                 "Distance along the view axis that is in focus, scene units (0: autofocus on "
                 "the surface under the image centre)")
      ->capture_default_str()
      ->transform(finiteIn(0, kMaxSceneLength));
  cmd.add_option_function<int>(
         "--emission-samples", [this](int samples) { render.setEmissionSamples(samples); },
         "Emission seen directly or in mirrors (not through glass) is kept out of the denoisers' "
         "input and added back to every image, estimated from this many camera rays per pixel "
         "where the pixel's samples disagree on it (light edges, defocused lights); 0: denoise "
         "it with the rest")
      ->transform(integerIn(0, kMaxEmissionSamples))
      ->default_str(std::to_string(render.emissionSamples));
  auto* backgroundFlag = cmd.add_option("--background", background,
                                        "Constant environment radiance R,G,B (or one grey value)")
                             ->transform(radianceColour());
  auto* envFlag = cmd.add_option("--env", env, "Equirectangular environment map (.hdr or .exr)")
                      ->transform(pathName());
  backgroundFlag->excludes(envFlag);
  cmd.add_option("--env-rotate", envRotate, "Rotate the environment about +Y, degrees")
      ->capture_default_str()
      ->transform(finiteIn(-360, 360));
  cmd.add_option("--env-intensity", envIntensity, "Scale the environment radiance")
      ->capture_default_str()
      ->transform(finiteIn(0, kMaxRadianceScale));
}

EnvironmentDesc SceneOptions::environment() const {
  if (!env.empty()) return environmentFromFile(env, envRotate, envIntensity);
  if (!background.empty()) {
    EnvironmentDesc e = EnvironmentDesc::constant(parseRgb(background));
    e.intensity = envIntensity;
    return e;
  }
  return {};
}

std::string SceneOptions::environmentLabel(const Scene& scene) const {
  if (scene.usesDefaultEnvironment()) return "default white (no lights in scene)";
  if (!env.empty()) return env;
  if (!background.empty()) return "constant " + background;
  return "none";
}

LoadedScene loadScene(const std::string& path, const SceneOptions& options, bool quiet) {
  const EnvironmentDesc environment = options.environment();
  Stopwatch stage;
  SceneDesc desc = loadGltf(path);
  const double loadSeconds = stage.restart();
  std::vector<std::string> warnings = desc.warnings;
  for (const std::string& w : warnings)
    std::cerr << "chorus: warning: " << path << ": " << w << "\n";

  Scene scene = buildScene(std::move(desc), environment);
  const double buildSeconds = stage.seconds();
  if (scene.usesDefaultEnvironment() && !quiet)
    std::cerr << "chorus: " << path
              << " has no lights: rendering under a uniform white environment (radiance 1)\n";
  return {std::move(scene), loadSeconds, buildSeconds, std::move(warnings)};
}

}  // namespace chorus::cli
