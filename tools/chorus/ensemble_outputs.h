#pragma once
// What `chorus denoise` and `chorus render --denoise` share: building members from method
// specs, reading a reference, and writing a combined result, its weight maps and the base
// outputs (the last two only with --keep, kept_outputs.h).
#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "common/image/exr_io.h"
#include "denoise/pipeline/ensemble.h"

namespace chorus::cli {

// A method spec as a file and layer name: "nlm:k=0.4" → "nlm_k=0.4".
std::string labelOf(const std::string& spec);

// membersFromSpecs (denoise/pipeline/ensemble.h) with labelOf labels, for file and layer names.
std::vector<EnsembleMember> fileSafeMembers(const std::vector<std::string>& specs);

// Throws chorus::Error naming `file` unless the reference read from it is width × height.
void checkReferenceSize(const Image& reference, const std::filesystem::path& file, int width,
                        int height);

// {"relmse", "dssim", "psnr"} of image against reference (PSNR null when infinite).
nlohmann::ordered_json metricsJson(const Image& image, const Image& reference);

// The options of a combination, for stats.json.
nlohmann::ordered_json combineOptionsJson(const CombineOptions& options);

// Writes the layers after repairForOutput (common/image/output_values.h: no NaN/Inf, and no
// negative radiance except in the layers `isSigned` names), with one warning line on stderr
// counting what was replaced. Empty layers are left out. Returns the layers as written.
std::vector<ExrLayer> writeRepairedExr(
    const std::filesystem::path& path, std::vector<ExrLayer> layers,
    const std::function<bool(const std::string&)>& isSigned = {});

// DIR/<name>.exr (layers: RGB = the blend, A and B when the members ran on the halves,
// mseEstimate) and DIR/<name>.png, through
// writeRepairedExr.
void writeCombined(const std::filesystem::path& dir, const std::string& name,
                   const CombineResult& result);

// The weight maps as DIR/<file>: one layer per base, and noisyFallback (1 where the blend is the
// noisy value) when the combiner has one; through writeRepairedExr (weights may be negative).
void writeWeights(const std::filesystem::path& dir, const std::string& file,
                  const CombineResult& result, const std::vector<BaseOutputs>& bases);

// DIR/<base>.exr for every base: RGB = the full-buffer output, layers A and B (when run).
void writeBaseOutputs(const std::filesystem::path& dir, const std::vector<BaseOutputs>& bases);

}  // namespace chorus::cli
