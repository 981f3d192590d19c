#pragma once
// The layer layout of `render.exr`: SampleBuffers <-> EXR layers.
//
//   ""                     full-buffer colour mean (RGB), what viewers show first
//   colorVariance          its variance of the mean
//   albedo, normal         RGB / XYZ (stored as R G B) means of the full buffer
//   depth, visibility      1 channel (Y)
//   <q>Variance            variance of the mean of each of the above
//   sampleCount            samples per pixel (Y)
//   sub<k>.<q>, sub<k>.<q>Variance, sub<k>.sampleCount   the same for sub-buffer k = 0 … K−1
//
// Reading takes the sub-buffers when present (exact), otherwise the full-buffer layers as K = 1.
#include <filesystem>
#include <vector>

#include "common/image/exr_io.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus {

std::vector<ExrLayer> sampleBuffersToLayers(const SampleBuffers& buffers);
// The same, moving the sub-buffers' images into the layers instead of copying them (halves the
// peak memory of writing a large render; `buffers` is left empty).
std::vector<ExrLayer> sampleBuffersToLayers(SampleBuffers&& buffers);
SampleBuffers sampleBuffersFromLayers(const std::vector<ExrLayer>& layers,
                                      const std::filesystem::path& fileForErrors);

}  // namespace chorus
