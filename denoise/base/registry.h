#pragma once
// Maps denoiser names (as used by `--methods` / `--denoise`) to factories and one-line
// descriptions. A method spec is "name" or "name:key=value:key=value".
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "denoise/base/base_denoiser.h"
#include "denoise/base/param_map.h"

namespace chorus {

struct DenoiserEntry {
  std::string name;
  std::string description;  // one line for `chorus denoise --help` / `chorus methods`
  // Builds the denoiser; reads its parameters from the map (unread keys are errors).
  std::function<std::unique_ptr<BaseDenoiser>(ParamMap&)> create;
};

// Every built-in denoiser, in a fixed order.
const std::vector<DenoiserEntry>& builtinDenoisers();

// Builds a denoiser from a spec such as "nfor" or "jnlm:k=0.4", inside a GuardedDenoiser
// (guarded_denoiser.h); every spec also takes guard=S, the outlier guard's ceiling in standard
// deviations (outlier_guard.h, default 8; 0 = no guard). Throws chorus::Error for an unknown
// name (listing the known ones) or an unknown parameter.
std::unique_ptr<BaseDenoiser> createDenoiser(const std::string& spec);

// Splits "a,b:k=1,c" into specs; throws chorus::Error on an empty list or empty item.
std::vector<std::string> splitMethodList(const std::string& list);

}  // namespace chorus
