// chorus denoise INPUT --methods a,b,... --out DIR: base denoisers plus an ensemble combiner
// (denoise/ensemble/) on
//   (a) a render.exr from `chorus render` (built-in methods from the registry),
//   (b) a directory in the ensemble paper's layout with the outputs of external denoisers
//       (color.exr, colorA.exr, colorB.exr, albedo.exr, normal.exr, <m>/<m>{,A,B}.exr),
//   (c) a Tungsten buffer directory (built-in methods; only halves A/B, no quarters).
// Writes DIR/<combiner>.exr/.png, DIR/weights.exr, DIR/<method>.exr and DIR/stats.json.
#include <nlohmann/json.hpp>

#include <cmath>
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
#include "denoise/base/registry.h"
#include "denoise/buffers/buffers_exr.h"
#include "denoise/buffers/tungsten_dir.h"
#include "denoise/ensemble/outputs_directory.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/ensemble.h"
#include "tools/chorus/command.h"
#include "tools/chorus/ensemble_flags.h"
#include "tools/chorus/ensemble_outputs.h"
#include "tools/chorus/flag_checks.h"

namespace chorus::cli {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

struct DenoiseArgs {
  std::string input, methods, out;
  std::string combine = "ensemble", reference;
  EnsembleFlags ensemble;
};

// What the combination step needs, from any of the three input forms.
struct LoadedInput {
  std::string kind;  // "render.exr", "outputs directory", "tungsten directory"
  EnsembleGuides guides;
  std::vector<BaseOutputs> bases;
  std::vector<StageTime> times;
};

LoadedInput runBuiltins(const EnsembleSources& sources, const std::vector<std::string>& specs,
                        const std::string& kind, const fs::path& input) {
  const std::vector<EnsembleMember> members = fileSafeMembers(specs);
  LoadedInput loaded;
  loaded.kind = kind;
  try {
    checkMembersCanRun(sources, members);
  } catch (const Error& e) {
    throw fileError(input, e.what());
  }
  loaded.bases = runBaseDenoisers(sources, members, &loaded.times);
  loaded.guides = guidesFromSources(sources);
  return loaded;
}

LoadedInput loadInput(const fs::path& input, const std::vector<std::string>& specs) {
  if (fs::is_regular_file(input)) {
    const SampleBuffers buffers = sampleBuffersFromLayers(readExr(input), input);
    EnsembleSources sources;
    try {
      sources = sourcesFromBuffers(buffers);
    } catch (const Error& e) {
      throw fileError(input, std::string(e.what()) + " (render with --splits 4)");
    }
    return runBuiltins(sources, specs, "render.exr", input);
  }
  if (!fs::is_directory(input)) throw fileError(input, "no such file or directory");
  bool anyFolder = false;
  for (const std::string& spec : specs) anyFolder = anyFolder || fs::is_directory(input / spec);
  if (anyFolder || (isOutputsDirectory(input) && !isTungstenDirectory(input))) {
    LoadedInput loaded;
    loaded.kind = "outputs directory";
    OutputsDirectory dir = readOutputsDirectory(input, specs);
    loaded.guides = std::move(dir.guides);
    loaded.bases = std::move(dir.bases);
    return loaded;
  }
  if (isTungstenDirectory(input))
    return runBuiltins(sourcesFromHalves(readTungstenDirectory(input)), specs, "tungsten directory",
                       input);
  throw fileError(input,
                  "is neither a render.exr, a directory of base outputs (color.exr, colorA.exr, "
                  "colorB.exr, <method>/…) nor a Tungsten buffer directory");
}

void runDenoise(const DenoiseArgs& args) {
  const Stopwatch total;
  const std::vector<std::string> specs = splitMethodList(args.methods);
  std::vector<Combiner> combiners;
  for (const std::string& name : splitMethodList(args.combine))
    combiners.push_back(parseCombiner(name));
  const CombineOptions options = args.ensemble.options();
  const fs::path out = args.out;
  const OwnedDirectory owned(out);  // one run at a time in DIR

  LoadedInput input = loadInput(args.input, specs);
  std::optional<Image> reference;
  if (!args.reference.empty()) {
    reference = readRgbExr(args.reference);
    requireFinitePixels(*reference, args.reference);
    checkReferenceSize(*reference, args.reference, input.guides.width(), input.guides.height());
  }
  for (Combiner c : combiners)
    if (needsReference(c) && !reference)
      throw Error("--combine " + std::string(combinerName(c)) + " needs --reference");
  input.times.insert(input.times.begin(), {"read", total.seconds()});
  checkEnsembleInputs(input.guides, pointersTo(input.bases));
  ensureDirectory(out);

  Json stats;
  stats["input"] = args.input;
  stats["input_kind"] = input.kind;
  stats["width"] = input.guides.width();
  stats["height"] = input.guides.height();
  stats["methods"] = specs;
  stats["options"] = combineOptionsJson(options);
  stats["options"].erase("combine");  // one run per --combine value
  Json times = Json::object(), metrics = Json::object();
  for (const StageTime& t : input.times) times[t.stage] = t.seconds;
  for (size_t k = 0; k < combiners.size(); ++k) {
    CombineOptions o = options;
    o.combiner = combiners[k];
    const std::string name(combinerName(o.combiner));
    const CombineResult result =
        combine(input.guides, pointersTo(input.bases), o, reference ? &*reference : nullptr);
    for (const StageTime& t : result.times) times[name + "/" + t.stage] = t.seconds;
    const Stopwatch write;
    writeCombined(out, name, result, input.bases,
                  k == 0 ? "weights.exr" : "weights-" + name + ".exr");
    times[name + "/write"] = write.seconds();
    if (reference) metrics[name] = metricsJson(result.image, *reference);
    if (o.combiner == Combiner::Ensemble)
      stats["noisy_fallback_pixels"] = result.noisyFallbackPixels;
    std::cout << "wrote " << (out / (name + ".exr")).string() << "\n";
  }
  const Stopwatch writeBases;
  writeBaseOutputs(out, input.bases);
  times["write bases"] = writeBases.seconds();
  if (reference) {
    metrics["noisy"] = metricsJson(input.guides.color, *reference);
    for (const BaseOutputs& base : input.bases)
      metrics[base.name] = metricsJson(base.full, *reference);
    stats["reference"] = args.reference;
    stats["metrics"] = metrics;
  }
  times["total"] = total.seconds();
  stats["seconds"] = times;
  writeTextAtomically(out / "stats.json", stats.dump(2) + "\n");
  std::cout << "wrote " << (out / "stats.json").string() << "\n";
}

const RegisterCommand registration(40, [](CLI::App& app) {
  auto args = std::make_shared<DenoiseArgs>();
  CLI::App* cmd = app.add_subcommand(
      "denoise",
      "Run base denoisers on half A, half B and the full buffer and blend them per pixel "
      "(ensemble, Zheng et al. 2021) or with another combiner");
  cmd->add_option("input", args->input,
                  "render.exr from `chorus render`, a directory of base outputs "
                  "(color.exr colorA.exr colorB.exr albedo.exr normal.exr <m>/<m>{,A,B}.exr) "
                  "or a Tungsten buffer directory")
      ->required();
  cmd->add_option("--methods", args->methods,
                  "Comma-separated base denoisers: built-in specs (name or name:key=value) for a "
                  "render.exr or Tungsten directory, folder names for a directory of outputs")
      ->required();
  cmd->add_option("--out", args->out, "Output directory")->required()->transform(nonEmpty());
  cmd->add_option("--combine", args->combine,
                  "Combiner, or a comma-separated list: ensemble, average, onehot-pre, "
                  "onehot-post, oracle, oracle-unconstrained (oracles need --reference)")
      ->capture_default_str();
  args->ensemble.addFlags(*cmd);
  cmd->add_option("--reference", args->reference,
                  "Reference image (.exr): metrics in stats.json, and the oracle combiners");
  cmd->callback([args] { runDenoise(*args); });
});

}  // namespace
}  // namespace chorus::cli
