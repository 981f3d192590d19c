#pragma once
// The denoising stage of `chorus render`: after the render, in the same process, the listed
// base denoisers run on half A, half B and the full buffer (in parallel), their outputs are
// blended by the ensemble (or another combiner), and the results are written next to
// render.exr.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "denoise/ensemble/combiners.h"
#include "denoise/pipeline/ensemble.h"
#include "tools/chorus/ensemble_flags.h"
#include "tools/chorus/kept_outputs.h"

namespace chorus::cli {

// The members `chorus render` uses when --denoise is not given (and `chorus denoise --methods
// default`), and with --preview (README, "Choosing the default members": the sweep evidence
// behind both).
inline constexpr const char* kDefaultDenoise = "nfor,rdfc,atrous";
// The previews' members spread an unconfirmed outlier's excess over a radius of 12 instead of 6
// (the guard's spread=R): at 4 samples per pixel a caustic's one bright sample is a poor guide to
// where its energy belongs, and a wider spread leaves a fainter blob (docs/ensemble-quality.md).
// The second member stops at depth edges 4× more loosely (sigmaZ=4): on a sloped surface SVGF's
// depth weight with sigmaZ=1 is e^-1 at every tap, which keeps that member close to the first;
// looser, it is the smoother partner the blend needs. The first stops at normals a little more
// loosely than à-trous's default (sigmaN=64 for 128): 0.2-1.7 % better at 1-16 spp on both
// halves (docs/ensemble-quality.md).
inline constexpr const char* kPreviewDenoise =
    "atrous:sigmaN=64:borrow=0.5:spread=12,"
    "atrous:iterations=4:sigmaL=8:sigmaN=16:sigmaZ=4:borrow=0.5:spread=12";

// The ensemble options previews change, each unless its flag was given (EnsembleFlags): no
// weight filter (it cost more than it gained at 4 spp), no image prior (the two à-trous members
// differ by detail, not by a ranking the whole image agrees on: cornell-box 512², 4 spp, relMSE
// 0.00505 without, 0.00511 with, and a pass over the image less), and the member fallback at
// K = 2 (where the blend's own error is 4× the best member's, that member: a permissive à-trous
// spreading a light onto a dark, well-measured pixel held 79 % of a 512² preview's error;
// docs/ensemble-quality.md), and a window on features only (the colour term lost on every
// tuning half of the previews: 128–160 px renders 0.969 → 0.972 of the better member, 256 and
// 512 px 0.832 → 0.832 and 0.750 → 0.751; docs/ensemble-quality.md). For `chorus render
// --preview` and bench_preview alike.
inline constexpr double kPreviewMemberFallback = 2.0;
inline void applyPreviewDefaults(CombineOptions& options, const EnsembleFlags& given = {}) {
  if (!given.weightFilterGiven) options.filter.enabled = false;
  if (!given.imagePriorGiven) options.mse.imagePrior = 0;
  if (!given.memberFallbackGiven) options.mse.memberFallback = kPreviewMemberFallback;
  if (!given.windowColorGiven) options.mse.windowSigmaColor = 0;
}

struct DenoiseStage {
  std::vector<std::string> specs;       // empty: render only (--denoise none)
  std::vector<EnsembleMember> members;  // built from specs once, by parse()
  CombineOptions options;
  bool writeExrs = true;  // false for previews: denoised.png only
  KeptOutputs keep;       // --keep: member outputs and weight maps

  // From a --denoise value ("none", "default", "preview" or a comma-separated list of method
  // specs). Throws chorus::Error for an unknown method or parameter.
  static DenoiseStage parse(const std::string& list, CombineOptions options, bool writeExrs);

  std::string label() const;  // "nfor,rdfc,..."
  bool enabled() const { return !specs.empty(); }
  // Sub-buffers the render needs: chorus::splitsNeeded of the members. Without denoising, what
  // the default members need, so that `chorus denoise render.exr` can run them later (render
  // now, denoise later); 1 for a preview, which writes no render.exr.
  int splitsNeeded() const;
  // The planes the render records: what the members and the combination read; without
  // denoising, what the default members read (for a later `chorus denoise`); colour only for a
  // preview without denoising.
  BufferPlanes planesNeeded() const;

  // The files run() writes, and those it leaves out for want of --keep (or, in a preview, of
  // a full run).
  std::vector<std::string> files() const;
  std::vector<LeftOut> leftOut() const;

  // Runs the members and the combiner on `sources` (sourcesFromBuffers of the render),
  // writes files() to `dir` (denoised.png and, unless a preview, denoised.exr; weights.exr and
  // <member>.exr with --keep), and adds every stage's seconds to stats["seconds"] and, with a
  // reference, the metrics of the noisy input, each member and the result to stats["metrics"].
  // Returns the seconds of the members and the combiner (without writing). Each member run's end
  // goes to `progress`.
  double run(const EnsembleSources& sources, const std::filesystem::path& dir,
             nlohmann::ordered_json& stats, const Image* reference,
             const RunsProgressCallback& progress = {}) const;
};

}  // namespace chorus::cli
