#pragma once
// The files of one cached corpus case (tools/eval/ensemble_cache.cpp writes them,
// tools/eval/combine_cached.cpp reads them): the noisy guides with the quarters, and every
// member's runs on A, B, the full buffer and without each quarter.
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "denoise/ensemble/ensemble_inputs.h"

namespace chorus {

std::filesystem::path cachedGuidesPath(const std::filesystem::path& dir);
// DIR/members/<spec>.exr, ':' and '=' of the spec replaced by '_' and '-'.
std::filesystem::path cachedMemberPath(const std::filesystem::path& dir, const std::string& spec);

void writeCachedGuides(const std::filesystem::path& dir, const EnsembleGuides& guides);
EnsembleGuides readCachedGuides(const std::filesystem::path& dir);

// Also writes the seconds of each run (A, B, full, heldOut0 … 3) next to the EXR (.tsv).
void writeCachedMember(const std::filesystem::path& dir, const BaseOutputs& outputs,
                       std::span<const double> seconds);
BaseOutputs readCachedMember(const std::filesystem::path& dir, const std::string& spec);

}  // namespace chorus
