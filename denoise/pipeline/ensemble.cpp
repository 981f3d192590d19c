#include "denoise/pipeline/ensemble.h"

#include <tbb/task_group.h>

#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <string>

#include "common/error.h"
#include "common/stopwatch.h"
#include "denoise/base/registry.h"
#include "denoise/ensemble/ensemble_types.h"
#include "denoise/pipeline/held_out_inputs.h"
#include "denoise/pipeline/member_runner.h"

namespace chorus {
namespace {

void rejectRepeatedLabels(std::span<const EnsembleMember> members) {
  std::set<std::string> labels;
  for (const EnsembleMember& member : members)
    if (!labels.insert(member.label).second)
      throw Error("base denoiser '" + member.label + "' is listed twice");
}

}  // namespace

std::vector<EnsembleMember> membersFromSpecs(std::span<const std::string> specs) {
  std::vector<EnsembleMember> members;
  for (const std::string& spec : specs)
    members.push_back({spec, std::shared_ptr<const BaseDenoiser>(createDenoiser(spec))});
  rejectRepeatedLabels(members);  // before any input is read or rendered
  return members;
}

namespace {

// Members with distinct labels (their outputs' file and layer names), at least one.
void checkLabels(std::span<const EnsembleMember> members) {
  if (members.empty()) throw Error("no base denoisers given");
  rejectRepeatedLabels(members);
}

bool needsHalves(const EnsembleMember& member) {
  return member.denoiser->requirements().halves;
}

}  // namespace

void checkMembersCanRun(const EnsembleSources& sources, std::span<const EnsembleMember> members) {
  checkLabels(members);
  if (members.size() > size_t(kMaxDenoisers))
    throw Error("at most " + std::to_string(kMaxDenoisers) + " base denoisers, got " +
                std::to_string(members.size()));
  for (const EnsembleMember& member : members) {
    if (!needsHalves(member)) continue;
    const char* missing = !sources.a.halves ? "half A" : !sources.b.halves ? "half B" : nullptr;
    if (missing)
      throw Error("base denoiser '" + member.label +
                  "' needs two independent halves of its own input, but " + missing +
                  " has none (the ensemble runs it on half A and half B, which needs 4 "
                  "independent sub-buffers; this input has only 2)");
  }
}

void checkMembersCanRunAlone(const DenoiseInput& input, std::span<const EnsembleMember> members) {
  checkLabels(members);
  for (const EnsembleMember& member : members)
    if (needsHalves(member) && !input.halves)
      throw Error("base denoiser '" + member.label +
                  "' needs two independent halves of its input, and this input has none");
}

namespace {

// Counts finished runs and hands each to the callback, one call at a time.
class RunsCounter {
 public:
  // Reports 0 of `total` at once, so that a display shows the runs before the first ends.
  RunsCounter(size_t total, const RunsProgressCallback& callback)
      : total_(total), callback_(callback) {
    if (callback_) callback_({0, total_, {}, 0});
  }
  void finished(const std::string& name, double seconds) {
    if (!callback_) return;
    const std::lock_guard lock(mutex_);
    callback_({++done_, total_, name, seconds});
  }

 private:
  size_t done_ = 0, total_;
  const RunsProgressCallback& callback_;
  std::mutex mutex_;
};

}  // namespace

std::vector<Image> runMembersAlone(const DenoiseInput& input,
                                   std::span<const EnsembleMember> members,
                                   std::vector<StageTime>* times,
                                   const RunsProgressCallback& progress) {
  checkMembersCanRunAlone(input, members);
  const Stopwatch all;
  std::vector<Image> outputs(members.size());
  std::vector<double> seconds(members.size());
  const MemberRunner runner(input, members);
  RunsCounter counter(members.size(), progress);
  tbb::task_group group;
  for (size_t m = 0; m < members.size(); ++m)
    group.run([&, m] {
      const Stopwatch run;
      outputs[m] = runner.run(m);
      seconds[m] = run.seconds();
      counter.finished(members[m].label + "/full", seconds[m]);
    });
  group.wait();
  if (times) {
    for (size_t m = 0; m < members.size(); ++m)
      times->push_back({members[m].label + "/full", seconds[m]});
    times->push_back({"members", all.seconds()});
  }
  return outputs;
}

int splitsNeeded(std::span<const EnsembleMember> members) {
  for (const EnsembleMember& member : members)
    if (needsHalves(member)) return 4;
  return 2;
}

bool readsHalves(std::span<const EnsembleMember> members) {
  for (const EnsembleMember& member : members) {
    const DenoiserRequirements r = member.denoiser->requirements();
    if (r.halves || r.readsHalves) return true;
  }
  return false;
}

BaseRuns baseRunsFor(const MseOptions& options, const EnsembleSources& sources) {
  BaseRuns runs;
  runs.heldOut = options.estimate != MseEstimate::Halves && hasQuarters(sources);
  runs.halves = !runs.heldOut || options.estimate == MseEstimate::Extrapolated;
  runs.full = runs.halves || blendsFullRuns(sources.width(), sources.height(),
                                            meanSampleCount(sources.full.whole));
  return runs;
}

bool blendsFullRuns(int width, int height, double samplesPerPixel) {
  return long(width) * long(height) >= kFullRunPixels && samplesPerPixel <= kFullRunSpp;
}

CombineOptions optionsForRuns(CombineOptions options, const BaseRuns& runs,
                              std::span<const EnsembleMember> members, int width, int height) {
  const bool large = long(width) * long(height) >= kWideWindowPixels;
  if (large || (runs.full && runs.heldOut && splitsNeeded(members) == 4))
    options.mse.windowRadius = options.mse.fullRunWindowRadius;
  return options;
}

std::vector<BaseOutputs> runBaseDenoisers(const EnsembleSources& sources,
                                          std::span<const EnsembleMember> members,
                                          std::vector<StageTime>* times, BaseRuns runs,
                                          const RunsProgressCallback& progress) {
  checkMembersCanRun(sources, members);
  const Stopwatch all;
  if (!runs.full && !runs.heldOut)
    throw Error("runBaseDenoisers: without the full run the held-out runs are needed");
  // Every input: its name in `times`, where its runs' outputs go, and the input the sources
  // hold, or else how to build it (those come last). A built input exists only while its runs
  // do: a held-out input holds three sub-buffers of every plane (2.3 GB at 4K), and four at
  // once did not fit a 4K render in 24 GiB; the full buffer with halves the sources do not hold
  // (renders and sweeps keep none: two more copies of every plane through every run) likewise.
  struct Part {
    std::string name;
    std::function<Image&(BaseOutputs&)> output;
    const DenoiseInput* input = nullptr;
    std::function<DenoiseInput()> build = nullptr;
  };
  std::vector<Part> plan;
  const bool buildFull = runs.full && !sources.full.halves && readsHalves(members);
  if (runs.full && !buildFull) plan.push_back({"full", &BaseOutputs::full, &sources.full});
  if (runs.halves) {
    plan.push_back({"A", &BaseOutputs::a, &sources.a});
    plan.push_back({"B", &BaseOutputs::b, &sources.b});
  }
  const size_t own = plan.size();
  if (buildFull)
    plan.push_back({"full", &BaseOutputs::full, nullptr, [&sources] {
                      DenoiseInput full = sources.full;
                      full.halves = fullBufferHalves(sources);
                      return full;
                    }});
  if (runs.heldOut)
    for (int k = 0; k < kHeldOutQuarters; ++k)
      plan.push_back({"without-q" + std::to_string(k),
                      [k](BaseOutputs& o) -> Image& { return o.heldOut[size_t(k)]; }, nullptr,
                      [&sources, k] { return heldOutInput(sources, k); }});
  const size_t parts = plan.size();
  std::vector<BaseOutputs> outputs(members.size());
  for (size_t m = 0; m < members.size(); ++m) {
    outputs[m].name = members[m].label;
    if (runs.heldOut) outputs[m].heldOut.resize(kHeldOutQuarters);
  }
  std::vector<double> seconds(members.size() * parts);
  RunsCounter counter(members.size() * parts, progress);
  // Every member on parts [first, last), on `input` or else each part's own.
  const auto runParts = [&](size_t first, size_t last, const DenoiseInput* input) {
    std::vector<std::unique_ptr<const MemberRunner>> runners(last - first);
    tbb::task_group group;
    for (size_t part = first; part < last; ++part)
      group.run([&, part] {
        runners[part - first] =
            std::make_unique<const MemberRunner>(input ? *input : *plan[part].input, members);
      });
    group.wait();
    for (size_t part = first; part < last; ++part)
      for (size_t m = 0; m < members.size(); ++m) {
        Image* target = &plan[part].output(outputs[m]);
        const MemberRunner* runner = runners[part - first].get();
        group.run([&, m, part, target, runner] {
          const Stopwatch clock;
          *target = runner->run(m);
          addEmission(*target, sources.emission);
          seconds[m * parts + part] = clock.seconds();
          counter.finished(members[m].label + "/" + plan[part].name, seconds[m * parts + part]);
        });
      }
    group.wait();
  };
  runParts(0, own, nullptr);  // the inputs the sources hold, all at once
  for (size_t part = own; part < parts; ++part) {
    const DenoiseInput input = plan[part].build();
    runParts(part, part + 1, &input);
  }
  if (!runs.full)
    for (BaseOutputs& o : outputs) o.full = meanOfHeldOutRuns(o);
  if (times) {
    for (size_t m = 0; m < members.size(); ++m)
      for (size_t part = 0; part < parts; ++part)
        times->push_back({members[m].label + "/" + plan[part].name, seconds[m * parts + part]});
    times->push_back({"bases", all.seconds()});
  }
  return outputs;
}

Ensemble::Ensemble(std::vector<EnsembleMember> members, CombineOptions options)
    : members_(std::move(members)), options_(std::move(options)) {
  for (EnsembleMember& member : members_) {
    if (!member.denoiser) throw Error("Ensemble: a member has no denoiser");
    if (member.label.empty()) member.label = member.denoiser->name();
  }
}

EnsembleResult Ensemble::run(const SampleBuffers& buffers, const Image* reference) const {
  return run(sourcesFromBuffers(buffers), reference);
}

EnsembleResult Ensemble::run(const EnsembleSources& sources, const Image* reference,
                             const RunsProgressCallback& progress) const {
  EnsembleResult result;
  const BaseRuns runs = baseRunsFor(options_.mse, sources);
  result.bases = runBaseDenoisers(sources, members_, &result.times, runs, progress);
  result.guides = guidesFromSources(sources, runs.heldOut);
  result.options = optionsForRuns(options_, runs, members_, sources.width(), sources.height());
  result.combined = combine(result.guides, pointersTo(result.bases), result.options, reference);
  result.times.insert(result.times.end(), result.combined.times.begin(),
                      result.combined.times.end());
  return result;
}

}  // namespace chorus
