#include "denoise/ensemble/blend.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <vector>

#include "common/error.h"
#include "denoise/ensemble/ensemble_inputs.h"

namespace chorus {

Image blend(std::span<const Image> weights, std::span<const Image* const> outputs,
            const Image& fallback) {
  if (weights.size() != outputs.size() || weights.empty())
    throw Error("blend: need one weight map per output");
  const int w = fallback.width(), h = fallback.height();
  const int weightChannels = weights[0].channels();
  for (size_t i = 0; i < weights.size(); ++i) {
    if (weights[i].width() != w || weights[i].height() != h ||
        weights[i].channels() != weightChannels || (weightChannels != 1 && weightChannels != 3))
      throw Error("blend: weight maps must be 1- or 3-channel images of the output size");
    if (outputs[i]->width() != w || outputs[i]->height() != h || outputs[i]->channels() != 3)
      throw Error("blend: outputs must be RGB images of the fallback's size");
  }
  if (fallback.channels() != 3) throw Error("blend: the fallback must be RGB");

  Image out(w, h, 3);
  const size_t pixels = size_t(w) * size_t(h);
  tbb::parallel_for(size_t(0), pixels, [&](size_t p) {
    for (int c = 0; c < 3; ++c) {
      const size_t weightIndex = p * size_t(weightChannels) + size_t(weightChannels == 3 ? c : 0);
      const size_t e = p * 3 + size_t(c);
      double sum = 0.0;
      for (size_t i = 0; i < weights.size(); ++i) {
        const double weight = weights[i].data()[weightIndex];
        if (weight != 0.0) sum += weight * outputs[i]->data()[e];
      }
      if (!std::isfinite(float(sum))) {
        const float noisy = fallback.data()[e];
        sum = std::isfinite(noisy) ? noisy : 0.0f;
      }
      out.data()[e] = float(sum);
    }
  });
  return out;
}

Image estimatedBlendMse(const Image& blendA, const Image& blendB, const Image& colorA,
                        const Image& colorB) {
  if (!blendA.sameShape(blendB) || !blendA.sameShape(colorA) || !blendA.sameShape(colorB))
    throw Error("estimatedBlendMse: images differ in shape");
  Image out(blendA.width(), blendA.height(), blendA.channels());
  for (size_t e = 0; e < out.size(); ++e) {
    const double zA = blendA.data()[e], zB = blendB.data()[e];
    const double xA = colorA.data()[e], xB = colorB.data()[e];
    const double value =
        0.5 * ((zA - xB) * (zA - xB) + (zB - xA) * (zB - xA) - (xA - xB) * (xA - xB));
    out.data()[e] = std::isfinite(float(value)) ? float(value) : 0.0f;
  }
  return out;
}

Image heldOutBlendMse(std::span<const Image> heldOutBlends, std::span<const Image> quarters) {
  if (heldOutBlends.size() != 4 || quarters.size() != 4)
    throw Error("heldOutBlendMse: expected four held-out blends and four quarters");
  const Image& like = quarters[0];
  for (size_t k = 0; k < 4; ++k)
    if (!heldOutBlends[k].sameShape(like) || !quarters[k].sameShape(like))
      throw Error("heldOutBlendMse: images differ in shape");
  // The folds the weights' estimate compares (an empty quarter says nothing about the error).
  const std::vector<size_t> folds = comparedFolds(quarters);
  const double n = double(folds.size());
  Image out(like.width(), like.height(), like.channels());
  for (size_t e = 0; e < out.size(); ++e) {
    double mean = 0, error = 0, spread = 0;
    for (size_t k : folds) mean += quarters[k].data()[e] / n;
    for (size_t k : folds) {
      const double x = quarters[k].data()[e], d = heldOutBlends[k].data()[e] - x;
      error += d * d / n;
      spread += (x - mean) * (x - mean) / (n - 1);
    }
    const double value = error - spread;
    out.data()[e] = std::isfinite(float(value)) ? float(value) : 0.0f;
  }
  return out;
}

}  // namespace chorus
