#include "tools/chorus/render_denoise.h"

#include "common/error.h"
#include "common/image/png_io.h"
#include "common/stopwatch.h"
#include "denoise/base/registry.h"
#include "denoise/pipeline/member_planes.h"
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
                         nlohmann::ordered_json& stats, const Image* reference,
                         const RunsProgressCallback& progress) const {
  const Ensemble ensemble(members, options);
  checkMembersCanRun(sources, ensemble.members());
  checkPlanesHeld(sources.full.whole.planes(), ensemble.members(), true);
  const Stopwatch denoise;
  const EnsembleResult result = ensemble.run(sources, nullptr, progress);
  const double denoiseSeconds = denoise.seconds();

  nlohmann::ordered_json& seconds = stats["seconds"];
  for (const StageTime& t : result.times) seconds[t.stage] = t.seconds;
  Stopwatch write;
  if (writeExrs)
    writeCombined(dir, "denoised", result.combined);
  else
    writePng(dir / "denoised.png", result.combined.image);
  if (keep.weights) writeWeights(dir, "weights.exr", result.combined, result.bases);
  if (keep.members) writeBaseOutputs(dir, result.bases);
  seconds["write denoised"] = write.seconds();

  stats["denoise"] = combineOptionsJson(options);
  // The radius the weights were estimated with (optionsForRuns widens it on large images).
  stats["denoise"]["window_used"] = result.options.mse.windowRadius;
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

BufferPlanes DenoiseStage::planesNeeded() const {
  if (enabled()) return planesReadBy(members, true);
  if (!writeExrs) return BufferPlanes::colorOnly();
  return planesReadBy(fileSafeMembers(splitMethodList(kDefaultDenoise)), true);
}

std::vector<std::string> DenoiseStage::files() const {
  if (!enabled()) return {};
  std::vector<std::string> files = {"denoised.png"};
  if (writeExrs) files.insert(files.begin(), "denoised.exr");
  if (keep.weights) files.push_back("weights.exr");
  if (keep.members)
    for (const EnsembleMember& member : members) files.push_back(member.label + ".exr");
  return files;
}

std::vector<LeftOut> DenoiseStage::leftOut() const {
  std::vector<LeftOut> files;
  if (!enabled()) return files;
  if (!writeExrs) files.push_back({"denoised.exr", "without --preview"});
  if (!keep.weights) files.push_back({"weights.exr", "--keep weights"});
  if (!keep.members)
    for (const EnsembleMember& member : members)
      files.push_back({member.label + ".exr", "--keep members"});
  return files;
}

std::string DenoiseStage::label() const {
  std::string text;
  for (const std::string& spec : specs) text += (text.empty() ? "" : ",") + spec;
  return text;
}

}  // namespace chorus::cli
