#include "denoise/base/registry.h"

#include <sstream>

#include "denoise/base/atrous/atrous.h"
#include "denoise/base/cross_bilateral/bilateral.h"
#include "denoise/base/cross_bilateral/sbf.h"
#include "denoise/base/guarded_denoiser.h"
#include "denoise/base/jnlm/joint_nlmeans.h"
#include "denoise/base/nfor/nfor.h"
#include "denoise/base/nlm/dual_buffer_nlm.h"
#include "denoise/base/rdfc/rdfc.h"

#include "common/error.h"

namespace chorus {

const std::vector<DenoiserEntry>& builtinDenoisers() {
  // Each denoiser's file provides its entry; add new ones here, in the order `--help` lists them.
  static const std::vector<DenoiserEntry> entries = {
      {"nfor",
       "NFOR: first-order regression on features with NL-means weights (Bitterli et al. 2016, as "
       "in Tungsten); needs halves",
       [](ParamMap& p) { return std::make_unique<NforDenoiser>(NforParams::fromParams(p)); }},
      {"nlm",
       "NL-means with dual-buffer variance, cross-filtered halves (Rousselle et al. 2012); needs "
       "halves",
       [](ParamMap& p) {
         return std::make_unique<DualBufferNlMeans>(DualBufferNlMeansParams::fromParams(p));
       }},
      {"sbf", "SURE-based selection among feature-guided cross-bilateral filters (Li et al. 2012)",
       [](ParamMap& p) { return std::make_unique<Sbf>(SbfParams::fromParams(p)); }},
      {"atrous",
       "edge-avoiding à-trous wavelet filter, SVGF weights (Dammertz et al. 2010): fast preview",
       [](ParamMap& p) { return std::make_unique<Atrous>(AtrousParams::fromParams(p)); }},
      {"bilateral",
       "joint cross-bilateral filter on normal, albedo, depth and colour (SBF's building block)",
       [](ParamMap& p) { return std::make_unique<Bilateral>(BilateralParams::fromParams(p)); }},
      {"rdfc",
       "SURE-selected NL-means candidates with feature prefiltering and a second pass "
       "(Rousselle et al. 2013)",
       [](ParamMap& p) { return std::make_unique<Rdfc>(RdfcParams::fromParams(p)); }},
      {"jnlm",
       "joint NL-means: colour patches with variance cancellation plus albedo/normal/depth range "
       "terms, cross-filtered halves when present",
       [](ParamMap& p) {
         return std::make_unique<JointNlMeans>(JointNlMeansParams::fromParams(p));
       }},
  };
  return entries;
}

std::unique_ptr<BaseDenoiser> createDenoiser(const std::string& spec) {
  const size_t colon = spec.find(':');
  const std::string name = spec.substr(0, colon);
  for (const DenoiserEntry& entry : builtinDenoisers()) {
    if (entry.name != name) continue;
    ParamMap params =
        colon == std::string::npos ? ParamMap() : ParamMap::parse(spec.substr(colon + 1), name);
    std::unique_ptr<BaseDenoiser> denoiser;
    try {
      OutlierGuardOptions guard;
      guard.ceilingSigmas = params.getFloat("guard", guard.ceilingSigmas);
      if (!(guard.ceilingSigmas >= 0.0f))
        throw Error("guard must be 0 (off) or a positive number of standard deviations");
      guard.spreadRadius = params.getInt("spread", guard.spreadRadius);
      if (guard.spreadRadius < 1 || guard.spreadRadius > kMaxGuardSpread)
        throw Error("spread must be a radius of 1 … " + std::to_string(kMaxGuardSpread) +
                    " pixels");
      guard.spreadPeak = params.getFloat("peak", guard.spreadPeak);
      if (!(guard.spreadPeak >= 0.0f))
        throw Error("peak must be 0 (the spread radius always) or a positive number");
      denoiser = std::make_unique<GuardedDenoiser>(entry.create(params), guard);
    } catch (const Error& e) {  // a bad value: say which denoiser it was for
      throw Error("denoiser " + name + ": " + e.what());
    }
    params.rejectUnread("denoiser " + name);
    return denoiser;
  }
  std::string known;
  for (const DenoiserEntry& entry : builtinDenoisers())
    known += (known.empty() ? "" : ", ") + entry.name;
  throw Error("unknown denoiser '" + name + "' (known: " + (known.empty() ? "none" : known) + ")");
}

std::vector<std::string> splitMethodList(const std::string& list) {
  std::vector<std::string> specs;
  std::stringstream stream(list);
  std::string item;
  while (std::getline(stream, item, ',')) {
    if (item.empty()) throw Error("empty method name in list '" + list + "'");
    specs.push_back(item);
  }
  if (specs.empty()) throw Error("empty method list");
  return specs;
}

}  // namespace chorus
