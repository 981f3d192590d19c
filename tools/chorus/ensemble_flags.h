#pragma once
// The ensemble flags shared by `chorus denoise` and `chorus render --denoise`: solver, MSE
// form and window, relative objective, weight filter, seed.
#include <CLI/CLI.hpp>

#include <string>

#include "denoise/ensemble/combiners.h"

namespace chorus::cli {

struct EnsembleFlags {
  std::string solver = "active-set", weightFilter = "bilateral", mseForm = "summed";
  std::string estimate = estimateName(MseOptions{}.estimate);
  int window = MseOptions{}.windowRadius;
  double windowColor = MseOptions{}.windowSigmaColor;
  bool relative = MseOptions{}.relative;
  double outlierCap = MseOptions{}.outlierCap;
  double consistency = MseOptions{}.consistency;
  double plausibility = MseOptions{}.plausibility;
  double imagePrior = MseOptions{}.imagePrior;
  double noisyFallback = MseOptions{}.noisyFallback;
  double memberFallback = MseOptions{}.memberFallback;
  uint64_t seed = 1;

  bool weightFilterGiven = false;    // --weight-filter was on the command line
  bool imagePriorGiven = false;      // --image-prior was on the command line
  bool memberFallbackGiven = false;  // --member-fallback was on the command line
  bool windowGiven = false;          // --window was on the command line (no full-run radius)
  bool windowColorGiven = false;     // --window-color was on the command line

  void addFlags(CLI::App& cmd);
  // Throws chorus::Error for an unknown value.
  CombineOptions options() const;
};

}  // namespace chorus::cli
