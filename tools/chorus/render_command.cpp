// chorus render SCENE: path-trace a glTF scene into K independent sub-buffers holding the
// features the denoisers read, write DIR/render.exr, DIR/color.png and DIR/stats.json, then
// (unless --denoise none) denoise in the same process: DIR/denoised.exr/.png, and with --keep
// weights.exr and one EXR per member. --preview: 4 spp, the fast members, DIR/denoised.png and
// stats.json only.
#include <nlohmann/json.hpp>

#include <iostream>
#include <optional>
#include <string>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/image/finite_pixels.h"
#include "common/image/png_io.h"
#include "common/owned_directory.h"
#include "common/stopwatch.h"
#include "common/thread_limit.h"
#include "denoise/buffers/buffers_exr.h"
#include "renderer/render.h"
#include "tools/chorus/command.h"
#include "tools/chorus/ensemble_flags.h"
#include "tools/chorus/ensemble_outputs.h"
#include "tools/chorus/flag_checks.h"
#include "tools/chorus/kept_outputs.h"
#include "tools/chorus/memory_estimate.h"
#include "tools/chorus/progress_bar.h"
#include "tools/chorus/render_denoise.h"
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
  std::string denoise = "default", combine = "ensemble", reference;
  EnsembleFlags ensemble;
  KeptOutputs keep;
  bool preview = false, sppGiven = false, denoiseGiven = false;
  bool quiet = false;
};

// Below this many samples per pixel `chorus render` without --denoise blends the preview's
// members (K = 2) instead of the default ones: K = 4 leaves sub-buffers empty there, and every
// rendered corpus entry (128–160 px, chorus render against its reference) blended 1.8–2.5×
// better in geometric mean on both halves at 1 and 2 spp (still 0.84 / 0.94 since held-out runs
// take no empty quarter as a half), but not at 3 (tuning 0.98, validation 1.04: interior-doorway
// 4× worse; at 512 px tuning 1.11); docs/ensemble-quality.md, "Below 4 spp".
constexpr int kDefaultMembersFromSpp = 3;

bool previewMembersForFewSamples(const RenderArgs& args) {
  return !args.denoiseGiven && !args.preview &&
         args.sceneOptions.render.spp < kDefaultMembersFromSpp;
}

// What previewMembersForFewSamples chose, for stderr and stats.json's notes; empty otherwise.
std::string previewMembersNote(const RenderArgs& args) {
  if (!previewMembersForFewSamples(args)) return {};
  return "at " + std::to_string(args.sceneOptions.render.spp) + " spp the default members (" +
         kDefaultDenoise + ") would leave sub-buffers empty: denoising with the preview's (" +
         kPreviewDenoise + ") instead (--denoise default keeps them)";
}

DenoiseStage denoiseStageOf(const RenderArgs& args) {
  CombineOptions options = args.ensemble.options();
  options.combiner = parseCombiner(args.combine);
  const bool previewMembers = args.preview || previewMembersForFewSamples(args);
  if (previewMembers) applyPreviewDefaults(options, args.ensemble);
  const std::string list = args.denoiseGiven ? args.denoise
                           : previewMembers  ? "preview"
                                             : "default";
  DenoiseStage stage = DenoiseStage::parse(list, options, !args.preview);
  stage.keep = args.keep;
  const int needed = stage.splitsNeeded();
  if (stage.enabled() && args.splits != 0 && args.splits < needed)
    throw Error("--denoise " + stage.label() + " needs " + std::to_string(needed) +
                " sub-buffers: omit --splits or give --splits " + std::to_string(needed));
  return stage;
}

// Sample i of a pixel goes to sub-buffer i mod K: below K samples per pixel some sub-buffers
// stay empty, and the members' runs (some of whose halves are empty at 1-2 spp) and the estimate
// that compares them have less to work with (Cornell box 64², default members: NFOR 3.1x worse
// than the noisy input at 2 spp; the blend 0.141 against the preview's 0.063; at 3 spp on the
// Cornell box 512² still 1.6x NFOR's full run). Empty when the run denoises at K spp or more.
std::string fewSamplesWarning(const DenoiseStage& denoise, const RenderOptions& options) {
  if (!denoise.enabled() || options.spp >= options.splits) return {};
  const int empty = options.splits - options.spp;
  return std::to_string(empty) + " of the " + std::to_string(options.splits) +
         " sub-buffers get no samples at " + std::to_string(options.spp) +
         " spp, which leaves the members and their weights less to work with: render at least " +
         std::to_string(options.splits) + " spp" +
         (options.splits == 4 ? ", or --preview (2 sub-buffers)" : "");
}

nlohmann::ordered_json statsJson(const RenderArgs& args, const RenderOptions& options,
                                 const RenderStats& s, const LoadedScene& loaded) {
  nlohmann::ordered_json j;
  j["scene"] = args.scene;
  j["width"] = s.width;
  j["height"] = s.height;
  j["spp"] = s.spp;
  j["splits"] = s.splits;
  // The feature planes the sub-buffers hold, and those no member reads.
  j["planes"] = {{"recorded", options.planes.names()},
                 {"left_out", BufferPlanes::all().minus(options.planes).names()}};
  j["seed"] = options.seed;
  j["max_depth"] = options.maxDepth;
  j["roulette_depth"] = options.rouletteStartDepth;
  j["camera"] = options.camera;
  if (options.lensRadius > 0)
    j["lens"] = {{"radius", options.lensRadius}, {"focus_distance", s.focusDistance}};
  j["threads"] = options.threads;
  j["environment"] = args.sceneOptions.environmentLabel(loaded.scene);
  j["seconds"] = {{"load", loaded.loadSeconds},
                  {"bvh_build", loaded.buildSeconds},
                  {"render", s.renderSeconds}};
  j["samples"] = s.samples;
  j["samples_per_second"] = s.samplesPerSecond();
  j["rays"] = s.rays;
  j["shadow_rays"] = s.shadowRays;
  j["rays_per_second"] = s.raysPerSecond();
  j["triangles"] = s.triangles;
  j["nan_samples_dropped"] = s.nanSamplesDropped;
  j["tracer"] = s.lanes ? "lanes" : "one-path";
  // What the emission pass re-estimated (0 pixels: the samples of every pixel agreed).
  if (options.separateEmission)
    j["emission"] = {{"samples", options.emissionSamples},
                     {"pixels", s.emissionPixels},
                     {"seconds", s.emissionSeconds}};
  else
    j["emission"] = "denoised with the rest";
  j["warnings"] = loaded.warnings;
  j["chorus_version"] = CHORUS_VERSION;
  return j;
}

// Every file this run writes in DIR, stats.json last (OwnedDirectory::replacePreviousRun).
std::vector<std::string> outputFiles(const RenderArgs& args, const DenoiseStage& denoise) {
  std::vector<std::string> files;
  if (!args.preview)
    files = {"render.exr", "color.png"};
  else if (!denoise.enabled())
    files = {"color.png"};
  const std::vector<std::string> denoised = denoise.files();
  files.insert(files.end(), denoised.begin(), denoised.end());
  files.push_back("stats.json");
  return files;
}

std::vector<LeftOut> leftOutFiles(const RenderArgs& args, const DenoiseStage& denoise) {
  std::vector<LeftOut> files;
  if (args.preview) files.push_back({"render.exr", "without --preview"});
  const std::vector<LeftOut> denoised = denoise.leftOut();
  files.insert(files.end(), denoised.begin(), denoised.end());
  return files;
}

void runRender(RenderArgs args) {
  const Stopwatch total;
  // --threads bounds the denoising too, not only the renderer's arena.
  const ThreadLimit threads(args.sceneOptions.render.threads);
  if (args.preview && !args.sppGiven) args.sceneOptions.render.spp = 4;
  const DenoiseStage denoise = denoiseStageOf(args);
  RenderOptions options = args.sceneOptions.render;
  options.splits = args.splits > 0 ? args.splits : denoise.splitsNeeded();
  options.planes = denoise.planesNeeded();
  std::optional<Image> reference;
  if (!args.reference.empty()) {
    if (!denoise.enabled()) throw Error("--reference needs --denoise");
    reference = readRgbExr(args.reference);
    requireFinitePixels(*reference, args.reference);
  }
  const LoadedScene loaded = loadScene(args.scene, args.sceneOptions, args.quiet);
  // Everything that can be checked fails here, before the render allocates its film.
  const Resolution size = renderResolution(loaded.scene, options);
  if (reference) checkReferenceSize(*reference, args.reference, size.width, size.height);
  checkRunMemory(size, options.splits, denoise.members);
  focusCamera(loaded.scene, options);  // a lens its camera cannot take, nothing to focus on
  OwnedDirectory out(args.out);        // held until every file is written
  // Said once nothing can fail any more before the render.
  const std::string fewSamples = fewSamplesWarning(denoise, options);
  if (!fewSamples.empty() && !args.quiet) std::cerr << "chorus: warning: " << fewSamples << "\n";
  const std::string previewMembers = previewMembersNote(args);
  if (!previewMembers.empty() && !args.quiet)
    std::cerr << "chorus: note: " << previewMembers << "\n";

  const bool showProgress = !args.quiet && TerminalLine::stderrIsTerminal();
  ProgressBar bar(showProgress);
  RenderResult result =
      render::render(loaded.scene, options, [&bar](const RenderProgress& p) { bar.update(p); });
  bar.finish();
  if (!args.quiet) {
    const RenderStats& s = result.stats;
    std::fprintf(stderr,
                 "chorus: rendered %s at %dx%d, %d spp, %d split(s) in %.2f s: %.2f M samples/s, "
                 "%.2f M rays/s, %llu NaN sample(s) dropped\n",
                 args.scene.c_str(), s.width, s.height, s.spp, s.splits, s.renderSeconds,
                 s.samplesPerSecond() / 1e6, s.raysPerSecond() / 1e6,
                 static_cast<unsigned long long>(s.nanSamplesDropped));
  }

  // The previous run's files go before the first of this run's is written (a killed render
  // leaves them untouched; a run killed while writing leaves no stats.json).
  const std::vector<std::string> files = outputFiles(args, denoise);
  out.replacePreviousRun(files);
  nlohmann::ordered_json stats = statsJson(args, options, result.stats, loaded);
  if (!fewSamples.empty()) stats["warnings"].push_back(fewSamples);
  if (!previewMembers.empty()) stats["notes"].push_back(previewMembers);
  stats["outputs"] = outputsJson(files, leftOutFiles(args, denoise));
  // The denoisers' inputs are copies, so the buffers can move into render.exr's layers (no
  // second copy of a large render in memory), and render.exr is on disk before denoising. A
  // preview writes no render.exr: its inputs take the buffers over.
  std::optional<EnsembleSources> sources;
  if (denoise.enabled()) {
    sources = args.preview ? sourcesFromBuffers(std::move(result.buffers), false)
                           : sourcesFromBuffers(result.buffers, false);
    // The full buffer's halves (two copies of every plane, 1.5 GB at 4K) are built for the run
    // on the full buffer only, while it runs (runBaseDenoisers); a preview whose members read
    // them holds them from the start, so that its full run goes with its half runs.
    if (args.preview && readsHalves(denoise.members) &&
        baseRunsFor(denoise.options.mse, *sources).full)
      addHalvesOfFull(*sources);
  }
  const Stopwatch write;
  if (!args.preview) {
    const std::vector<ExrLayer> layers = sampleBuffersToLayers(std::move(result.buffers));
    writeExr(out.path() / "render.exr", layers, ExrPixelType::Float);
    writePng(out.path() / "color.png", layers.front().image);  // the full-buffer colour mean
  } else if (!sources) {
    writePng(out.path() / "color.png", result.buffers.noisyColor());
  }
  stats["seconds"]["write render"] = write.seconds();
  result.buffers = {};
  double denoiseSeconds = 0;
  if (sources) {
    RunsProgressLine runs(showProgress);
    denoiseSeconds = denoise.run(*sources, out.path(), stats, reference ? &*reference : nullptr,
                                 runs.callback());
    runs.finish();
  }
  stats["seconds"]["total"] = total.seconds();
  writeTextAtomically(out.path() / "stats.json", stats.dump(2) + "\n");

  if (!args.quiet) {
    if (sources)
      std::fprintf(stderr, "chorus: denoised with %s (%s) in %.2f s\n", denoise.label().c_str(),
                   args.combine.c_str(), denoiseSeconds);
    std::string written;
    for (const std::string& file : files) written += (written.empty() ? "" : " ") + file;
    std::fprintf(stderr, "chorus: wrote %s in %s\n", written.c_str(), out.path().c_str());
  }
}

const RegisterCommand renderCommand(30, [](CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Path-trace a glTF scene into independent sub-buffers (colour and the features the "
      "denoisers read: albedo, normal, depth, visibility, with variances); writes "
      "DIR/render.exr, color.png, stats.json and, unless --denoise none, denoised.exr/.png");
  cmd->add_option("scene", args->scene, "glTF scene (.gltf or .glb)")->required();
  cmd->add_option("--out", args->out, "Output directory")
      ->capture_default_str()
      ->transform(pathName());
  cmd->add_option("--spp", args->sceneOptions.render.spp,
                  "Samples per pixel (over all sub-buffers)")
      ->capture_default_str()
      ->transform(integerIn(1, kMaxSpp))
      ->each([args](const std::string&) { args->sppGiven = true; });
  cmd->add_option("--splits", args->splits,
                  "Independent sub-buffers K: 1, 2 or 4 (default: what --denoise needs; with "
                  "--denoise none, what the default members need, for a later `chorus denoise`)")
      ->transform(integerIn(1, 4))  // refuses '' (CLI11 leaves the default for an empty value)
      ->check(CLI::IsMember({1, 2, 4}));
  args->sceneOptions.addFlags(*cmd);
  cmd->add_option("--denoise", args->denoise,
                  std::string("Denoising after the render: none (render.exr keeps the "
                              "sub-buffers and features the default members read), default (") +
                      kDefaultDenoise + "; when not given, below " +
                      std::to_string(kDefaultMembersFromSpp) +
                      " spp the preview's members), preview (" + kPreviewDenoise +
                      ") or a comma-separated list of base denoisers (name or name:key=value; "
                      "`chorus denoise --help` lists them)")
      ->capture_default_str()
      ->each([args](const std::string&) { args->denoiseGiven = true; });
  cmd->add_option("--combine", args->combine,
                  "How the members are blended: ensemble, average, onehot-pre, onehot-post")
      ->capture_default_str();
  cmd->add_flag("--preview", args->preview,
                std::string("Fast preview: 4 spp unless --spp, members ") + kPreviewDenoise +
                    " unless --denoise, no weight filter unless --weight-filter, writes only "
                    "denoised.png and stats.json (and what --keep lists)");
  cmd->add_option("--reference", args->reference,
                  "Reference image (.exr) of the same view: metrics of the noisy input, each "
                  "member and the result in stats.json")
      ->transform(pathName());
  args->ensemble.addFlags(*cmd);
  args->keep.addFlag(*cmd);
  cmd->add_flag("--quiet", args->quiet, "No progress bar or summary line");
  cmd->callback([args] { runRender(*args); });
});

}  // namespace
}  // namespace chorus::cli
