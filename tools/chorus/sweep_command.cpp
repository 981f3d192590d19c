// chorus sweep SCENE... --out DIR: sample-count sweeps of every base denoiser and every
// combination × combiner against a reference, with results.csv and a self-contained
// report.html (tools/sweep/). `--merge DIR...` combines the directories of sharded runs.

#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/owned_directory.h"
#include "common/thread_limit.h"
#include "denoise/base/registry.h"
#include "tools/chorus/command.h"
#include "tools/chorus/ensemble_flags.h"
#include "tools/chorus/flag_checks.h"
#include "tools/chorus/memory_estimate.h"
#include "tools/chorus/scene_options.h"
#include "tools/sweep/report_html.h"
#include "tools/sweep/sweep_directory.h"
#include "tools/sweep/sweep_runner.h"

namespace chorus::cli {
namespace {

namespace fs = std::filesystem;

// A budget below 10 ms is shorter than any probe render; 1e7 s (four months) is past any sweep.
constexpr double kMinReferenceSeconds = 0.01, kMaxReferenceSeconds = 1e7;
// The report embeds every crop as a PNG: a side beyond this would make it megabytes per case.
constexpr int64_t kMaxCropSize = 1024;

struct SweepArgs {
  std::vector<std::string> scenes, references, merge;
  std::string spp = "4,8,16,32,64,128,256", methods, combos = "all";
  std::string combiners = "ensemble,onehot-pre,onehot-post,average,oracle";
  std::string out, shard = "0/1";
  int referenceSpp = sweep::kDefaultReferenceSpp;
  double referenceSeconds = 0;
  int cropSize = 96;
  SceneOptions scene;
  EnsembleFlags ensemble;
  bool quiet = false;
};

std::string defaultMethods() {
  std::string list;
  for (const DenoiserEntry& entry : builtinDenoisers())
    list += (list.empty() ? "" : ",") + entry.name;
  return list;
}

template <typename T>
std::string joined(const std::vector<T>& items) {
  std::ostringstream text;
  for (size_t i = 0; i < items.size(); ++i) text << (i ? "," : "") << items[i];
  return text.str();
}

// The report's "details" line: what was swept and how, so a mailed report explains itself.
std::string describe(const sweep::SweepConfig& c, const SweepArgs& args) {
  std::ostringstream text;
  text << "scenes: " << joined(args.scenes) << "\nspp: " << joined(c.spps)
       << "; methods: " << joined(c.methods) << "; combos: " << c.combos
       << "; combiners: " << joined(c.combiners) << "\nreference: "
       << (!c.references.empty()    ? joined(args.references)
           : c.referenceSeconds > 0 ? std::to_string(c.referenceSeconds) + " s budget"
                                    : std::to_string(c.referenceSpp) + " spp")
       << "; size: " << c.render.width << "x" << c.render.height << " (0: from the camera)"
       << "; seed " << c.render.seed << "; threads " << c.render.threads << " (0: all)"
       << "; chorus " << CHORUS_VERSION;
  return text.str();
}

void printHeadline(const fs::path& out, const std::vector<sweep::SweepRow>& rows) {
  std::cout << "wrote " << (out / "results.csv").string() << " (" << rows.size() << " rows) and "
            << (out / "report.html").string() << "\n";
  for (const char* other : {"best-member", "onehot-pre", "onehot-post", "average"}) {
    const sweep::EnsembleWins w = sweep::ensembleWins(rows, other);
    if (w.cases)
      std::printf("ensemble beats %s in %.1f%% of %d cases\n", other, w.percent(), w.cases);
  }
}

void runMerge(const SweepArgs& args) {
  if (!args.scenes.empty())
    throw Error("--merge takes sweep directories, not scenes (got '" + args.scenes[0] + "')");
  sweep::ReportInfo info;
  info.details = "merged from: " + joined(args.merge);
  std::vector<fs::path> inputs(args.merge.begin(), args.merge.end());
  const OwnedDirectory out(args.out, {"cases", "references"});
  printHeadline(args.out, sweep::mergeSweeps(args.out, inputs, info));
}

// Every case renders K = kCaseSplits sub-buffers (sample i to sub-buffer i mod K): below K spp
// some stay empty, and the members and their weights have less to work with
// (docs/ensemble-quality.md, "Below 4 spp"). Said at the end of a sweep that succeeded, so that a
// failing one prints its one error line only.
std::string lowSppWarning(const std::vector<int>& spps) {
  constexpr int k = sweep::kCaseSplits;
  std::string few;
  for (int spp : spps)
    if (spp < k) few += (few.empty() ? "" : ", ") + std::to_string(spp);
  if (few.empty()) return {};
  return "at " + few + " spp some of the " + std::to_string(k) +
         " sub-buffers get no samples, which left the members and their weights less to work "
         "with (chorus render denoises "
         "with the preview's members below 3 spp)";
}

void runSweepCommand(const SweepArgs& args) {
  if (!args.merge.empty()) return runMerge(args);
  if (args.scenes.empty()) throw Error("no scenes given (or --merge DIR... to combine sweeps)");
  sweep::SweepConfig config;
  config.scenes.assign(args.scenes.begin(), args.scenes.end());
  config.spps = sweep::parseIntList(args.spp, "--spp");
  for (int spp : config.spps)
    if (spp > kMaxSpp)
      throw Error("--spp '" + args.spp + "': " + std::to_string(spp) + " is above " +
                  std::to_string(kMaxSpp));
  config.methods = splitMethodList(args.methods.empty() ? defaultMethods() : args.methods);
  config.combos = args.combos;
  config.combiners = splitMethodList(args.combiners);
  config.references.assign(args.references.begin(), args.references.end());
  config.referenceSpp = args.referenceSpp;
  config.referenceSeconds = args.referenceSeconds;
  config.out = args.out;
  config.shard = sweep::parseShard(args.shard);
  config.render = args.scene.render;
  config.environment = args.scene.environment();
  config.combine = args.ensemble.options();
  config.cropSize = args.cropSize;
  // Every case renders with K = 4 and runs every method: checked before anything is written
  // when --width and --height fix the size, else as each scene is loaded (its camera decides).
  const std::vector<EnsembleMember> members = membersFromSpecs(config.methods);
  if (config.render.width > 0 && config.render.height > 0)
    checkRunMemory({config.render.width, config.render.height}, sweep::kCaseSplits, members);
  config.loadScene = [&](const fs::path& path) {
    render::Scene scene = std::move(loadScene(path.string(), args.scene, args.quiet).scene);
    checkRunMemory(render::renderResolution(scene, config.render), sweep::kCaseSplits, members);
    return scene;
  };
  config.progress = args.quiet ? nullptr : &std::cerr;
  config.report.details = describe(config, args);
  // Denoisers run on TBB: --threads limits them as it limits the renderer.
  const ThreadLimit threads(config.render.threads);
  const OwnedDirectory out(config.out, {"cases", "references"});  // held for the whole sweep

  const sweep::SweepRunStats stats = sweep::runSweep(config);
  if (!args.quiet) {
    std::cerr << "sweep: ran " << stats.casesRun << " case(s), " << stats.casesSkipped
              << " already done, " << stats.referencesRendered << " reference(s) rendered\n";
    const std::string few = lowSppWarning(config.spps);
    if (!few.empty()) std::cerr << "chorus: warning: " << few << "\n";
  }
  printHeadline(config.out, sweep::readCsv(config.out / "results.csv"));
}

const RegisterCommand sweepCommand(50, [](CLI::App& app) {
  auto args = std::make_shared<SweepArgs>();
  CLI::App* cmd = app.add_subcommand(
      "sweep",
      "Sample-count sweep: per scene and spp, render once (K = 4), run every base denoiser "
      "once, evaluate every combination with every combiner against a reference; writes "
      "DIR/results.csv and a self-contained DIR/report.html");
  cmd->add_option("scenes", args->scenes, "glTF scenes (.gltf or .glb)");
  cmd->add_option("--out", args->out, "Output directory (reruns resume from it)")
      ->required()
      ->transform(pathName());
  cmd->add_option("--spp", args->spp, "Comma-separated samples per pixel")->capture_default_str();
  cmd->add_option("--methods", args->methods,
                  "Comma-separated base denoisers (default: every built-in one)");
  cmd->add_option("--combos", args->combos,
                  "'all' (every subset of at least two methods), 'none', or a list such as "
                  "nfor+rdfc,nfor+nlm+atrous")
      ->capture_default_str();
  cmd->add_option("--combiners", args->combiners,
                  "Comma-separated: ensemble, onehot-pre, onehot-post, average, oracle, "
                  "oracle-unconstrained")
      ->capture_default_str();
  cmd->add_option("--reference", args->references,
                  "Reference EXR, once per scene in scene order (default: rendered into "
                  "DIR/references/)")
      ->transform(pathName());
  cmd->add_option("--reference-spp", args->referenceSpp, "Samples per pixel of rendered references")
      ->capture_default_str()
      ->transform(integerIn(1, kMaxSpp));
  cmd->add_option("--reference-seconds", args->referenceSeconds,
                  "Render each reference for about this long instead (spp from a 16-spp probe)")
      ->transform(finiteIn(kMinReferenceSeconds, kMaxReferenceSeconds));
  cmd->add_option("--shard", args->shard,
                  "I/N: run only the cases whose index mod N is I (for job arrays)")
      ->capture_default_str();
  cmd->add_option("--merge", args->merge,
                  "Combine the sweep directories of sharded runs into --out (no scenes)")
      ->expected(1, -1)
      ->transform(pathName());
  cmd->add_option("--crop-size", args->cropSize, "Side of the report's crops, pixels")
      ->capture_default_str()
      ->transform(integerIn(1, kMaxCropSize));
  args->scene.addFlags(*cmd);
  args->ensemble.addFlags(*cmd);
  cmd->add_flag("--quiet", args->quiet, "No progress lines");
  cmd->callback([args] { runSweepCommand(*args); });
});

}  // namespace
}  // namespace chorus::cli
