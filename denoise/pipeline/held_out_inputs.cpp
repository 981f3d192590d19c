#include "denoise/pipeline/held_out_inputs.h"

#include "common/error.h"

namespace chorus {
namespace {

const SubBuffer& quarter(const EnsembleSources& sources, int k) {
  return (k < 2 ? *sources.a.halves : *sources.b.halves)[size_t(k % 2)];
}

}  // namespace

bool hasQuarters(const EnsembleSources& sources) {
  return sources.a.halves.has_value() && sources.b.halves.has_value();
}

DenoiseInput heldOutInput(const EnsembleSources& sources, int k) {
  if (!hasQuarters(sources))
    throw Error(
        "the leave-one-quarter-out estimate needs 4 independent sub-buffers (this input has "
        "only 2)");
  if (k < 0 || k >= kHeldOutQuarters) throw Error("heldOutInput: no quarter " + std::to_string(k));
  // The intact half (the other pair of quarters) and the quarter left of k's own pair.
  const DenoiseInput& intact = k < 2 ? sources.b : sources.a;
  const SubBuffer& single = quarter(sources, k ^ 1);
  DenoiseInput in;
  in.sampleShare = 0.75;
  if (holdsNoSamples(single)) {
    // Only the intact pair holds samples: its quarters are the halves, since a member that
    // splits its input would otherwise filter one half holding nothing, and the fold would
    // misjudge it (docs/ensemble-quality.md "Below 4 spp").
    in.whole = intact.whole;
    in.halves = *intact.halves;
    return in;
  }
  in.whole = merge({&single, &intact.whole});
  in.halves = std::array<SubBuffer, 2>{single, intact.whole};
  return in;
}

std::vector<DenoiseInput> heldOutInputs(const EnsembleSources& sources) {
  std::vector<DenoiseInput> inputs;
  for (int k = 0; k < kHeldOutQuarters; ++k) inputs.push_back(heldOutInput(sources, k));
  return inputs;
}

}  // namespace chorus
