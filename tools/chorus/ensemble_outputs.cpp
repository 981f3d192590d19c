#include "tools/chorus/ensemble_outputs.h"

#include <cctype>
#include <cmath>
#include <functional>
#include <iostream>
#include <vector>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/image/output_values.h"
#include "common/image/png_io.h"
#include "denoise/metrics/metrics.h"

namespace chorus::cli {

std::string labelOf(const std::string& spec) {
  std::string label = spec;
  for (char& c : label)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.' ||
          c == '=' || c == '+'))
      c = '_';
  return label;
}

std::vector<EnsembleMember> fileSafeMembers(const std::vector<std::string>& specs) {
  std::vector<EnsembleMember> members = membersFromSpecs(specs);
  for (EnsembleMember& member : members) member.label = labelOf(member.label);
  return members;
}

void checkReferenceSize(const Image& reference, const std::filesystem::path& file, int width,
                        int height) {
  if (reference.width() != width || reference.height() != height)
    throw fileError(file, "is " + std::to_string(reference.width()) + "x" +
                              std::to_string(reference.height()) + "x" +
                              std::to_string(reference.channels()) + ", expected " +
                              std::to_string(width) + "x" + std::to_string(height) + "x3");
}

nlohmann::ordered_json metricsJson(const Image& image, const Image& reference) {
  const ImageMetrics m = computeMetrics(image, reference);
  nlohmann::ordered_json j;
  j["relmse"] = m.relMse;
  j["dssim"] = m.dssim;
  j["psnr"] = std::isfinite(m.psnr) ? nlohmann::ordered_json(m.psnr) : nlohmann::ordered_json();
  return j;
}

nlohmann::ordered_json combineOptionsJson(const CombineOptions& o) {
  return {{"combine", combinerName(o.combiner)},
          {"solver", solverName(o.solver)},
          {"mse", o.mse.form == MseForm::Summed ? "summed" : "per-channel"},
          {"estimate", estimateName(o.mse.estimate)},
          {"window", o.mse.windowRadius},
          {"full_run_window", o.mse.fullRunWindowRadius},
          {"window_color", o.mse.windowSigmaColor},
          {"relative", o.mse.relative},
          {"outlier_cap", o.mse.outlierCap},
          {"consistency", o.mse.consistency},
          {"plausibility", o.mse.plausibility},
          {"image_prior", o.mse.imagePrior},
          {"noisy_fallback", o.mse.noisyFallback},
          {"member_fallback", o.mse.memberFallback},
          {"weight_filter", o.filter.enabled ? "bilateral" : "none"},
          {"solver_seed", o.seed}};
}

std::vector<ExrLayer> writeRepairedExr(const std::filesystem::path& path,
                                       std::vector<ExrLayer> layers,
                                       const std::function<bool(const std::string&)>& isSigned) {
  std::erase_if(layers, [](const ExrLayer& layer) { return layer.image.empty(); });
  OutputRepairs repairs;
  for (ExrLayer& layer : layers) {
    const OutputRepairs r = repairForOutput(layer.image, isSigned && isSigned(layer.name));
    repairs.nonFinite += r.nonFinite;
    repairs.negative += r.negative;
  }
  if (repairs.total() > 0)
    std::cerr << "chorus: warning: " << path.string() << ": " << repairs.nonFinite
              << " NaN/Inf values written as 0 (+Inf as the largest float), " << repairs.negative
              << " negative radiance values as 0\n";
  writeExr(path, layers);
  return layers;
}

void writeCombined(const std::filesystem::path& dir, const std::string& name,
                   const CombineResult& result) {
  const std::vector<ExrLayer> written =
      writeRepairedExr(dir / (name + ".exr"),
                       {{"", result.image},
                        {"A", result.imageA},
                        {"B", result.imageB},
                        {"mseEstimate", result.mseEstimate}},
                       [](const std::string& layer) { return layer == "mseEstimate"; });
  writePng(dir / (name + ".png"), written.front().image);
}

void writeWeights(const std::filesystem::path& dir, const std::string& file,
                  const CombineResult& result, const std::vector<BaseOutputs>& bases) {
  std::vector<ExrLayer> weights;
  for (size_t i = 0; i < bases.size(); ++i) weights.push_back({bases[i].name, result.weights[i]});
  if (!result.noisyFallback.empty()) weights.push_back({"noisyFallback", result.noisyFallback});
  // Weights may be negative (oracle-unconstrained).
  writeRepairedExr(dir / file, std::move(weights), [](const std::string&) { return true; });
}

void writeBaseOutputs(const std::filesystem::path& dir, const std::vector<BaseOutputs>& bases) {
  for (const BaseOutputs& base : bases)
    writeRepairedExr(dir / (base.name + ".exr"), {{"", base.full}, {"A", base.a}, {"B", base.b}});
}

}  // namespace chorus::cli
