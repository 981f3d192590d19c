#include "denoise/ensemble/ensemble_inputs.h"

#include <algorithm>
#include <set>

#include "common/error.h"
#include "denoise/ensemble/ensemble_types.h"

namespace chorus {
namespace {

std::string shapeText(const Image& image) {
  return std::to_string(image.width()) + "x" + std::to_string(image.height()) + "x" +
         std::to_string(image.channels());
}

void checkImage(const Image& image, const std::string& what, const Image& like) {
  if (image.width() != like.width() || image.height() != like.height() || image.channels() != 3)
    throw Error(what + " is " + shapeText(image) + ", expected " + std::to_string(like.width()) +
                "x" + std::to_string(like.height()) + "x3");
}

}  // namespace

void checkEnsembleInputs(const EnsembleGuides& guides, std::span<const BaseOutputs* const> bases) {
  const Image& like = guides.color;
  if (like.empty()) throw Error("the noisy colour image is empty");
  checkImage(like, "the noisy colour", like);
  checkImage(guides.colorA, "the noisy colour of half A", like);
  checkImage(guides.colorB, "the noisy colour of half B", like);
  checkImage(guides.albedo, "the albedo", like);
  checkImage(guides.normal, "the normal", like);
  if (!guides.quarters.empty() && guides.quarters.size() != 4)
    throw Error("expected 4 noisy quarters, got " + std::to_string(guides.quarters.size()));
  for (size_t k = 0; k < guides.quarters.size(); ++k)
    checkImage(guides.quarters[k], "the noisy colour of quarter " + std::to_string(k), like);
  if (bases.empty()) throw Error("no base denoiser outputs to combine");
  if (bases.size() > size_t(kMaxDenoisers))
    throw Error("at most " + std::to_string(kMaxDenoisers) +
                " base denoisers can be combined, got " + std::to_string(bases.size()));
  std::set<std::string> names;
  for (const BaseOutputs* base : bases) {
    if (!names.insert(base->name).second)
      throw Error("base denoiser '" + base->name + "' is listed twice");
    if (base->hasHalfRuns() != bases[0]->hasHalfRuns())
      throw Error("base denoiser '" + base->name + "' " + (base->hasHalfRuns() ? "has" : "lacks") +
                  " half runs, '" + bases[0]->name + "' " +
                  (base->hasHalfRuns() ? "lacks them" : "has them"));
    if (base->hasHalfRuns() || base->heldOut.empty()) {
      checkImage(base->a, "the output of " + base->name + " on half A", like);
      checkImage(base->b, "the output of " + base->name + " on half B", like);
    }
    checkImage(base->full, "the output of " + base->name + " on the full buffer", like);
    if (base->heldOut.size() != bases[0]->heldOut.size() ||
        (!base->heldOut.empty() && base->heldOut.size() != 4))
      throw Error("base denoiser '" + base->name + "' has " + std::to_string(base->heldOut.size()) +
                  " held-out runs (every base needs 0 or 4, and the same)");
    if (!base->heldOut.empty() && guides.quarters.empty())
      throw Error("held-out runs of '" + base->name + "' without the noisy quarters");
    for (size_t k = 0; k < base->heldOut.size(); ++k)
      checkImage(base->heldOut[k],
                 "the output of " + base->name + " without quarter " + std::to_string(k), like);
  }
}

Image meanOfHeldOutRuns(const BaseOutputs& base) {
  if (base.heldOut.size() != 4)
    throw Error("base denoiser '" + base.name + "' has no four held-out runs to average");
  Image mean = base.heldOut[0];
  for (size_t k = 1; k < 4; ++k)
    if (!base.heldOut[k].sameShape(mean))
      throw Error("the held-out runs of '" + base.name + "' differ in shape");
  // In double: four values near FLT_MAX have a finite mean but not a finite float sum.
  for (size_t e = 0; e < mean.size(); ++e) {
    double sum = 0;
    for (const Image& run : base.heldOut) sum += run.data()[e];
    mean.data()[e] = float(0.25 * sum);
  }
  return mean;
}

std::array<bool, 4> sampledQuarters(std::span<const Image> quarters) {
  std::array<bool, 4> sampled{};
  for (size_t k = 0; k < quarters.size() && k < 4; ++k) {
    const std::span<const float> q = quarters[k].values();
    sampled[k] = !std::all_of(q.begin(), q.end(), [](float v) { return v == 0.0f; });
  }
  return sampled;
}

std::vector<size_t> comparedFolds(std::span<const Image> quarters) {
  const std::array<bool, 4> sampled = sampledQuarters(quarters);
  std::vector<size_t> folds;
  for (size_t k = 0; k < 4; ++k)
    if (sampled[k]) folds.push_back(k);
  if (folds.size() < 2) folds = {0, 1, 2, 3};
  return folds;
}

std::vector<const BaseOutputs*> pointersTo(const std::vector<BaseOutputs>& bases) {
  std::vector<const BaseOutputs*> pointers;
  for (const BaseOutputs& base : bases) pointers.push_back(&base);
  return pointers;
}

}  // namespace chorus
