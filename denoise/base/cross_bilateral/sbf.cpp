#include "denoise/base/cross_bilateral/sbf.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "common/error.h"
#include "denoise/base/cross_bilateral/cross_bilateral.h"
#include "denoise/base/filters/sure.h"
#include "denoise/base/input_planes.h"
#include "denoise/base/selection_knee.h"
#include "denoise/base/variance_calibration.h"

namespace chorus {

namespace {

std::vector<float> parseSigmaList(const std::string& text) {
  std::vector<float> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, '/')) {
    size_t used = 0;
    float value = 0;
    try {
      value = std::stof(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !(value >= 0) || value > 64)
      throw Error("sbf: sigmaS=" + text + " must be a '/'-separated list of widths in [0, 64]");
    values.push_back(value);
  }
  if (values.empty()) throw Error("sbf: sigmaS is empty");
  return values;
}

std::string joinSigmaList(const std::vector<float>& values) {
  std::ostringstream out;
  for (size_t i = 0; i < values.size(); ++i) out << (i ? "/" : "") << values[i];
  return out.str();
}

void requirePositive(float value, const char* name) {
  if (!(value >= 0) || !std::isfinite(value))
    throw Error(std::string("sbf: ") + name + " must be a finite number ≥ 0");
}

}  // namespace

SbfParams SbfParams::fromParams(ParamMap& params) {
  SbfParams p;
  p.sigmaS = parseSigmaList(params.getString("sigmaS", joinSigmaList(p.sigmaS)));
  p.sigmaN = params.getFloat("sigmaN", p.sigmaN);
  p.sigmaR = params.getFloat("sigmaR", p.sigmaR);
  p.sigmaD = params.getFloat("sigmaD", p.sigmaD);
  p.sigmaMse = params.getFloat("sigmaMse", p.sigmaMse);
  p.selectionKnee = params.getFloat("selectionKnee", p.selectionKnee);
  requirePositive(p.selectionKnee, "selectionKnee");
  requirePositive(p.sigmaN, "sigmaN");
  requirePositive(p.sigmaR, "sigmaR");
  requirePositive(p.sigmaD, "sigmaD");
  if (!(p.sigmaMse >= 0)) throw Error("sbf: sigmaMse must be 0 (from the samples) or positive");
  if (p.sigmaMse > 64) throw Error("sbf: sigmaMse must be ≤ 64");
  p.calibrationRadius = params.getInt("calibrate", p.calibrationRadius);
  if (p.calibrationRadius < 0 || p.calibrationRadius > kMaxCalibrationRadius)
    throw Error("sbf: calibrate must be in [0, " + std::to_string(kMaxCalibrationRadius) + "]");
  p.calibrateFrom = params.getFloat("calibrateFrom", p.calibrateFrom);
  requirePositive(p.calibrateFrom, "calibrateFrom");
  return p;
}

float sureSmoothingWidth(double spp) {
  if (!(spp > 0)) return 8.0f;
  return float(std::clamp(16.0 / std::sqrt(spp), 2.0, 8.0));
}

SbfResult runSbf(const SubBuffer& buffer, const SbfParams& params, const Image* sureVariance) {
  const int w = buffer.width(), h = buffer.height();
  const size_t pixels = size_t(w) * size_t(h);
  const int candidateCount = int(params.sigmaS.size());
  const PlanarImage color = sanitizedMean(buffer.color);
  const PlanarImage variance =
      sanitizedVarianceOfMean(sureVariance ? *sureVariance : buffer.color.varianceOfMean);
  const FeatureGuide guide =
      makeFeatureGuide(buffer, {params.sigmaN, params.sigmaR, params.sigmaD});

  // 1. Candidates.
  const std::vector<BilateralCandidate> candidates =
      crossBilateralCandidates(color, variance, guide, params.sigmaS, 0.0f);

  // 2. SURE per candidate and pixel, averaged over RGB (§5: the −σ² term does not change the
  // argmin; it is kept so that the maps are MSE estimates).
  PlanarImage sure(w, h, candidateCount);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, pixels), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i)
          for (int s = 0; s < candidateCount; ++s) {
            const BilateralCandidate& cand = candidates[size_t(s)];
            float sum = 0;
            for (int c = 0; c < 3; ++c)
              sum += sureTerm(cand.filtered.plane(c)[i], color.plane(c)[i], variance.plane(c)[i],
                              cand.derivative.plane(c)[i]);
            sure.plane(s)[i] = std::isfinite(sum) ? sum / 3.0f : std::numeric_limits<float>::max();
          }
      });

  // 3. Smooth the SURE maps (the raw per-pixel estimates are far too noisy to select with),
  // a bright pixel's in relative units (selection_knee.h: the features cannot tell a highlight
  // seen in a mirror from the surface around it); its level: the first candidate's output.
  std::vector<float*> maps;
  for (int s = 0; s < candidateCount; ++s) maps.push_back(sure.plane(s));
  const BilateralCandidate& first = candidates[0];
  kneeBrightErrors(
      maps, pixels,
      [&](size_t i) {
        double level = 0;
        for (int c = 0; c < 3; ++c) level += first.filtered.plane(c)[i];
        return level / 3.0;
      },
      kneeLevel({color.plane(0), size_t(3) * pixels}, params.selectionKnee));
  const float sigmaMse =
      (params.sigmaMse > 0 ? params.sigmaMse : sureSmoothingWidth(meanSampleCount(buffer))) *
      (sureVariance ? kCalibratedSureSmoothing : 1.0f);
  const PlanarImage smoothed = crossBilateralSmooth(sure, guide, sigmaMse);

  // 4. Hard per-pixel selection; ties go to the first candidate in sigmaS order.
  SbfResult result{Image(w, h, 3), Image(w, h, 1)};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i < r.end(); ++i) {
                        int best = 0;
                        for (int s = 1; s < candidateCount; ++s)
                          if (smoothed.plane(s)[i] < smoothed.plane(best)[i]) best = s;
                        result.selection.data()[i] = float(best);
                        for (int c = 0; c < 3; ++c) {
                          const float v = candidates[size_t(best)].filtered.plane(c)[i];
                          result.output.data()[i * 3 + size_t(c)] = std::isfinite(v) ? v : 0.0f;
                        }
                      }
                    });
  return result;
}

Image Sbf::run(const DenoiseInput& input) const {
  const bool calibrate =
      params_.calibrationRadius > 0 &&
      renderSamplesPerPixel(input.whole, input.sampleShare) >= params_.calibrateFrom;
  const Image variance =
      calibrate ? calibratedWholeColorVariance(input, params_.calibrationRadius, 1.0f) : Image();
  return runSbf(input.whole, params_, variance.empty() ? nullptr : &variance).output;
}

}  // namespace chorus
