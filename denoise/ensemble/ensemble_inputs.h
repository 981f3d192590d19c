#pragma once

// The data the ensemble combines: the noisy half-buffer means and features ("guides") and, for
// every base denoiser, its outputs on half A, half B and the full buffer (what produces them:
// denoise/pipeline/). Issue 7's sweeps run
// every base denoiser once and then combine subsets of the same BaseOutputs, so the combination
// step takes pointers to them (nothing is copied per combination).
#include <array>
#include <span>
#include <string>
#include <vector>

#include "common/image/image.h"

namespace chorus {

// Noisy inputs and features of one render, all of the same size.
struct EnsembleGuides {
  Image color;           // full-buffer noisy colour (RGB): the fallback where no base is finite
  Image colorA, colorB;  // x^A, x^B: noisy half-buffer means (RGB)
  Image albedo, normal;  // full-buffer feature means (RGB / XYZ), guides of the weight filter
  // x_0 … x_3, the noisy quarter means (RGB; K = 4 sub-buffers, half A = quarters 0 and 1):
  // what the leave-one-quarter-out estimate compares the held-out runs with. Empty otherwise.
  std::vector<Image> quarters;

  int width() const { return color.width(); }
  int height() const { return color.height(); }
};

// One base denoiser's outputs: y^A (run on half A only), y^B (half B only) and y (full buffer),
// and, for the leave-one-quarter-out estimate, y^(−k): run on every quarter but k (k = 0 … 3;
// denoise/pipeline/held_out_inputs.h). heldOut is empty when that estimate is not used; a and b
// are empty when the held-out runs replace them (then every base has four held-out runs and
// none has half runs).
struct BaseOutputs {
  std::string name;
  Image a, b, full;
  std::vector<Image> heldOut;

  bool hasHalfRuns() const { return !a.empty() || !b.empty(); }
};

// Throws chorus::Error (one line naming the image) unless every guide and base output is RGB
// of the guides' size, and there are 1 … kMaxDenoisers bases with distinct names. Quarters and
// held-out runs are optional, but when given, four of each (the held-out runs of every base);
// half runs may be left out only when held-out runs are given, and by every base.
void checkEnsembleInputs(const EnsembleGuides& guides, std::span<const BaseOutputs* const> bases);

// The mean of a base's four held-out runs: with the quarters estimate this is the base's output
// that the ensemble blends instead of a run on the full buffer (it uses every sample; for a
// linear filter it equals the full run, and for the nonlinear members it was better on the
// corpus: docs/ensemble-quality.md). Requires four held-out runs.
Image meanOfHeldOutRuns(const BaseOutputs& base);

// Which quarters hold samples: one that is 0 everywhere has none (below 4 spp sample i goes to
// sub-buffer i mod 4). All false without quarters.
std::array<bool, 4> sampledQuarters(std::span<const Image> quarters);
// The folds a leave-one-quarter-out estimate compares: the quarters with samples while two or
// more have them, else all four.
std::vector<size_t> comparedFolds(std::span<const Image> quarters);

// Pointers to every element, for combine().
std::vector<const BaseOutputs*> pointersTo(const std::vector<BaseOutputs>& bases);

}  // namespace chorus
