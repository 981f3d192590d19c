#pragma once
// The buffer planes (BufferPlanes: the mean and variance of each feature) each built-in member
// reads and what the combination reads, so that a render records only those (a render for the
// preview's à-trous members has no visibility and no feature variances), and a later run on a
// render.exr fails with one line when its members read a plane the file does not hold.
#include <span>
#include <string>

#include "denoise/buffers/sample_buffers.h"
#include "denoise/pipeline/ensemble.h"

namespace chorus {

// What `denoiser` reads of its input, by its name (an unknown denoiser: every plane).
BufferPlanes planesReadBy(const BaseDenoiser& denoiser);

// What the members read, and with `combined` what the combination of their outputs reads too
// (the full buffer's albedo and normal, the weight filter's and the error estimate's guides).
BufferPlanes planesReadBy(std::span<const EnsembleMember> members, bool combined);

// Throws chorus::Error (one line) naming the first member and the planes it reads that `held`
// lacks; `combined` as above.
void checkPlanesHeld(BufferPlanes held, std::span<const EnsembleMember> members, bool combined);

}  // namespace chorus
