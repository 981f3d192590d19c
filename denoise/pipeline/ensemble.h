#pragma once
// The ensemble runner: runs the chosen base denoisers on the full buffer and on half A and
// half B, or for the leave-one-quarter-out estimate on the four held-out inputs instead (all
// 3N or 4N runs in parallel as TBB tasks), then combines their outputs (combiners.h) and reports
// the time of every stage. For sweeps that reuse base outputs across combinations, call
// runBaseDenoisers() once and combine() per combination instead. runMembersAlone() runs members
// on one input only, without the ensemble (`chorus denoise --combine none`).
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "denoise/base/base_denoiser.h"
#include "denoise/buffers/sample_buffers.h"
#include "denoise/ensemble/combiners.h"
#include "denoise/pipeline/ensemble_sources.h"

namespace chorus {

// A base denoiser and the label its outputs carry (layer and file names; must be unique).
struct EnsembleMember {
  std::string label;
  std::shared_ptr<const BaseDenoiser> denoiser;
};

// One member per registry spec ("nfor", "jnlm:k=0.4"), labelled with the spec. Throws
// chorus::Error for an unknown name or parameter (denoise/base/registry.h) or a spec listed twice.
std::vector<EnsembleMember> membersFromSpecs(std::span<const std::string> specs);

// Progress of the member runs, for a command's progress display: called with done = 0 before
// any run starts, then once as each run ends (from the thread that ran it, one call at a time):
// `done` of `total` runs finished, the last one named as in the stage times ("nfor/without-q0").
struct RunsProgress {
  size_t done = 0, total = 0;
  std::string finished;
  double seconds = 0;  // of that run
};
using RunsProgressCallback = std::function<void(const RunsProgress&)>;

// Throws chorus::Error (one line) when a member cannot run on these sources, e.g. a denoiser
// that needs two halves of its own input while the half buffers have none (K = 2 renders and
// Tungsten directories: only the full buffer has halves). The full buffer's halves, when the
// sources do not hold them, are built for the run on it (runBaseDenoisers).
void checkMembersCanRun(const EnsembleSources& sources, std::span<const EnsembleMember> members);

// Sub-buffers a render needs for these members: 4 when one needs two halves of its own input (it
// then runs on quarters inside each half: NFOR, RDFC, dual-buffer NL-means), else 2 (the
// ensemble's halves A and B). Fewer sub-buffers mean less film to fill and merge.
int splitsNeeded(std::span<const EnsembleMember> members);

// Whether some member needs or reads the halves of its input (else sourcesFromBuffers can leave
// the full input's halves out: two copies of the render less).
bool readsHalves(std::span<const EnsembleMember> members);

// Throws chorus::Error (one line) when a member cannot run on `input` alone: one that needs two
// independent halves of its input while `input` has none (a K = 1 render).
void checkMembersCanRunAlone(const DenoiseInput& input, std::span<const EnsembleMember> members);

// Every member on `input` only (no runs on halves, no combination), in parallel; the outputs in
// member order, as the members return them (a render's emission is not in `input`: add it,
// SampleBuffers::emission). Appends "<label>/full" (the time of each run) and "members" (wall
// time of all of them) to `times`.
std::vector<Image> runMembersAlone(const DenoiseInput& input,
                                   std::span<const EnsembleMember> members,
                                   std::vector<StageTime>* times = nullptr,
                                   const RunsProgressCallback& progress = {});

// Which runs of every member the ensemble needs.
struct BaseRuns {
  bool full = true;      // on the full buffer; else `full` is the mean of the held-out runs
  bool halves = true;    // on half A and half B
  bool heldOut = false;  // on the four inputs without one quarter (held_out_inputs.h)
};
// The runs an estimate needs on these sources: the quarters (and the extrapolated) estimate
// use the held-out runs when the sources carry four independent quarters (K = 4). The quarters
// estimate then needs no half runs (the estimate and the weight filter's guide read only the
// held-out runs), and the full run only where blendsFullRuns says so; elsewhere the ensemble
// blends the mean of the held-out runs (meanOfHeldOutRuns). The extrapolated estimate also
// needs the halves and keeps the full run. Otherwise the full and the half runs.
BaseRuns baseRunsFor(const MseOptions& options, const EnsembleSources& sources);

// Whether the quarters estimate's blend takes each member's run on the full buffer (a fifth run)
// instead of the mean of its four held-out runs: on images of at least kFullRunPixels pixels at
// up to kFullRunSpp samples per pixel. There a held-out run sees three samples of four, split
// 2 + 1 by the members that halve their input, and its mean stays well behind the full run; at
// 128-160 px, and at 64 spp and more, the mean (an average of four runs) wins. Chosen on the
// tuning halves of the corpora at 128-160, 256 and 512 px (docs/ensemble-quality.md).
inline constexpr long kFullRunPixels = 32768;  // 2^15, e.g. 256 x 128
inline constexpr double kFullRunSpp = 16;
bool blendsFullRuns(int width, int height, double samplesPerPixel);
// `options` for a blend of these runs: the MSE window of radius mse.fullRunWindowRadius (15 by
// default, a sparse window over box means: mse_estimate.cpp) on images of at least
// kWideWindowPixels pixels, and on smaller ones where the weights, estimated from the held-out
// runs, blend the full runs (blendsFullRuns) and some member needs two halves of its own input
// (NFOR, RDFC). Such a member's full run is much better than its held-out runs (three samples
// of four, split 2 + 1), so the local differences the held-out runs show carry over less than
// their image-wide ranking; the wider window was 5 % better on both halves of the 256- and
// 512-px corpora there. From 512 x 341 pixels on it also blends the held-out means better (64
// spp: 2.8 % on tuning, 0.6 % on validation; at 256 px 1 % worse, so not there), and the
// previews' two à-trous members (512 px, 4 spp: 1.8 % / 1.2 %; 256 px: 0.99 / 1.03). Members
// that filter their whole input (the synthetic entries' box, Gaussian and median filters, at
// 128–256 px) lost with it at few samples: there the radius stays. Else unchanged
// (docs/ensemble-quality.md).
inline constexpr long kWideWindowPixels = 131072;  // 2^17, e.g. 512 x 256
CombineOptions optionsForRuns(CombineOptions options, const BaseRuns& runs,
                              std::span<const EnsembleMember> members, int width, int height);
// Every member on the runs that `runs` asks for, in parallel, each output with the sources'
// emission added back. Appends "<label>/A", "<label>/B", "<label>/full", "<label>/without-q<k>"
// (the time of each run) and "bases" (wall time of all of them) to `times`; reports each run's
// end to `progress`.
std::vector<BaseOutputs> runBaseDenoisers(const EnsembleSources& sources,
                                          std::span<const EnsembleMember> members,
                                          std::vector<StageTime>* times = nullptr,
                                          BaseRuns runs = {},
                                          const RunsProgressCallback& progress = {});

struct EnsembleResult {
  CombineResult combined;          // image, weights, A/B blends, estimated MSE
  std::vector<BaseOutputs> bases;  // every base output (full, A/B or held out), in member order
  EnsembleGuides guides;           // the noisy inputs the weights were estimated from
  std::vector<StageTime> times;    // every stage: base runs, "bases", "solve", "filter", "blend"
  CombineOptions options;          // what the blend was combined with (optionsForRuns)
};

class Ensemble {
 public:
  Ensemble(std::vector<EnsembleMember> members, CombineOptions options);

  const std::vector<EnsembleMember>& members() const { return members_; }
  const CombineOptions& options() const { return options_; }

  // From K = 2 or 4 sub-buffers (input(HalfA), input(HalfB), input(Full)).
  EnsembleResult run(const SampleBuffers& buffers, const Image* reference = nullptr) const;
  EnsembleResult run(const EnsembleSources& sources, const Image* reference = nullptr,
                     const RunsProgressCallback& progress = {}) const;

 private:
  std::vector<EnsembleMember> members_;
  CombineOptions options_;
};

}  // namespace chorus
