#include "denoise/pipeline/ensemble_sources.h"

#include "common/error.h"
#include "denoise/base/outlier_guard.h"

namespace chorus {
namespace {

void checkSplitCount(int k) {
  if (k < 2 || k % 2 != 0)
    throw Error("the ensemble needs an even number of independent sub-buffers (2 or 4), got " +
                std::to_string(k));
}

}  // namespace

EnsembleSources sourcesFromBuffers(const SampleBuffers& buffers, bool halvesOfFull) {
  checkSplitCount(buffers.splitCount());
  EnsembleSources sources;
  sources.a = buffers.input(BufferPart::HalfA);
  sources.b = buffers.input(BufferPart::HalfB);
  sources.full.whole = buffers.part(BufferPart::Full);
  sources.emission = buffers.emission();
  if (halvesOfFull) addHalvesOfFull(sources);
  return sources;
}

std::array<SubBuffer, 2> fullBufferHalves(const EnsembleSources& sources) {
  // Copied rather than merged again.
  return {sources.a.whole, sources.b.whole};
}

void addHalvesOfFull(EnsembleSources& sources) {
  sources.full.halves = fullBufferHalves(sources);
}

EnsembleSources sourcesFromBuffers(SampleBuffers&& buffers, bool halvesOfFull) {
  const int k = buffers.splitCount();
  checkSplitCount(k);
  EnsembleSources sources;
  sources.full.whole = buffers.part(BufferPart::Full);
  if (k == 2) {  // the halves are the two sub-buffers themselves: moved, not copied
    sources.a.whole = std::move(buffers.sub(0));
    sources.b.whole = std::move(buffers.sub(1));
    sources.a.sampleShare = sources.b.sampleShare = 0.5;
  } else {
    sources.a = buffers.input(BufferPart::HalfA);
    sources.b = buffers.input(BufferPart::HalfB);
  }
  sources.emission = buffers.emission();
  if (halvesOfFull) addHalvesOfFull(sources);
  buffers = {};
  return sources;
}

EnsembleSources sourcesFromHalves(const DenoiseInput& input) {
  if (!input.halves) throw Error("the ensemble needs two independent halves of the input");
  EnsembleSources sources;
  sources.a.whole = (*input.halves)[0];
  sources.b.whole = (*input.halves)[1];
  sources.a.sampleShare = sources.b.sampleShare = 0.5 * input.sampleShare;
  sources.full = input;
  return sources;
}

EnsembleGuides guidesFromSources(const EnsembleSources& sources, bool withQuarters) {
  EnsembleGuides guides;
  guides.color = sources.full.whole.color.mean;
  // The halves the error estimate compares the members with, as the members saw them: with the
  // outlier guard's clamps. A firefly left in x^B would dominate every (y^A − x^B)² around it.
  guides.colorA = guardOutliers(sources.a).input.whole.color.mean;
  guides.colorB = guardOutliers(sources.b).input.whole.color.mean;
  // With K = 4 the halves' own halves are the quarters the leave-one-quarter-out estimate
  // compares the held-out runs with (quarter k = half k / 2, own half k % 2), as rendered: not
  // guarded. A quarter holds a quarter of the samples (one at 4 spp), which never confirm a
  // bright value, so the guard clamped ordinary samples of bright surfaces and took 1-5 % off
  // every quarter's mean: the estimate then favoured members that were too dark, most where
  // the members differ by little (512 px: docs/ensemble-quality.md). The outlier cap weighs
  // down the fireflies they keep.
  if (withQuarters && sources.a.halves && sources.b.halves)
    for (const DenoiseInput* half : {&sources.a, &sources.b})
      for (const SubBuffer& quarter : *half->halves) guides.quarters.push_back(quarter.color.mean);
  for (Image* noisy : {&guides.color, &guides.colorA, &guides.colorB})
    addEmission(*noisy, sources.emission);
  for (Image& quarter : guides.quarters) addEmission(quarter, sources.emission);
  guides.albedo = sources.full.whole.albedo.mean;
  guides.normal = sources.full.whole.normal.mean;
  return guides;
}

}  // namespace chorus
