// chorus render SCENE: path-trace a glTF scene into K independent sub-buffers and write
// DIR/render.exr (every layer), DIR/color.png (preview) and DIR/stats.json.
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <string>

#include "denoise/buffers/buffers_exr.h"
#include "denoise/image/exr_io.h"
#include "denoise/image/png_io.h"
#include "denoise/util/atomic_file.h"
#include "denoise/util/error.h"
#include "renderer/render.h"
#include "tools/chorus/command.h"
#include "tools/chorus/progress_bar.h"
#include "tools/chorus/scene_options.h"

namespace chorus::cli {
namespace {

namespace fs = std::filesystem;
using namespace chorus::render;

struct RenderArgs {
  std::string scene;
  std::string out = "out";
  SceneOptions sceneOptions;  // sceneOptions.render carries --spp too
  int splits = 0;             // 0: what the denoising stage needs
  std::string denoise = "none";
  bool quiet = false;
};

// The stage after rendering. Only "none" exists so far; the ensemble plugs in here: it parses
// its spec, says how many sub-buffers it needs, and runs on the buffers after they are written.
struct DenoiseStage {
  std::string spec;
  int splitsNeeded() const { return 1; }
  void run(const SampleBuffers&, const fs::path&, nlohmann::ordered_json&) const {}
};

DenoiseStage parseDenoiseStage(const std::string& spec) {
  if (spec != "none") throw Error("--denoise '" + spec + "' is not available (only 'none' so far)");
  return {spec};
}


nlohmann::ordered_json statsJson(const RenderArgs& args, const RenderStats& s,
                                 const LoadedScene& loaded) {
  const RenderOptions& options = args.sceneOptions.render;
  nlohmann::ordered_json j;
  j["scene"] = args.scene;
  j["width"] = s.width;
  j["height"] = s.height;
  j["spp"] = s.spp;
  j["splits"] = s.splits;
  j["seed"] = options.seed;
  j["max_depth"] = options.maxDepth;
  j["camera"] = options.camera;
  j["threads"] = options.threads;
  j["environment"] = args.sceneOptions.environmentLabel(loaded.scene);
  j["seconds"] = {
      {"load", loaded.loadSeconds}, {"bvh_build", loaded.buildSeconds}, {"render", s.renderSeconds}};
  j["samples"] = s.samples;
  j["samples_per_second"] = s.samplesPerSecond();
  j["rays"] = s.rays;
  j["rays_per_second"] = s.raysPerSecond();
  j["triangles"] = s.triangles;
  j["nan_samples_dropped"] = s.nanSamplesDropped;
  j["warnings"] = loaded.warnings;
  j["denoise"] = args.denoise;
  j["chorus_version"] = CHORUS_VERSION;
  return j;
}

void runRender(RenderArgs args) {
  const DenoiseStage denoise = parseDenoiseStage(args.denoise);
  RenderOptions options = args.sceneOptions.render;
  options.splits = args.splits > 0 ? args.splits : denoise.splitsNeeded();
  const LoadedScene loaded = loadScene(args.scene, args.sceneOptions, args.quiet);

  ProgressBar bar(!args.quiet && ProgressBar::stderrIsTerminal());
  RenderResult result =
      render::render(loaded.scene, options, [&bar](const RenderProgress& p) { bar.update(p); });
  bar.finish();

  const fs::path out = args.out;
  ensureDirectory(out);
  nlohmann::ordered_json stats =
      statsJson(args, result.stats, loaded);
  denoise.run(result.buffers, out, stats);
  // The buffers move into the EXR layers (no second copy of a large render in memory).
  const std::vector<ExrLayer> layers = sampleBuffersToLayers(std::move(result.buffers));
  writeExr(out / "render.exr", layers, ExrPixelType::Float);
  writePng(out / "color.png", layers.front().image);  // the full-buffer colour mean
  writeTextAtomically(out / "stats.json", stats.dump(2) + "\n");

  if (!args.quiet) {
    const RenderStats& s = result.stats;
    std::fprintf(stderr,
                 "chorus: rendered %s at %dx%d, %d spp, %d split(s) in %.2f s: %.2f M samples/s, "
                 "%.2f M rays/s, %llu NaN sample(s) dropped -> %s\n",
                 args.scene.c_str(), s.width, s.height, s.spp, s.splits, s.renderSeconds,
                 s.samplesPerSecond() / 1e6, s.raysPerSecond() / 1e6,
                 static_cast<unsigned long long>(s.nanSamplesDropped), out.c_str());
  }
}

const RegisterCommand registration(30, [](CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Path-trace a glTF scene into independent sub-buffers (colour, albedo, normal, "
      "depth, visibility, with variances); writes DIR/render.exr, color.png, stats.json");
  cmd->add_option("scene", args->scene, "glTF scene (.gltf or .glb)")->required();
  cmd->add_option("--out", args->out, "Output directory")->capture_default_str();
  cmd->add_option("--spp", args->sceneOptions.render.spp, "Samples per pixel (over all sub-buffers)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--splits", args->splits,
                  "Independent sub-buffers K: 1, 2 or 4 (default: what --denoise needs)")
      ->check(CLI::IsMember({1, 2, 4}));
  args->sceneOptions.addFlags(*cmd);
  cmd->add_option("--denoise", args->denoise, "Denoising after the render: none")
      ->capture_default_str();
  cmd->add_flag("--quiet", args->quiet, "No progress bar or summary line");
  cmd->callback([args] { runRender(*args); });
});

}  // namespace
}  // namespace chorus::cli
