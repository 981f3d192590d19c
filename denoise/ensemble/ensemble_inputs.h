#pragma once
// The data the ensemble combines: the noisy half-buffer means and features ("guides") and, for
// every base denoiser, its outputs on half A, half B and the full buffer. Issue 7's sweeps run
// every base denoiser once and then combine subsets of the same BaseOutputs, so the combination
// step takes pointers to them (nothing is copied per combination).
#include <span>
#include <string>
#include <vector>

#include "denoise/buffers/sample_buffers.h"
#include "denoise/image/image.h"

namespace chorus {

// Noisy inputs and features of one render, all of the same size.
struct EnsembleGuides {
  Image color;           // full-buffer noisy colour (RGB): the fallback where no base is finite
  Image colorA, colorB;  // x^A, x^B: noisy half-buffer means (RGB)
  Image albedo, normal;  // full-buffer feature means (RGB / XYZ), guides of the weight filter

  int width() const { return color.width(); }
  int height() const { return color.height(); }
};

// One base denoiser's outputs: y^A (run on half A only), y^B (half B only) and y (full buffer).
struct BaseOutputs {
  std::string name;
  Image a, b, full;
};

// The three inputs every base denoiser runs on. Each input sees only its own samples (the run
// on A must not see B: the MSE estimate relies on y^A being independent of x^B).
struct EnsembleSources {
  DenoiseInput a, b, full;
  int width() const { return full.width(); }
  int height() const { return full.height(); }
};

// From K independent sub-buffers (K even): a = input(HalfA), b = input(HalfB), full =
// input(Full). With K = 4 the half runs get quarters as their own halves; with K = 2 they get
// none. Throws chorus::Error for an odd K.
EnsembleSources sourcesFromBuffers(const SampleBuffers& buffers);

// The same, taking the sub-buffers over (K = 2: they become a and b instead of being copied;
// `buffers` is left empty). Without `halvesOfFull`, full.halves stays empty (for members that
// never read it: see readsHalves in ensemble.h).
EnsembleSources sourcesFromBuffers(SampleBuffers&& buffers, bool halvesOfFull);

// From an input with two halves (e.g. a Tungsten directory): a = halves[0], b = halves[1]
// (without halves of their own), full = the input. Throws chorus::Error without halves.
EnsembleSources sourcesFromHalves(const DenoiseInput& input);

EnsembleGuides guidesFromSources(const EnsembleSources& sources);

// Throws chorus::Error (one line naming the image) unless every guide and base output is RGB
// of the guides' size, and there are 1 … kMaxDenoisers bases with distinct names.
void checkEnsembleInputs(const EnsembleGuides& guides, std::span<const BaseOutputs* const> bases);

// Pointers to every element, for combine().
std::vector<const BaseOutputs*> pointersTo(const std::vector<BaseOutputs>& bases);

}  // namespace chorus
