#pragma once
// The layer layout of `render.exr`: SampleBuffers <-> EXR layers.
//
//   sub<k>.color, sub<k>.colorVariance   colour mean (RGB) of sub-buffer k = 0 … K−1 and its
//                                        variance of the mean
//   sub<k>.albedo, sub<k>.normal         RGB / XYZ (stored as R G B) feature means
//   sub<k>.depth, sub<k>.visibility      1 channel (Y)
//   sub<k>.<q>Variance                   variance of the mean of each feature
//   sub<k>.sampleCount                   samples per pixel (Y)
//   ""                                   the full buffer's colour mean (RGB) with the emission
//                                        added, what viewers show first; the rest of the full
//                                        buffer is the exact merge of the sub-buffers and is not
//                                        stored
//   emission                             when the render separated it (SampleBuffers::emission):
//                                        what the camera sees emitted directly or in mirrors
//                                        (RGB), left out of every sub<k>.color
//
// With K = 1 and no emission the one buffer's layers carry no prefix: "" is its colour mean,
// then colorVariance, albedo, … as above (with emission it is sub0, so that "" is the image).
// Features are stored when the buffers hold them (BufferPlanes): a render for members that read
// fewer features has fewer layers. Reading takes the sub-buffers when present, otherwise the
// unprefixed layers as K = 1; colour and the sample count are required, each feature plane is read
// when present.
#include <filesystem>
#include <vector>

#include "common/image/exr_io.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus {

std::vector<ExrLayer> sampleBuffersToLayers(const SampleBuffers& buffers);
// The same, moving the sub-buffers' images into the layers instead of copying them (halves the
// peak memory of writing a large render; `buffers` is left empty).
std::vector<ExrLayer> sampleBuffersToLayers(SampleBuffers&& buffers);
// Throws chorus::Error naming `fileForErrors` when colour or a sample count is missing, a layer
// has the wrong channel count, a variance is stored without its mean, or the sub-buffers differ
// in size or in the planes they hold.
SampleBuffers sampleBuffersFromLayers(const std::vector<ExrLayer>& layers,
                                      const std::filesystem::path& fileForErrors);

}  // namespace chorus
