#pragma once
// The directory layout of the ensemble paper's reference code (Zheng et al. 2021), so that the
// outputs of any denoiser run elsewhere (OIDN, OptiX, a network) can be ensembled:
//
//   DIR/color.exr  colorA.exr  colorB.exr   noisy full buffer and its two independent halves
//   DIR/albedo.exr  normal.exr              full-buffer features
//   DIR/<m>/<m>.exr  <m>/<m>A.exr  <m>/<m>B.exr   method m run on the full buffer, A and B
//
// Every file is a single-layer EXR of the same size (RGB; RGBA is read as RGB, one channel is
// replicated to three).
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "denoise/ensemble/ensemble_inputs.h"

namespace chorus {

struct OutputsDirectory {
  EnsembleGuides guides;
  std::vector<BaseOutputs> bases;  // in the order of `methods`, named after them
};

// True when DIR has color.exr, colorA.exr and colorB.exr.
bool isOutputsDirectory(const std::filesystem::path& dir);

// Reads the noisy buffers and the given methods' outputs. Throws chorus::Error with one line
// naming the file for a missing method folder or file, a bad file, or a size mismatch.
OutputsDirectory readOutputsDirectory(const std::filesystem::path& dir,
                                      std::span<const std::string> methods);

// Writes the same layout (atomically, file by file).
void writeOutputsDirectory(const std::filesystem::path& dir, const EnsembleGuides& guides,
                           std::span<const BaseOutputs> bases);

}  // namespace chorus
