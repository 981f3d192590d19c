#include "denoise/pipeline/ensemble.h"

#include <tbb/task_group.h>

#include <functional>
#include <set>
#include <string>

#include "common/error.h"
#include "common/stopwatch.h"
#include "denoise/base/registry.h"
#include "denoise/ensemble/ensemble_types.h"
#include "denoise/pipeline/held_out_inputs.h"

namespace chorus {

std::vector<EnsembleMember> membersFromSpecs(std::span<const std::string> specs) {
  std::vector<EnsembleMember> members;
  for (const std::string& spec : specs)
    members.push_back({spec, std::shared_ptr<const BaseDenoiser>(createDenoiser(spec))});
  return members;
}

namespace {

// Members with distinct labels (their outputs' file and layer names), at least one.
void checkLabels(std::span<const EnsembleMember> members) {
  if (members.empty()) throw Error("no base denoisers given");
  std::set<std::string> labels;
  for (const EnsembleMember& member : members)
    if (!labels.insert(member.label).second)
      throw Error("base denoiser '" + member.label + "' is listed twice");
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
    const char* missing = !sources.a.halves      ? "half A"
                          : !sources.b.halves    ? "half B"
                          : !sources.full.halves ? "the full buffer"
                                                 : nullptr;
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

std::vector<Image> runMembersAlone(const DenoiseInput& input,
                                   std::span<const EnsembleMember> members,
                                   std::vector<StageTime>* times) {
  checkMembersCanRunAlone(input, members);
  const Stopwatch all;
  std::vector<Image> outputs(members.size());
  std::vector<double> seconds(members.size());
  tbb::task_group group;
  for (size_t m = 0; m < members.size(); ++m)
    group.run([&, m] {
      const Stopwatch run;
      outputs[m] = members[m].denoiser->run(input);
      seconds[m] = run.seconds();
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
  runs.full = runs.halves;
  return runs;
}

std::vector<BaseOutputs> runBaseDenoisers(const EnsembleSources& sources,
                                          std::span<const EnsembleMember> members,
                                          std::vector<StageTime>* times, BaseRuns runs) {
  checkMembersCanRun(sources, members);
  const Stopwatch all;
  const std::vector<DenoiseInput> heldOutInputList =
      runs.heldOut ? heldOutInputs(sources) : std::vector<DenoiseInput>{};
  // Every run: its input, its name in `times` and where its output goes.
  struct Run {
    const DenoiseInput* input;
    std::string part;
    std::function<Image&(BaseOutputs&)> output;
  };
  if (!runs.full && !runs.heldOut)
    throw Error("runBaseDenoisers: without the full run the held-out runs are needed");
  std::vector<Run> plan;
  if (runs.full) plan.push_back({&sources.full, "full", &BaseOutputs::full});
  if (runs.halves) {
    plan.push_back({&sources.a, "A", &BaseOutputs::a});
    plan.push_back({&sources.b, "B", &BaseOutputs::b});
  }
  for (size_t k = 0; k < heldOutInputList.size(); ++k)
    plan.push_back({&heldOutInputList[k], "without-q" + std::to_string(k),
                    [k](BaseOutputs& o) -> Image& { return o.heldOut[k]; }});
  const size_t parts = plan.size();
  std::vector<BaseOutputs> outputs(members.size());
  std::vector<double> seconds(members.size() * parts);
  tbb::task_group group;
  for (size_t m = 0; m < members.size(); ++m) {
    BaseOutputs& o = outputs[m];
    o.name = members[m].label;
    o.heldOut.resize(heldOutInputList.size());
    for (size_t part = 0; part < parts; ++part) {
      Image* target = &plan[part].output(o);
      group.run([&, m, part, target] {
        const Stopwatch clock;
        *target = members[m].denoiser->run(*plan[part].input);
        seconds[m * parts + part] = clock.seconds();
      });
    }
  }
  group.wait();
  if (!runs.full)
    for (BaseOutputs& o : outputs) o.full = meanOfHeldOutRuns(o);
  if (times) {
    for (size_t m = 0; m < members.size(); ++m)
      for (size_t part = 0; part < parts; ++part)
        times->push_back({members[m].label + "/" + plan[part].part, seconds[m * parts + part]});
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

EnsembleResult Ensemble::run(const EnsembleSources& sources, const Image* reference) const {
  EnsembleResult result;
  const BaseRuns runs = baseRunsFor(options_.mse, sources);
  result.bases = runBaseDenoisers(sources, members_, &result.times, runs);
  result.guides = guidesFromSources(sources, runs.heldOut);
  result.combined = combine(result.guides, pointersTo(result.bases), options_, reference);
  result.times.insert(result.times.end(), result.combined.times.begin(),
                      result.combined.times.end());
  return result;
}

}  // namespace chorus
