// chorus denoise INPUT --methods a,b,... --out DIR: base denoisers plus an ensemble combiner
// (denoise/ensemble/) on
//   (a) a render.exr from `chorus render` (built-in methods from the registry),
//   (b) a directory in the ensemble paper's layout with the outputs of external denoisers
//       (color.exr, colorA.exr, colorB.exr, albedo.exr, normal.exr, <m>/<m>{,A,B}.exr),
//   (c) a Tungsten buffer directory (built-in methods; only halves A/B, no quarters).
// Writes DIR/<combiner>.exr/.png, DIR/weights.exr, DIR/<method>.exr and DIR/stats.json.
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "denoise/base/registry.h"
#include "denoise/buffers/buffers_exr.h"
#include "denoise/buffers/tungsten_dir.h"
#include "denoise/ensemble/ensemble.h"
#include "denoise/ensemble/outputs_directory.h"
#include "denoise/image/exr_io.h"
#include "denoise/image/png_io.h"
#include "denoise/metrics/metrics.h"
#include "denoise/util/atomic_file.h"
#include "denoise/util/error.h"
#include "tools/chorus/command.h"

namespace chorus::cli {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

struct DenoiseArgs {
  std::string input, methods, out;
  std::string combine = "ensemble", solver = "active-set", weightFilter = "bilateral";
  std::string mseForm = "summed", reference;
  int window = MseOptions{}.windowRadius;
  bool relative = MseOptions{}.relative;
  uint64_t seed = 1;
};

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A method spec as a file and layer name: "nlm:k=0.4" → "nlm_k=0.4".
std::string labelOf(const std::string& spec) {
  std::string label = spec;
  for (char& c : label)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.' ||
          c == '=' || c == '+'))
      c = '_';
  return label;
}

// What the combination step needs, from any of the three input forms.
struct LoadedInput {
  std::string kind;  // "render.exr", "outputs directory", "tungsten directory"
  EnsembleGuides guides;
  std::vector<BaseOutputs> bases;
  std::vector<StageTime> times;
};

LoadedInput runBuiltins(const EnsembleSources& sources, const std::vector<std::string>& specs,
                        const std::string& kind, const fs::path& input) {
  std::vector<EnsembleMember> members;
  for (const std::string& spec : specs)
    members.push_back({labelOf(spec), std::shared_ptr<const BaseDenoiser>(createDenoiser(spec))});
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

CombineOptions combineOptions(const DenoiseArgs& args) {
  CombineOptions o;
  o.solver = parseSolver(args.solver);
  if (args.mseForm == "per-channel")
    o.mse.form = MseForm::PerChannel;
  else if (args.mseForm == "summed")
    o.mse.form = MseForm::Summed;
  else
    throw Error("unknown --mse '" + args.mseForm + "' (known: per-channel, summed)");
  if (args.window < 0) throw Error("--window must be at least 0");
  o.mse.windowRadius = args.window;
  o.mse.relative = args.relative;
  if (args.weightFilter != "bilateral" && args.weightFilter != "none")
    throw Error("unknown --weight-filter '" + args.weightFilter + "' (known: bilateral, none)");
  o.filter.enabled = args.weightFilter == "bilateral";
  o.seed = args.seed;
  return o;
}

Json metricsJson(const Image& image, const Image& reference) {
  const ImageMetrics m = computeMetrics(image, reference);
  Json j;
  j["relmse"] = m.relMse;
  j["dssim"] = m.dssim;
  j["psnr"] = std::isfinite(m.psnr) ? Json(m.psnr) : Json();
  return j;
}

void writeResult(const fs::path& out, const std::string& name, const CombineResult& result,
                 const std::vector<BaseOutputs>& bases, const std::string& weightsFile) {
  writeExr(out / (name + ".exr"), {{"", result.image},
                                   {"A", result.imageA},
                                   {"B", result.imageB},
                                   {"mseEstimate", result.mseEstimate}});
  writePng(out / (name + ".png"), result.image);
  std::vector<ExrLayer> weights;
  for (size_t i = 0; i < bases.size(); ++i) weights.push_back({bases[i].name, result.weights[i]});
  writeExr(out / weightsFile, weights);
}

void runDenoise(const DenoiseArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<std::string> specs = splitMethodList(args.methods);
  std::vector<Combiner> combiners;
  for (const std::string& name : splitMethodList(args.combine))
    combiners.push_back(parseCombiner(name));
  const CombineOptions options = combineOptions(args);
  const fs::path out = args.out;

  LoadedInput input = loadInput(args.input, specs);
  std::optional<Image> reference;
  if (!args.reference.empty()) {
    reference = readExrLayer(args.reference);
    if (reference->channels() == 4) reference = reference->channelRange(0, 3);
    if (reference->channels() != 3 || !reference->sameSize(input.guides.color))
      throw fileError(args.reference, "is " + std::to_string(reference->width()) + "x" +
                                          std::to_string(reference->height()) + "x" +
                                          std::to_string(reference->channels()) + ", expected " +
                                          std::to_string(input.guides.width()) + "x" +
                                          std::to_string(input.guides.height()) + "x3");
  }
  for (Combiner c : combiners)
    if (needsReference(c) && !reference)
      throw Error("--combine " + std::string(combinerName(c)) + " needs --reference");
  input.times.insert(input.times.begin(), {"read", secondsSince(start)});
  checkEnsembleInputs(input.guides, pointersTo(input.bases));
  ensureDirectory(out);

  Json stats;
  stats["input"] = args.input;
  stats["input_kind"] = input.kind;
  stats["width"] = input.guides.width();
  stats["height"] = input.guides.height();
  stats["methods"] = specs;
  stats["options"] = {{"solver", args.solver},
                      {"mse", args.mseForm},
                      {"window", args.window},
                      {"relative", args.relative},
                      {"weight_filter", args.weightFilter},
                      {"seed", args.seed}};
  Json times = Json::object(), metrics = Json::object();
  for (const StageTime& t : input.times) times[t.stage] = t.seconds;
  for (size_t k = 0; k < combiners.size(); ++k) {
    CombineOptions o = options;
    o.combiner = combiners[k];
    const std::string name(combinerName(o.combiner));
    const CombineResult result =
        combine(input.guides, pointersTo(input.bases), o, reference ? &*reference : nullptr);
    for (const StageTime& t : result.times) times[name + "/" + t.stage] = t.seconds;
    const auto writeStart = std::chrono::steady_clock::now();
    writeResult(out, name, result, input.bases,
                k == 0 ? "weights.exr" : "weights-" + name + ".exr");
    times[name + "/write"] = secondsSince(writeStart);
    if (reference) metrics[name] = metricsJson(result.image, *reference);
    std::cout << "wrote " << (out / (name + ".exr")).string() << "\n";
  }
  const auto writeStart = std::chrono::steady_clock::now();
  for (const BaseOutputs& base : input.bases)
    writeExr(out / (base.name + ".exr"), {{"", base.full}, {"A", base.a}, {"B", base.b}});
  times["write bases"] = secondsSince(writeStart);
  if (reference) {
    metrics["noisy"] = metricsJson(input.guides.color, *reference);
    for (const BaseOutputs& base : input.bases)
      metrics[base.name] = metricsJson(base.full, *reference);
    stats["reference"] = args.reference;
    stats["metrics"] = metrics;
  }
  times["total"] = secondsSince(start);
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
  cmd->add_option("--out", args->out, "Output directory")->required();
  cmd->add_option("--combine", args->combine,
                  "Combiner, or a comma-separated list: ensemble, average, onehot-pre, "
                  "onehot-post, oracle, oracle-unconstrained (oracles need --reference)")
      ->capture_default_str();
  cmd->add_option("--solver", args->solver,
                  "Weight solver: active-set (exact) or pairwise (the "
                  "paper's iteration)")
      ->capture_default_str();
  cmd->add_option("--weight-filter", args->weightFilter,
                  "bilateral (joint bilateral on normal, albedo and the blend, radius 7) or none")
      ->capture_default_str();
  cmd->add_option(
         "--mse", args->mseForm,
         "MSE matrix per-channel (one weight per colour channel) or summed (one per pixel)")
      ->capture_default_str();
  cmd->add_option("--window", args->window,
                  "Radius of the feature-guided window the MSE estimate is accumulated over "
                  "(0 = per pixel, as in the paper)")
      ->capture_default_str();
  cmd->add_flag("--relative,!--absolute", args->relative,
                "Divide the MSE estimate by (mean² + 0.01) so that it targets relMSE");
  cmd->add_option("--reference", args->reference,
                  "Reference image (.exr): metrics in stats.json, and the oracle combiners");
  cmd->add_option("--seed", args->seed, "Seed of the pairwise solver")->capture_default_str();
  cmd->callback([args] { runDenoise(*args); });
});

}  // namespace
}  // namespace chorus::cli
