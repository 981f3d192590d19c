#pragma once
// The three inputs every base denoiser of an ensemble runs on (half A, half B, the full buffer),
// made from a render's sub-buffers or from an input that already has two halves, and the noisy
// guides the combination step reads from them.
#include <array>

#include "denoise/buffers/sample_buffers.h"
#include "denoise/ensemble/ensemble_inputs.h"

namespace chorus {

// The three inputs every base denoiser runs on. Each input sees only its own samples (the run
// on A must not see B: the MSE estimate relies on y^A being independent of x^B).
struct EnsembleSources {
  DenoiseInput a, b, full;
  // The emission the inputs' colour leaves out (SampleBuffers::emission; empty when none): every
  // member run's output and every noisy guide gets it added back, so that the ensemble weighs
  // and blends images of the whole scene while the members filter only the rest.
  Image emission;
  int width() const { return full.width(); }
  int height() const { return full.height(); }
};

// From K independent sub-buffers (K even): a = input(HalfA), b = input(HalfB), full =
// input(Full). With K = 4 the half runs get quarters as their own halves; with K = 2 they get
// none. Throws chorus::Error for an odd K. Without `halvesOfFull`, full.halves stays empty (no
// member reads it: see readsHalves and baseRunsFor in ensemble.h; addHalvesOfFull adds it).
EnsembleSources sourcesFromBuffers(const SampleBuffers& buffers, bool halvesOfFull = true);

// The same, taking the sub-buffers over (K = 2: they become a and b instead of being copied;
// `buffers` is left empty).
EnsembleSources sourcesFromBuffers(SampleBuffers&& buffers, bool halvesOfFull);

// The full buffer's halves: the half inputs' wholes (copies of every plane of both).
std::array<SubBuffer, 2> fullBufferHalves(const EnsembleSources& sources);
// full.halves = fullBufferHalves(sources).
void addHalvesOfFull(EnsembleSources& sources);

// From an input with two halves (e.g. a Tungsten directory): a = halves[0], b = halves[1]
// (without halves of their own), full = the input. Throws chorus::Error without halves.
EnsembleSources sourcesFromHalves(const DenoiseInput& input);

// The noisy colour of the full buffer, both halves (through the outlier guard, as the members
// see them: denoise/base/outlier_guard.h), and the full buffer's albedo and normal; with
// `withQuarters` and K = 4 also the four quarters (each guarded on its own samples). The
// sources' emission is added to every noisy colour.
EnsembleGuides guidesFromSources(const EnsembleSources& sources, bool withQuarters = false);

}  // namespace chorus
