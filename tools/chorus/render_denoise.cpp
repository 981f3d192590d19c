#include "tools/chorus/render_denoise.h"

#include "common/error.h"
#include "common/image/png_io.h"
#include "common/stopwatch.h"
#include "denoise/base/registry.h"
#include "tools/chorus/ensemble_outputs.h"

namespace chorus::cli {

DenoiseStage DenoiseStage::parse(const std::string& list, CombineOptions options, bool writeExrs) {
  DenoiseStage stage;
  stage.options = options;
  stage.writeExrs = writeExrs;
  if (list == "none") return stage;
  const std::string expanded = list == "default"   ? kDefaultDenoise
                               : list == "preview" ? kPreviewDenoise
                                                   : list;
  stage.specs = splitMethodList(expanded);
  stage.members = fileSafeMembers(stage.specs);  // unknown names and parameters fail here,
                                                 // before the render
  if (needsReference(options.combiner))
    throw Error("--combine " + std::string(combinerName(options.combiner)) +
                " needs a reference: use `chorus denoise --reference` on render.exr");
  return stage;
}

double DenoiseStage::run(const EnsembleSources& sources, const std::filesystem::path& dir,
                         nlohmann::ordered_json& stats, const Image* reference) const {
  const Ensemble ensemble(members, options);
  checkMembersCanRun(sources, ensemble.members());
  const Stopwatch denoise;
  const EnsembleResult result = ensemble.run(sources);
  const double denoiseSeconds = denoise.seconds();

  nlohmann::ordered_json& seconds = stats["seconds"];
  for (const StageTime& t : result.times) seconds[t.stage] = t.seconds;
  Stopwatch write;
  if (writeExrs) {
    writeCombined(dir, "denoised", result.combined, result.bases, "weights.exr");
    writeBaseOutputs(dir, result.bases);
  } else {
    writePng(dir / "denoised.png", result.combined.image);
  }
  seconds["write denoised"] = write.seconds();

  stats["denoise"] = combineOptionsJson(options);
  stats["denoise"]["methods"] = specs;
  stats["denoise"]["noisy_fallback_pixels"] = result.combined.noisyFallbackPixels;
  if (reference) {
    nlohmann::ordered_json& metrics = stats["metrics"];
    metrics["noisy"] = metricsJson(result.guides.color, *reference);
    for (const BaseOutputs& base : result.bases)
      metrics[base.name] = metricsJson(base.full, *reference);
    metrics["denoised"] = metricsJson(result.combined.image, *reference);
  }
  return denoiseSeconds;
}

int DenoiseStage::splitsNeeded() const {
  if (enabled()) return chorus::splitsNeeded(members);
  if (!writeExrs) return 1;
  return chorus::splitsNeeded(fileSafeMembers(splitMethodList(kDefaultDenoise)));
}

std::string DenoiseStage::label() const {
  std::string text;
  for (const std::string& spec : specs) text += (text.empty() ? "" : ",") + spec;
  return text;
}

}  // namespace chorus::cli
