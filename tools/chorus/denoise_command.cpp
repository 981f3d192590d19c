// chorus denoise INPUT --methods a,b,... --out DIR: base denoisers, alone or blended per pixel by
// a combiner (denoise/ensemble/), on
//   (a) a render.exr from `chorus render` (built-in members; its K sub-buffers),
//   (b) a Tungsten buffer directory (built-in members; the full buffer and its halves A/B),
//   (c) a directory in the ensemble paper's layout with the outputs of external denoisers
//       (color.exr, colorA.exr, colorB.exr, albedo.exr, normal.exr, <m>/<m>{,A,B}.exr).
// --combine none (the default for a single method) runs each member alone on the full buffer:
// DIR/<method>.exr/.png and DIR/stats.json. Any other combiner runs every member on half A,
// half B and the full buffer and blends them: DIR/<combiner>.exr/.png and DIR/stats.json, with
// --keep weights DIR/weights.exr, with --keep members DIR/<method>.exr. docs/cli.md: which
// input can feed which member.
#include <nlohmann/json.hpp>

#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/image/finite_pixels.h"
#include "common/image/png_io.h"
#include "common/owned_directory.h"
#include "common/stopwatch.h"
#include "common/thread_limit.h"
#include "denoise/base/registry.h"
#include "denoise/buffers/buffers_exr.h"
#include "denoise/buffers/sample_buffers.h"
#include "denoise/buffers/tungsten_dir.h"
#include "denoise/ensemble/outputs_directory.h"
#include "denoise/pipeline/ensemble.h"
#include "denoise/pipeline/member_planes.h"
#include "tools/chorus/command.h"
#include "tools/chorus/ensemble_flags.h"
#include "tools/chorus/ensemble_outputs.h"
#include "tools/chorus/flag_checks.h"
#include "tools/chorus/kept_outputs.h"
#include "tools/chorus/progress_bar.h"
#include "tools/chorus/render_denoise.h"

namespace chorus::cli {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

struct DenoiseArgs {
  std::string input, methods, out;
  std::string combine;  // empty: ensemble, or none for a single method
  std::string reference;
  EnsembleFlags ensemble;
  KeptOutputs keep;
  int threads = 0;  // 0: all cores
  bool quiet = false;
};

// An input as read, before any member runs: the buffers built-in members run on (a render.exr's
// sub-buffers or a Tungsten directory's full buffer with its halves), or the finished outputs of
// an outputs directory.
struct ReadInput {
  fs::path path;
  std::string kind;  // "render.exr", "tungsten directory", "outputs directory"
  std::optional<SampleBuffers> render;
  std::optional<DenoiseInput> tungsten;
  std::optional<OutputsDirectory> outputs;

  int width() const {
    return render ? render->width() : tungsten ? tungsten->width() : outputs->guides.width();
  }
  int height() const {
    return render ? render->height() : tungsten ? tungsten->height() : outputs->guides.height();
  }
};

ReadInput readInput(const fs::path& path, const std::vector<std::string>& specs) {
  ReadInput input;
  input.path = path;
  if (fs::is_regular_file(path)) {
    input.kind = "render.exr";
    input.render = sampleBuffersFromLayers(readExr(path), path);
    return input;
  }
  if (!fs::is_directory(path)) throw fileError(path, "no such file or directory");
  bool anyFolder = false;
  for (const std::string& spec : specs) anyFolder = anyFolder || fs::is_directory(path / spec);
  if (anyFolder || (isOutputsDirectory(path) && !isTungstenDirectory(path))) {
    input.kind = "outputs directory";
    input.outputs = readOutputsDirectory(path, specs);
    return input;
  }
  if (isTungstenDirectory(path)) {
    input.kind = "tungsten directory";
    input.tungsten = readTungstenDirectory(path);
    return input;
  }
  throw fileError(path,
                  "is neither a render.exr, a directory of base outputs (color.exr, colorA.exr, "
                  "colorB.exr, <method>/…) nor a Tungsten buffer directory");
}

// What an error about the input's buffers adds: how to get an input that feeds the member.
std::string inputHint(const ReadInput& input, bool alone) {
  if (input.render && input.render->splitCount() == 1)
    return alone ? "; this render.exr holds 1 sub-buffer: render without --splits 1"
                 : "; this render.exr holds 1 sub-buffer: render without --splits 1, or run "
                   "each member alone with --combine none";
  if (alone) return "";
  if (input.render && input.render->splitCount() < 4)
    return "; render with --splits 4, or run it alone with --combine none";
  return "; run it alone on the full buffer with --combine none";
}

// A render.exr below K spp has sub-buffers without a sample (sample i goes to sub-buffer
// i mod K): the members' runs and the ensemble's estimate have less to work with
// (docs/ensemble-quality.md, "Below 4 spp"). Empty when every sub-buffer holds samples, or the
// render recorded no counts.
std::string emptySubBuffersWarning(const ReadInput& input) {
  if (!input.render) return {};
  const int splits = input.render->splitCount();
  int empty = 0;
  for (int k = 0; k < splits; ++k) {
    const SubBuffer& buffer = input.render->sub(k);
    if (buffer.sampleCount.empty()) return {};
    empty += holdsNoSamples(buffer);
  }
  if (empty == 0) return {};
  return input.path.string() + ": " + std::to_string(empty) + " of its " + std::to_string(splits) +
         " sub-buffers hold no samples, which leaves the members and their weights less to work "
         "with: render at least " +
         std::to_string(splits) + " spp (or, below 3 spp, denoise in chorus render)";
}

// Throws, naming the input, when a render.exr lacks a feature the members (and, `combined`, the
// combination) read: it was rendered for members that read fewer.
void checkFeaturesHeld(const ReadInput& input, const std::vector<EnsembleMember>& members,
                       bool combined) {
  if (!input.render) return;
  try {
    checkPlanesHeld(input.render->sub(0).planes(), members, combined);
  } catch (const Error& e) {
    throw fileError(input.path, e.what() + std::string(" (rendered for other members: render "
                                                       "with --denoise none, or with these)"));
  }
}

// Member outputs and the timings of their runs.
struct MemberRuns {
  std::vector<BaseOutputs> bases;  // alone: only `full` is set
  std::vector<StageTime> times;
  std::vector<EnsembleMember> members;  // empty for an outputs directory
  BaseRuns used;                        // the runs in `bases` (optionsForRuns)
};

// --combine none: each member alone on the full buffer (an outputs directory's full outputs are
// taken as they are).
MemberRuns runAlone(ReadInput& input, const std::vector<std::string>& specs,
                    const RunsProgressCallback& progress) {
  MemberRuns runs;
  if (input.outputs) {
    runs.bases = std::move(input.outputs->bases);
    return runs;
  }
  const std::vector<EnsembleMember> members = fileSafeMembers(specs);
  std::optional<DenoiseInput> merged;  // a render's full buffer and its halves A and B
  if (input.render) merged = input.render->input(BufferPart::Full);
  const DenoiseInput& full = merged ? *merged : *input.tungsten;
  checkFeaturesHeld(input, members, false);
  try {
    checkMembersCanRunAlone(full, members);
  } catch (const Error& e) {
    throw fileError(input.path, e.what() + inputHint(input, true));
  }
  std::vector<Image> images = runMembersAlone(full, members, &runs.times, progress);
  for (size_t m = 0; m < members.size(); ++m) {
    if (input.render) addEmission(images[m], input.render->emission());
    runs.bases.push_back({members[m].label, {}, {}, std::move(images[m]), {}});
  }
  return runs;
}

// Every member on half A, half B and the full buffer (and the held-out inputs when the estimate
// uses them), for the combiners.
MemberRuns runForEnsemble(ReadInput& input, const std::vector<std::string>& specs,
                          const MseOptions& mse, EnsembleGuides* guides,
                          const RunsProgressCallback& progress) {
  MemberRuns runs;
  if (input.outputs) {
    runs.bases = std::move(input.outputs->bases);
    *guides = std::move(input.outputs->guides);
    return runs;
  }
  runs.members = fileSafeMembers(specs);
  const std::vector<EnsembleMember>& members = runs.members;
  checkFeaturesHeld(input, members, true);
  EnsembleSources sources;
  try {
    // The full buffer's halves, when a run on it needs them, are built for that run only
    // (runBaseDenoisers).
    sources = input.render ? sourcesFromBuffers(*input.render, false)
                           : sourcesFromHalves(*input.tungsten);
    checkMembersCanRun(sources, members);
  } catch (const Error& e) {
    throw fileError(input.path, e.what() + inputHint(input, false));
  }
  runs.used = baseRunsFor(mse, sources);
  runs.bases = runBaseDenoisers(sources, members, &runs.times, runs.used, progress);
  *guides = guidesFromSources(sources, runs.used.heldOut);
  return runs;
}

// The noisy full-buffer colour, for the metrics of the input.
Image noisyColor(const ReadInput& input) {
  if (input.outputs) return input.outputs->guides.color;
  if (input.tungsten) return input.tungsten->whole.color.mean;
  return input.render->noisyColor();
}

// The combiners of --combine; none of them for --combine none (or no --combine and one method).
std::vector<Combiner> combinersOf(const std::string& list, size_t methodCount) {
  if (list.empty())
    return methodCount == 1 ? std::vector<Combiner>{} : std::vector{Combiner::Ensemble};
  const std::vector<std::string> names = splitMethodList(list);
  std::vector<Combiner> combiners;
  for (const std::string& name : names) {
    if (name != "none") {
      combiners.push_back(parseCombiner(name));
      continue;
    }
    if (names.size() > 1)
      throw Error("--combine none runs each method alone: it cannot be listed with combiners");
  }
  return combiners;
}

// "wrote PATH" on stdout, unless --quiet.
void reportWritten(const DenoiseArgs& args, const fs::path& path) {
  if (!args.quiet) std::cout << "wrote " << path.string() << "\n";
}

// Writes DIR/stats.json, and its warnings on stderr (unless --quiet): at the end, once the run
// has succeeded, so that a run that fails prints its one error line only.
void writeStats(const DenoiseArgs& args, Json& stats, Json& times, const Stopwatch& total) {
  if (!args.quiet)
    for (const Json& warning : stats["warnings"])
      std::cerr << "chorus: warning: " << warning.get<std::string>() << "\n";
  times["total"] = total.seconds();
  stats["seconds"] = times;
  const fs::path path = fs::path(args.out) / "stats.json";
  writeTextAtomically(path, stats.dump(2) + "\n");
  reportWritten(args, path);
}

void runDenoise(const DenoiseArgs& args) {
  const Stopwatch total;
  const ThreadLimit threads(args.threads);
  const std::vector<std::string> specs =
      splitMethodList(args.methods == "default" ? kDefaultDenoise : args.methods);
  const std::vector<Combiner> combiners = combinersOf(args.combine, specs.size());
  const CombineOptions options = args.ensemble.options();
  const fs::path out = args.out;
  const OwnedDirectory owned(out);  // one run at a time in DIR

  ReadInput input = readInput(args.input, specs);
  std::optional<Image> reference;
  if (!args.reference.empty()) {
    reference = readRgbExr(args.reference);
    requireFinitePixels(*reference, args.reference);
    checkReferenceSize(*reference, args.reference, input.width(), input.height());
  }
  for (Combiner c : combiners)
    if (needsReference(c) && !reference)
      throw Error("--combine " + std::string(combinerName(c)) + " needs --reference");
  const double readSeconds = total.seconds();
  const std::string emptySubBuffers = emptySubBuffersWarning(input);

  Json stats;
  stats["input"] = args.input;
  stats["input_kind"] = input.kind;
  stats["width"] = input.width();
  stats["height"] = input.height();
  stats["methods"] = specs;
  stats["threads"] = args.threads;
  stats["warnings"] = emptySubBuffers.empty() ? Json::array() : Json::array({emptySubBuffers});
  Json combinerNames = Json::array();
  for (Combiner c : combiners) combinerNames.push_back(combinerName(c));
  stats["combine"] = combiners.empty() ? Json("none") : combinerNames;
  Json times = Json::object(), metrics = Json::object();
  times["read"] = readSeconds;
  if (reference) {
    stats["reference"] = args.reference;
    metrics["noisy"] = metricsJson(noisyColor(input), *reference);
  }

  // The members' runs on a terminal line (they take most of the time), unless --quiet.
  RunsProgressLine progress(!args.quiet && TerminalLine::stderrIsTerminal());
  if (combiners.empty()) {
    const MemberRuns runs = runAlone(input, specs, progress.callback());
    progress.finish();
    for (const StageTime& t : runs.times) times[t.stage] = t.seconds;
    ensureDirectory(out);
    const Stopwatch write;
    std::vector<std::string> written;
    for (const BaseOutputs& base : runs.bases) {
      writeExr(out / (base.name + ".exr"), base.full);
      writePng(out / (base.name + ".png"), base.full);
      written.insert(written.end(), {base.name + ".exr", base.name + ".png"});
      if (reference) metrics[base.name] = metricsJson(base.full, *reference);
      reportWritten(args, out / (base.name + ".exr"));
    }
    times["write"] = write.seconds();
    written.push_back("stats.json");
    stats["outputs"] = outputsJson(written, {});  // the members' outputs are the result
    if (reference) stats["metrics"] = metrics;
    return writeStats(args, stats, times, total);
  }

  EnsembleGuides guides;
  const MemberRuns runs = runForEnsemble(input, specs, options.mse, &guides, progress.callback());
  progress.finish();
  for (const StageTime& t : runs.times) times[t.stage] = t.seconds;
  checkEnsembleInputs(guides, pointersTo(runs.bases));
  ensureDirectory(out);
  stats["options"] = combineOptionsJson(options);
  stats["options"].erase("combine");  // one run per --combine value
  const CombineOptions forRuns =
      optionsForRuns(options, runs.used, runs.members, guides.width(), guides.height());
  // The radius the weights were estimated with (optionsForRuns widens it on large images).
  stats["options"]["window_used"] = forRuns.mse.windowRadius;
  std::vector<std::string> written;
  std::vector<LeftOut> leftOut;
  for (size_t k = 0; k < combiners.size(); ++k) {
    CombineOptions o = forRuns;
    o.combiner = combiners[k];
    const std::string name(combinerName(o.combiner));
    const CombineResult result =
        combine(guides, pointersTo(runs.bases), o, reference ? &*reference : nullptr);
    for (const StageTime& t : result.times) times[name + "/" + t.stage] = t.seconds;
    const Stopwatch write;
    writeCombined(out, name, result);
    written.insert(written.end(), {name + ".exr", name + ".png"});
    const std::string weightsFile = k == 0 ? "weights.exr" : "weights-" + name + ".exr";
    if (args.keep.weights) {
      writeWeights(out, weightsFile, result, runs.bases);
      written.push_back(weightsFile);
    } else {
      leftOut.push_back({weightsFile, "--keep weights"});
    }
    times[name + "/write"] = write.seconds();
    if (reference) metrics[name] = metricsJson(result.image, *reference);
    if (o.combiner == Combiner::Ensemble)
      stats["noisy_fallback_pixels"] = result.noisyFallbackPixels;
    reportWritten(args, out / (name + ".exr"));
  }
  if (args.keep.members) {
    const Stopwatch writeBases;
    writeBaseOutputs(out, runs.bases);
    times["write bases"] = writeBases.seconds();
  }
  for (const BaseOutputs& base : runs.bases) {
    if (args.keep.members)
      written.push_back(base.name + ".exr");
    else
      leftOut.push_back({base.name + ".exr", "--keep members"});
  }
  written.push_back("stats.json");
  stats["outputs"] = outputsJson(written, leftOut);
  if (reference) {
    for (const BaseOutputs& base : runs.bases)
      metrics[base.name] = metricsJson(base.full, *reference);
    stats["metrics"] = metrics;
  }
  writeStats(args, stats, times, total);
}

const RegisterCommand denoiseCommand(40, [](CLI::App& app) {
  auto args = std::make_shared<DenoiseArgs>();
  CLI::App* cmd = app.add_subcommand(
      "denoise",
      "Run base denoisers alone on the full buffer (--combine none, the default for one method), "
      "or on half A, half B and the full buffer blended per pixel (ensemble, Zheng et al. 2021) "
      "or by another combiner");
  cmd->add_option("input", args->input,
                  "render.exr from `chorus render`, a Tungsten buffer directory, or a directory "
                  "of base outputs (color.exr colorA.exr colorB.exr albedo.exr normal.exr "
                  "<m>/<m>{,A,B}.exr). Members that need two halves of their input (nfor, rdfc, "
                  "nlm) run alone on a render.exr of 2 or more sub-buffers or a Tungsten "
                  "directory, in the ensemble on a render.exr of 4; the others on any input")
      ->required();
  cmd->add_option("--methods", args->methods,
                  "Comma-separated base denoisers: built-in specs (name or name:key=value) for a "
                  "render.exr or Tungsten directory (default: chorus render's default members), "
                  "folder names for a directory of outputs")
      ->required();
  cmd->add_option("--out", args->out, "Output directory")->required()->transform(pathName());
  cmd->add_option("--combine", args->combine,
                  "none (each method alone on the full buffer: DIR/<method>.exr/.png), or a "
                  "combiner or comma-separated list of them: ensemble, average, onehot-pre, "
                  "onehot-post, oracle, oracle-unconstrained (oracles need --reference). "
                  "Default: none for one method, else ensemble");
  args->ensemble.addFlags(*cmd);
  args->keep.addFlag(*cmd);
  cmd->add_option("--reference", args->reference,
                  "Reference image (.exr): relMSE, DSSIM and PSNR of the noisy input, each member "
                  "and each combination in stats.json, and the oracle combiners");
  cmd->add_option("--threads", args->threads, "Worker threads (0: all cores)")
      ->capture_default_str()
      ->transform(integerIn(0, kMaxThreads));
  cmd->add_flag("--quiet", args->quiet, "No progress line and no \"wrote\" lines");
  cmd->callback([args] { runDenoise(*args); });
});

}  // namespace
}  // namespace chorus::cli
