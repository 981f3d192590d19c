// Combine-only evaluation of one cached corpus entry (tools/eval/ensemble_cache.cpp made the
// cache; tools/eval/cached_corpus.py drives both): per cached spp, every combination × combiner
// with the given ensemble flags, scored against the entry's reference, written as sweep cases
// (OUT/<entry>/cases/<entry>_spp<N>.csv) so that tools/eval/summarize.py reads them like a
// corpus run; with --preview-methods also the --preview configuration at its spp
// (OUT/<entry>.preview/cases/). Only the combination step runs: trying an option over a whole
// half takes minutes instead of the hour of a corpus run.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/thread_limit.h"
#include "denoise/base/registry.h"
#include "denoise/ensemble/combiners.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/ensemble.h"
#include "tools/chorus/ensemble_flags.h"
#include "tools/chorus/render_denoise.h"
#include "tools/eval/cached_case.h"
#include "tools/eval/tool_main.h"
#include "tools/sweep/sweep_directory.h"
#include "tools/sweep/sweep_plan.h"
#include "tools/sweep/sweep_results.h"

namespace {

using namespace chorus;
namespace fs = std::filesystem;

struct Args {
  std::string cache, name, out, methods, combos, combiners = "ensemble";
  std::string previewMethods, previewSpp = "4", spp;
  int threads = 2;
  bool fullFromHeldOut = false, diagnose = false, noHalfRuns = false;
  cli::EnsembleFlags ensemble;
};

// The members of `specs` that the registry knows: the synthetic entries' filters (box3, gauss3,
// median5: tests/support/synthetic_cases.h) are not in it, and filter their whole input.
std::vector<EnsembleMember> registeredMembers(const std::vector<std::string>& specs) {
  std::vector<std::string> known;
  for (const std::string& spec : specs) {
    const std::string name = spec.substr(0, spec.find(':'));
    for (const DenoiserEntry& entry : builtinDenoisers())
      if (entry.name == name) known.push_back(spec);
  }
  return membersFromSpecs(known);
}

// The rows of one case: noisy, every member, every combination × combiner.
std::vector<sweep::SweepRow> evaluate(const Args& args, const fs::path& caseDir, int spp,
                                      const std::vector<std::string>& methods,
                                      const std::vector<std::string>& combos,
                                      const CombineOptions& base, const Image& reference) {
  const EnsembleGuides guides = readCachedGuides(caseDir);
  // Members alone are always their full-buffer runs (what a user running one pays for).
  std::map<std::string, BaseOutputs> outputs;
  std::map<std::string, Image> alone;
  for (const std::string& m : methods) {
    BaseOutputs& o = outputs[m] = readCachedMember(caseDir, m);
    alone[m] = o.full;
    if (args.noHalfRuns && o.heldOut.size() == 4) o.a = o.b = Image();
  }
  // What the blends take, as the pipeline decides it (baseRunsFor, optionsForRuns): a case's
  // members all have their held-out runs or none.
  BaseRuns blended;
  blended.heldOut = !outputs.empty() && outputs.begin()->second.heldOut.size() == 4;
  blended.full = !(args.fullFromHeldOut && blended.heldOut &&
                   !blendsFullRuns(guides.width(), guides.height(), spp));
  if (!blended.full)
    for (auto& [name, o] : outputs) o.full = meanOfHeldOutRuns(o);
  std::vector<sweep::SweepRow> rows = {
      sweep::measuredRow(args.name, spp, "noisy", "-", 0, guides.color, reference, 0, 0)};
  for (const std::string& m : methods)
    rows.push_back(sweep::measuredRow(args.name, spp, m, "-", 1, alone[m], reference, 0, 0));
  for (const std::string& combo : combos) {
    std::vector<const BaseOutputs*> chosen;
    const std::vector<std::string> specs = sweep::splitCombination(combo);
    for (const std::string& m : specs) chosen.push_back(&outputs.at(m));
    const CombineOptions forRuns =
        optionsForRuns(base, blended, registeredMembers(specs), guides.width(), guides.height());
    for (const std::string& name : splitMethodList(args.combiners)) {
      CombineOptions options = forRuns;
      options.combiner = parseCombiner(name);
      const CombineResult result = combine(guides, chosen, options, &reference);
      double seconds = 0;
      for (const StageTime& t : result.times) seconds += t.seconds;
      rows.push_back(sweep::measuredRow(args.name, spp, combo, name, int(chosen.size()),
                                        result.image, reference, 0, seconds));
    }
  }
  return rows;
}

// --diagnose: per spp and member, the relMSE of its run on each part of the samples (what the
// halves and quarters estimates judge, against what the ensemble blends), on stdout.
void diagnose(const Args& args, const fs::path& caseDir, int spp,
              const std::vector<std::string>& methods, const Image& reference) {
  for (const std::string& m : methods) {
    const BaseOutputs o = readCachedMember(caseDir, m);
    const Image mean = o.heldOut.size() == 4 ? meanOfHeldOutRuns(o) : o.full;
    double heldOut = 0;
    for (const Image& run : o.heldOut) heldOut += computeMetrics(run, reference).relMse / 4;
    std::printf("%s\t%d\t%s\tA %.4g\tB %.4g\tfull %.4g\theldOut %.4g\theldOutMean %.4g\n",
                args.name.c_str(), spp, m.c_str(), computeMetrics(o.a, reference).relMse,
                computeMetrics(o.b, reference).relMse, computeMetrics(o.full, reference).relMse,
                heldOut, computeMetrics(mean, reference).relMse);
  }
}

void run(const Args& args) {
  checkThreadCount(args.threads);
  const ThreadLimit threads(args.threads);
  const fs::path cache = args.cache, out = args.out;
  const Image reference = readRgbExr(cache / "reference.exr");
  const std::vector<std::string> methods = splitMethodList(args.methods);
  const std::vector<std::string> combos = sweep::planCombinations(methods, args.combos);
  const CombineOptions options = args.ensemble.options();
  CombineOptions previewOptions = options;
  cli::applyPreviewDefaults(previewOptions, args.ensemble);
  const std::vector<int> previewSpps = sweep::parseIntList(args.previewSpp, "--preview-spp");
  std::vector<int> spps;
  if (!args.spp.empty()) {
    spps = sweep::parseIntList(args.spp, "--spp");
  } else {
    for (const fs::directory_entry& e : fs::directory_iterator(cache)) {
      const std::string name = e.path().filename().string();
      if (e.is_directory() && name.rfind("spp", 0) == 0) spps.push_back(std::stoi(name.substr(3)));
    }
    std::sort(spps.begin(), spps.end());
  }
  if (spps.empty()) throw fileError(cache, "holds no cached case (spp<N> folder)");
  for (int spp : spps) {
    const fs::path caseDir = cache / ("spp" + std::to_string(spp));
    if (args.diagnose) {
      diagnose(args, caseDir, spp, methods, reference);
      continue;
    }
    sweep::SweepCase c;
    c.scene = args.name;
    c.spp = spp;
    ensureDirectory(out / args.name / "cases");
    sweep::writeCsv(sweep::caseCsvPath(out / args.name, c),
                    evaluate(args, caseDir, spp, methods, combos, options, reference));
    if (!args.previewMethods.empty() &&
        std::find(previewSpps.begin(), previewSpps.end(), spp) != previewSpps.end()) {
      const std::vector<std::string> preview = splitMethodList(args.previewMethods);
      ensureDirectory(out / (args.name + ".preview") / "cases");
      sweep::writeCsv(sweep::caseCsvPath(out / (args.name + ".preview"), c),
                      evaluate(args, caseDir, spp, preview, sweep::planCombinations(preview, "all"),
                               previewOptions, reference));
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Combine-only evaluation of a cached corpus entry (tools/eval/cached_corpus.py)"};
  Args args;
  app.add_option("--cache", args.cache, "The entry's cache folder (spp<N>/, reference.exr)")
      ->required();
  app.add_option("--name", args.name, "Entry name (the rows' scene)")->required();
  app.add_option("--out", args.out, "Output folder: OUT/<name>/cases/*.csv")->required();
  app.add_option("--methods", args.methods, "Comma-separated members")->required();
  app.add_option("--combos", args.combos, "Combinations (planCombinations syntax)")->required();
  app.add_option("--combiners", args.combiners, "Comma-separated combiners")->capture_default_str();
  app.add_option("--spp", args.spp, "Comma-separated spp (default: every cached one)");
  app.add_option("--preview-methods", args.previewMethods,
                 "Members of the --preview configuration (empty: no preview rows)");
  app.add_option("--preview-spp", args.previewSpp, "spp of the preview rows")
      ->capture_default_str();
  app.add_option("--threads", args.threads, "TBB threads (0: all cores)")->capture_default_str();
  app.add_flag("--diagnose", args.diagnose,
               "Print each member's relMSE on A, B, full and held-out runs instead");
  app.add_flag("--full-from-held-out", args.fullFromHeldOut,
               "Replace each member's full-buffer output by the mean of its four held-out runs "
               "where the pipeline blends that mean (blendsFullRuns: not on images of >= 32768 "
               "pixels at <= 16 spp)");
  app.add_flag("--no-half-runs", args.noHalfRuns,
               "Drop the members' half runs where held-out runs replace them (as the pipeline "
               "does for the quarters estimate)");
  args.ensemble.addFlags(app);
  return chorus::eval::parseAndRun(app, argc, argv, "combine_cached", [&] { run(args); });
}
