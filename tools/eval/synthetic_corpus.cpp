// The synthetic entries of the evaluation corpus (tools/eval/corpus.json): a synthetic scene
// (tests/support/synthetic_cases.h) with independent per-channel Gaussian noise, denoised by
// members that filter each channel on its own — a 3×3 box, a Gaussian (σ 3) and a 5×5 median,
// the nonlinear one — then every combination of two or more members with every combiner, scored
// against the scene's expected value. Writes the rows of each spp as a sweep case
// (OUT/cases/<name>_spp<N>.csv, the format of `chorus sweep`, so that summarize.py reads both
// alike), resumes finished cases, and writes OUT/results.csv and report.html at the end.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/stopwatch.h"
#include "common/thread_limit.h"
#include "denoise/base/registry.h"
#include "denoise/ensemble/combiners.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/ensemble.h"
#include "tests/support/synthetic_cases.h"
#include "tools/eval/tool_main.h"
#include "tools/sweep/sweep_directory.h"
#include "tools/sweep/sweep_plan.h"
#include "tools/sweep/sweep_results.h"

namespace {

using namespace chorus;
namespace fs = std::filesystem;

EnsembleMember member(const std::string& name) {
  if (name == "box3") return {name, synthetic::createSyntheticDenoiser("box1")};
  if (name == "gauss3") return {name, synthetic::createSyntheticDenoiser("gauss3")};
  if (name == "median5") return {name, synthetic::createSyntheticDenoiser("median5")};
  throw Error("--members: unknown member '" + name + "' (known: box3, gauss3, median5)");
}

synthetic::SceneKind sceneKind(const std::string& name) {
  for (auto kind :
       {synthetic::SceneKind::Regions, synthetic::SceneKind::Shadows, synthetic::SceneKind::Hdr})
    if (synthetic::sceneName(kind) == name) return kind;
  throw Error("--scene: unknown synthetic scene '" + name + "' (known: regions, shadows, hdr)");
}

struct Args {
  std::string name, scene = "regions", members = "box3,gauss3,median5";
  std::string combiners = "ensemble,onehot-pre,onehot-post,average,oracle", spp = "4,16,64";
  std::string out;
  int size = 128, threads = 2;
  uint64_t seed = 1;
  float noise = 1.0f, fireflyRate = 0.0f;
};

std::string settingsText(const Args& a) {
  char text[512];
  std::snprintf(text, sizeof text,
                "synthetic %s size %d seed %llu noise %g firefly-rate %g members %s\n",
                a.scene.c_str(), a.size, static_cast<unsigned long long>(a.seed), double(a.noise),
                double(a.fireflyRate), a.members.c_str());
  return text;
}

std::vector<sweep::SweepRow> runCase(const Args& args, const sweep::SweepCase& c,
                                     const std::vector<EnsembleMember>& members,
                                     const std::vector<std::string>& combos,
                                     const std::vector<Combiner>& combiners) {
  const synthetic::Scene scene = synthetic::makeScene(sceneKind(args.scene), args.size, args.size);
  synthetic::NoiseModel model;
  model.noise = args.noise;
  model.sppPerSplit = c.spp / 4;
  model.fireflyRate = args.fireflyRate;
  const Image truth = synthetic::expectedValue(scene, model);
  const EnsembleSources sources = sourcesFromBuffers(
      synthetic::renderBuffers(scene, model, 4, args.seed * 100003ull + uint64_t(c.spp)));
  std::vector<StageTime> times;
  const std::vector<BaseOutputs> bases = runBaseDenoisers(sources, members, &times);
  const EnsembleGuides guides = guidesFromSources(sources);

  std::vector<sweep::SweepRow> rows = {
      sweep::measuredRow(c.scene, c.spp, "noisy", "-", 0, guides.color, truth, 0, 0)};
  for (const BaseOutputs& b : bases)
    rows.push_back(sweep::measuredRow(c.scene, c.spp, b.name, "-", 1, b.full, truth, 0, 0));
  for (const std::string& combo : combos) {
    std::vector<const BaseOutputs*> chosen;
    for (const std::string& name : sweep::splitCombination(combo))
      for (const BaseOutputs& b : bases)
        if (b.name == name) chosen.push_back(&b);
    for (Combiner combiner : combiners) {
      CombineOptions options;
      options.combiner = combiner;
      const Stopwatch time;
      const CombineResult result =
          combine(guides, chosen, options, needsReference(combiner) ? &truth : nullptr);
      rows.push_back(sweep::measuredRow(c.scene, c.spp, combo, std::string(combinerName(combiner)),
                                        int(chosen.size()), result.image, truth, 0,
                                        time.seconds()));
    }
  }
  return rows;
}

void run(const Args& args) {
  if (args.name.empty()) throw Error("--name is empty");
  if (args.size < 8 || args.size > 4096) throw Error("--size must be in 8..4096");
  if (!(args.noise >= 0) || !(args.fireflyRate >= 0 && args.fireflyRate <= 1))
    throw Error("--noise must be at least 0 and --firefly-rate in 0..1");
  sceneKind(args.scene);
  checkThreadCount(args.threads);
  const ThreadLimit threads(args.threads);
  const std::vector<int> spps = sweep::parseIntList(args.spp, "--spp");
  for (int spp : spps)
    if (spp % 4 != 0)
      throw Error("--spp: " + std::to_string(spp) + " is not a multiple of 4 (K = 4)");
  const std::vector<std::string> names = splitMethodList(args.members);
  std::vector<EnsembleMember> members;
  for (const std::string& name : names) members.push_back(member(name));
  const std::vector<std::string> combos = sweep::planCombinations(names, "all");
  std::vector<Combiner> combiners;
  for (const std::string& name : splitMethodList(args.combiners))
    combiners.push_back(parseCombiner(name));

  const fs::path out = args.out;
  ensureDirectory(out / "cases");
  const fs::path settings = sweep::settingsPath(out);
  if (fs::exists(settings) && readFileBytes(settings) != settingsText(args))
    throw fileError(settings, "holds a synthetic run with other settings: use another --out");
  writeTextAtomically(settings, settingsText(args));

  const Stopwatch total;
  for (int spp : spps) {
    sweep::SweepCase c;
    c.scene = args.name;
    c.spp = spp;
    const fs::path csv = sweep::caseCsvPath(out, c);
    if (fs::exists(csv)) continue;
    sweep::writeCsv(csv, runCase(args, c, members, combos, combiners));
    std::cerr << "synthetic: " << args.name << " at " << spp << " spp done, elapsed "
              << int(total.seconds()) << " s\n";
  }
  sweep::ReportInfo info;
  info.title = "chorus synthetic corpus entry " + args.name;
  info.details = settingsText(args);
  sweep::writeSweepSummary(out, info);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"A synthetic entry of the evaluation corpus (tools/eval/corpus.json)"};
  Args args;
  app.add_option("--name", args.name, "Scene name in the rows (the corpus entry)")->required();
  app.add_option("--scene", args.scene, "regions, shadows or hdr")->capture_default_str();
  app.add_option("--size", args.size, "Image width and height")->capture_default_str();
  app.add_option("--seed", args.seed, "Noise seed")->capture_default_str();
  app.add_option("--noise", args.noise, "Per-sample sigma = noise * sqrt(mu + 0.05)")
      ->capture_default_str();
  app.add_option("--firefly-rate", args.fireflyRate, "Probability that a sample is a firefly")
      ->capture_default_str();
  app.add_option("--members", args.members, "Comma-separated: box3, gauss3, median5")
      ->capture_default_str();
  app.add_option("--combiners", args.combiners, "Comma-separated combiners")->capture_default_str();
  app.add_option("--spp", args.spp, "Comma-separated spp (multiples of 4: K = 4 sub-buffers)")
      ->capture_default_str();
  app.add_option("--threads", args.threads, "TBB threads (0: all cores)")->capture_default_str();
  app.add_option("--out", args.out, "Output folder")->required();
  return chorus::eval::parseAndRun(app, argc, argv, "synthetic_corpus", [&] { run(args); });
}
