#include "denoise/base/cross_bilateral/bilateral.h"

#include <cmath>

#include "common/error.h"
#include "denoise/base/cross_bilateral/cross_bilateral.h"
#include "denoise/base/input_planes.h"

namespace chorus {

BilateralParams BilateralParams::fromParams(ParamMap& params) {
  BilateralParams p;
  p.sigmaS = params.getFloat("sigmaS", p.sigmaS);
  p.sigmaC = params.getFloat("sigmaC", p.sigmaC);
  p.sigmaN = params.getFloat("sigmaN", p.sigmaN);
  p.sigmaR = params.getFloat("sigmaR", p.sigmaR);
  p.sigmaD = params.getFloat("sigmaD", p.sigmaD);
  for (const auto& [name, value] : {std::pair{"sigmaC", p.sigmaC}, std::pair{"sigmaN", p.sigmaN},
                                    std::pair{"sigmaR", p.sigmaR}, std::pair{"sigmaD", p.sigmaD}})
    if (!(value >= 0) || !std::isfinite(value))
      throw Error(std::string("bilateral: ") + name + " must be a finite number ≥ 0");
  if (!(p.sigmaS >= 0 && p.sigmaS <= 64)) throw Error("bilateral: sigmaS must be in [0, 64]");
  return p;
}

Image Bilateral::run(const DenoiseInput& input) const {
  const SubBuffer& buffer = input.whole;
  const float sigmaS[] = {params_.sigmaS};
  const std::vector<BilateralCandidate> filtered = crossBilateralCandidates(
      sanitizedMean(buffer.color), sanitizedVarianceOfMean(buffer.color.varianceOfMean),
      makeFeatureGuide(buffer, {params_.sigmaN, params_.sigmaR, params_.sigmaD}), sigmaS,
      params_.sigmaC);
  Image out = filtered[0].filtered.toImage();
  for (float& v : out.values()) v = std::isfinite(v) ? v : 0.0f;
  return out;
}

}  // namespace chorus
