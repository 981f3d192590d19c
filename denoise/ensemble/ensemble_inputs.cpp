#include "denoise/ensemble/ensemble_inputs.h"

#include <set>

#include "denoise/ensemble/ensemble_types.h"
#include "denoise/util/error.h"

namespace chorus {
namespace {

std::string sizeText(const Image& image) {
  return std::to_string(image.width()) + "x" + std::to_string(image.height()) + "x" +
         std::to_string(image.channels());
}

void checkImage(const Image& image, const std::string& what, const Image& like) {
  if (image.width() != like.width() || image.height() != like.height() || image.channels() != 3)
    throw Error(what + " is " + sizeText(image) + ", expected " + std::to_string(like.width()) +
                "x" + std::to_string(like.height()) + "x3");
}

void checkSplitCount(int k) {
  if (k < 2 || k % 2 != 0)
    throw Error("the ensemble needs an even number of independent sub-buffers (2 or 4), got " +
                std::to_string(k));
}

}  // namespace

EnsembleSources sourcesFromBuffers(const SampleBuffers& buffers) {
  checkSplitCount(buffers.splitCount());
  EnsembleSources sources{buffers.input(BufferPart::HalfA), buffers.input(BufferPart::HalfB), {}};
  // The full buffer's halves are the half inputs' wholes: copied rather than merged again.
  sources.full.whole = buffers.part(BufferPart::Full);
  sources.full.halves = std::array<SubBuffer, 2>{sources.a.whole, sources.b.whole};
  return sources;
}

EnsembleSources sourcesFromBuffers(SampleBuffers&& buffers, bool halvesOfFull) {
  const int k = buffers.splitCount();
  checkSplitCount(k);
  EnsembleSources sources;
  sources.full.whole = buffers.part(BufferPart::Full);
  if (k == 2) {  // the halves are the two sub-buffers themselves: moved, not copied
    sources.a.whole = std::move(buffers.sub(0));
    sources.b.whole = std::move(buffers.sub(1));
  } else {
    sources.a = buffers.input(BufferPart::HalfA);
    sources.b = buffers.input(BufferPart::HalfB);
  }
  if (halvesOfFull)
    sources.full.halves = std::array<SubBuffer, 2>{sources.a.whole, sources.b.whole};
  buffers = {};
  return sources;
}

EnsembleSources sourcesFromHalves(const DenoiseInput& input) {
  if (!input.halves) throw Error("the ensemble needs two independent halves of the input");
  EnsembleSources sources;
  sources.a.whole = (*input.halves)[0];
  sources.b.whole = (*input.halves)[1];
  sources.full = input;
  return sources;
}

EnsembleGuides guidesFromSources(const EnsembleSources& sources) {
  EnsembleGuides guides;
  guides.color = sources.full.whole.color.mean;
  guides.colorA = sources.a.whole.color.mean;
  guides.colorB = sources.b.whole.color.mean;
  guides.albedo = sources.full.whole.albedo.mean;
  guides.normal = sources.full.whole.normal.mean;
  return guides;
}

void checkEnsembleInputs(const EnsembleGuides& guides, std::span<const BaseOutputs* const> bases) {
  const Image& like = guides.color;
  if (like.empty()) throw Error("the noisy colour image is empty");
  checkImage(like, "the noisy colour", like);
  checkImage(guides.colorA, "the noisy colour of half A", like);
  checkImage(guides.colorB, "the noisy colour of half B", like);
  checkImage(guides.albedo, "the albedo", like);
  checkImage(guides.normal, "the normal", like);
  if (bases.empty()) throw Error("no base denoiser outputs to combine");
  if (bases.size() > size_t(kMaxDenoisers))
    throw Error("at most " + std::to_string(kMaxDenoisers) +
                " base denoisers can be combined, got " + std::to_string(bases.size()));
  std::set<std::string> names;
  for (const BaseOutputs* base : bases) {
    if (!names.insert(base->name).second)
      throw Error("base denoiser '" + base->name + "' is listed twice");
    checkImage(base->a, "the output of " + base->name + " on half A", like);
    checkImage(base->b, "the output of " + base->name + " on half B", like);
    checkImage(base->full, "the output of " + base->name + " on the full buffer", like);
  }
}

std::vector<const BaseOutputs*> pointersTo(const std::vector<BaseOutputs>& bases) {
  std::vector<const BaseOutputs*> pointers;
  for (const BaseOutputs& base : bases) pointers.push_back(&base);
  return pointers;
}

}  // namespace chorus
