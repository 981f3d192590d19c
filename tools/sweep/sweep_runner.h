#pragma once
// Runs a sweep (issue 7): for every case (scene × spp) of this shard that is not already in the
// output directory, render once with K = 4, run every base denoiser once, and evaluate the noisy
// input, each base denoiser alone, and every combination × combiner against a reference; write
// the case's rows and crops atomically under DIR/cases/, then the summary (results.csv,
// report.html). Library code, so tests run sweeps without the CLI.
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "denoise/ensemble/combiners.h"
#include "renderer/render.h"
#include "renderer/scene/environment.h"
#include "tools/sweep/report_html.h"
#include "tools/sweep/sweep_plan.h"

namespace chorus::sweep {

// Samples per pixel of a rendered reference unless the sweep is given another count or a time.
inline constexpr int kDefaultReferenceSpp = 16384;
// Sub-buffers every case renders (the held-out quarters every member can run on).
inline constexpr int kCaseSplits = 4;

struct SweepConfig {
  std::vector<std::filesystem::path> scenes;
  std::vector<int> spps = {4, 8, 16, 32, 64, 128, 256};
  std::vector<std::string> methods;  // base denoiser specs ("nfor", "jnlm:k=0.4")
  std::string combos = "all";        // planCombinations spec
  std::vector<std::string> combiners = {"ensemble", "onehot-pre", "onehot-post", "average",
                                        "oracle"};
  // Reference images, one per scene in scene order (empty: render them into DIR/references/).
  std::vector<std::filesystem::path> references;
  int referenceSpp = kDefaultReferenceSpp;
  double referenceSeconds = 0;  // > 0: a time budget instead of referenceSpp (see runSweep)
  std::filesystem::path out;
  Shard shard;
  // Width, height, seed, threads, depth and camera of every render (spp and splits are set per
  // render). References use their own seed (reference_render.h), so that their error is
  // independent of the noisy renders'.
  render::RenderOptions render;
  render::EnvironmentDesc environment;
  // Loads and builds a scene; the default is loadGltf + buildScene(environment). The CLI passes
  // its own (warnings on stderr).
  std::function<render::Scene(const std::filesystem::path&)> loadScene;
  CombineOptions combine;  // solver, MSE form, weight filter (the combiner is set per row)
  int cropSize = 96;
  std::ostream* progress = nullptr;  // progress lines with ETA; nullptr: silent
  ReportInfo report;
};

// What a run did (for the CLI's summary line and for tests of resume and caching).
struct SweepRunStats {
  int casesPlanned = 0;  // cases of this shard
  int casesRun = 0;      // rendered and evaluated now
  int casesSkipped = 0;  // already complete in DIR
  int referencesRendered = 0;
  std::vector<std::string> ranCases;  // file stems of the cases run now, in order
};

// Throws chorus::Error for bad configuration (unknown method or combiner, a reference count
// that does not match the scenes, a reference of the wrong size naming the file, …) before
// rendering anything it can check up front.
SweepRunStats runSweep(const SweepConfig& config);

// The spp the reference of a scene is rendered with, from the spp budget or a time budget:
// with `seconds` > 0, a probe render of `probeSpp` samples took `probeSeconds`, and the
// reference gets the spp that fills the budget at that rate (at least probeSpp).
int referenceSppFor(int spp, double seconds, int probeSpp, double probeSeconds);

}  // namespace chorus::sweep
