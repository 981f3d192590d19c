#include "tools/sweep/sweep_runner.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <ostream>
#include <set>
#include <sstream>
#include <utility>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/image/false_color.h"
#include "common/image/finite_pixels.h"
#include "common/image/png_io.h"
#include "common/stopwatch.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/ensemble.h"
#include "renderer/scene/gltf_loader.h"
#include "tools/sweep/crop_window.h"
#include "tools/sweep/reference_render.h"
#include "tools/sweep/sweep_directory.h"

namespace chorus::sweep {

namespace fs = std::filesystem;

namespace {

constexpr int kProbeSpp = 16;

// Everything a case needs that does not depend on the case: validated once per sweep.
struct Plan {
  std::vector<EnsembleMember> members;
  std::vector<std::string> combos;
  std::vector<Combiner> combiners;
  std::set<std::pair<std::string, std::string>> rowKeys;  // (method, combiner) of every row
  size_t largestCombo = 0;                                // whose ensemble the crops show
};

Plan makePlan(const SweepConfig& config) {
  Plan plan;
  if (config.methods.empty()) throw Error("--methods is empty");
  for (const std::string& spec : config.methods)
    if (std::count(config.methods.begin(), config.methods.end(), spec) > 1)
      throw Error("--methods lists '" + spec + "' twice");
  plan.members = membersFromSpecs(config.methods);
  plan.combos = planCombinations(config.methods, config.combos);
  for (const std::string& name : config.combiners) plan.combiners.push_back(parseCombiner(name));
  plan.rowKeys.insert({"noisy", "-"});
  for (const std::string& m : config.methods) plan.rowKeys.insert({m, "-"});
  for (size_t i = 0; i < plan.combos.size(); ++i) {
    for (Combiner c : plan.combiners)
      plan.rowKeys.insert({plan.combos[i], std::string(combinerName(c))});
    if (splitCombination(plan.combos[i]).size() >
        splitCombination(plan.combos[plan.largestCombo]).size())
      plan.largestCombo = i;
  }
  return plan;
}

// A case is complete when its table exists and holds exactly the rows this sweep would write
// (a rerun with other methods or combiners recomputes it rather than mixing configurations).
bool caseIsComplete(const fs::path& csv, const Plan& plan) {
  if (!fs::exists(csv)) return false;
  std::set<std::pair<std::string, std::string>> keys;
  for (const SweepRow& r : readCsv(csv)) keys.insert({r.method, r.combiner});
  return keys == plan.rowKeys;
}

std::string sizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// Everything besides the method, combination and combiner lists that the rows of a sweep
// directory depend on (DIR/settings.txt): a rerun with other settings would mix incomparable
// rows, and its cached references would be stale.
std::string sweepSettings(const SweepConfig& config) {
  const render::RenderOptions& r = config.render;
  const render::EnvironmentDesc& e = config.environment;
  const CombineOptions& c = config.combine;
  std::ostringstream text;
  text << "size " << r.width << "x" << r.height << "\nseed " << r.seed << "\nmax-depth "
       << r.maxDepth << "\nroulette " << r.rouletteStartDepth << "\ncamera " << r.camera
       << "\nenvironment " << int(e.kind) << " " << e.radiance.r << "," << e.radiance.g << ","
       << e.radiance.b << " " << e.source << " " << e.rotationDegrees << " " << e.intensity
       << "\nreference";
  // Pinhole sweeps keep the settings they had before cameras had lenses (their folders resume).
  if (r.lensRadius > 0) text << "\nlens " << r.lensRadius << " focus " << r.focusDistance;
  for (const fs::path& file : config.references) text << " " << file.string();
  if (config.references.empty())
    text << " spp " << config.referenceSpp << " seconds " << config.referenceSeconds;
  text << "\nensemble " << solverName(c.solver) << " "
       << (c.mse.form == MseForm::Summed ? "summed" : "per-channel") << " window "
       << c.mse.windowRadius << " full-run-window " << c.mse.fullRunWindowRadius << " window-color "
       << c.mse.windowSigmaColor << (c.mse.relative ? " relative" : " absolute") << " outlier-cap "
       << c.mse.outlierCap << " consistency " << c.mse.consistency << " plausibility "
       << c.mse.plausibility << " image-prior " << c.mse.imagePrior << " noisy-fallback "
       << c.mse.noisyFallback << " filter " << (c.filter.enabled ? "bilateral" : "none") << " seed "
       << c.seed << "\ncrop " << config.cropSize << "\n";
  return text.str();
}

// Writes DIR/settings.txt, or throws chorus::Error naming it when DIR holds a sweep run with
// other settings. Returns whether it wrote the file.
bool claimDirectory(const SweepConfig& config) {
  const fs::path file = settingsPath(config.out);
  const std::string settings = sweepSettings(config);
  if (fs::exists(file)) {
    if (readFileBytes(file) != settings)
      throw fileError(file,
                      "holds a sweep run with other settings (scene, reference or ensemble "
                      "flags): rerun with those, or use another --out");
    return false;
  }
  ensureDirectory(config.out);
  writeTextAtomically(file, settings);
  return true;
}

// A new sweep that fails before it wrote a case or a reference (an unreadable scene, say)
// leaves --out as it found it: its empty subdirectories and settings.txt go.
void releaseUnusedClaim(const fs::path& out) {
  std::error_code ec;
  for (const char* sub : {"cases", "references"}) fs::remove(out / sub, ec);  // only when empty
  if (!fs::exists(out / "cases", ec) && !fs::exists(out / "references", ec))
    fs::remove(settingsPath(out), ec);
}

// The reference of a scene: the given file, else DIR/references/<scene>.exr, rendered once
// (reference_render.h: K = 1, its own seed) when absent. Returns the file it came from.
fs::path obtainReference(const SweepConfig& config, size_t sceneIndex, const std::string& scene,
                         const render::Scene& built, Image* reference, SweepRunStats* stats) {
  if (!config.references.empty()) {
    *reference = readRgbExr(config.references[sceneIndex]);
    return config.references[sceneIndex];
  }
  const fs::path cached = referencePath(config.out, scene);
  render::RenderOptions options = config.render;
  options.spp = config.referenceSpp;
  const bool wasCached = fs::exists(cached);
  const auto cachedTime = wasCached ? fs::last_write_time(cached) : fs::file_time_type{};
  if (!wasCached) {
    if (config.referenceSeconds > 0) {
      options.spp = kProbeSpp;
      options.splits = 1;
      const double probe = render::render(built, options).stats.renderSeconds;
      options.spp = referenceSppFor(config.referenceSpp, config.referenceSeconds, kProbeSpp, probe);
    }
    if (config.progress)
      *config.progress << "sweep: rendering the reference of " << scene << " at " << options.spp
                       << " spp\n"
                       << std::flush;
  }
  *reference = referenceRender(built, options, cached, config.progress ? "sweep" : "");
  // referenceRender also re-renders a cached reference of another width.
  if (!wasCached || fs::last_write_time(cached) != cachedTime) ++stats->referencesRendered;
  return cached;
}

double stageSeconds(const std::vector<StageTime>& times, const std::string& stage) {
  for (const StageTime& t : times)
    if (t.stage == stage) return t.seconds;
  return 0;
}

// One map per base whatever the MSE form (per-channel weights: their mean over channels).
Image channelMean(const Image& image) {
  Image mean(image.width(), image.height(), 1);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      float sum = 0;
      for (int c = 0; c < image.channels(); ++c) sum += image(x, y, c);
      mean(x, y, 0) = sum / float(image.channels());
    }
  return mean;
}

struct CaseResult {
  std::vector<SweepRow> rows;
  SceneCrops crops;
};

CaseResult runCase(const SweepConfig& config, const Plan& plan, const SweepCase& c,
                   const render::Scene& scene, const Image& reference,
                   const fs::path& referenceFile) {
  render::RenderOptions options = config.render;
  options.spp = c.spp;
  options.splits = kCaseSplits;
  const render::Resolution size = render::renderResolution(scene, options);
  if (reference.width() != size.width || reference.height() != size.height)  // before rendering
    throw fileError(referenceFile, "is " + sizeText(reference.width(), reference.height()) +
                                       " but the renders are " + sizeText(size.width, size.height));
  const render::RenderResult render = render::render(scene, options);
  const double renderSeconds = render.stats.renderSeconds;

  // The full buffer's halves are built for the full runs only (runBaseDenoisers).
  const EnsembleSources sources = sourcesFromBuffers(render.buffers, false);
  checkMembersCanRun(sources, plan.members);
  std::vector<StageTime> times;
  BaseRuns runs = baseRunsFor(config.combine.mse, sources);
  // A member alone is its full run (what a user running only it gets), so the sweep always runs
  // it; the ensemble blends what `chorus render` blends (the held-out runs' mean, when it does).
  const BaseRuns blended = runs;  // what the ensemble's weights blend (optionsForRuns)
  const bool blendsHeldOutMeans = !blended.full;
  runs.full = true;
  std::vector<BaseOutputs> bases = runBaseDenoisers(sources, plan.members, &times, runs);
  std::vector<Image> alone;  // each member's full run, for its own row
  for (BaseOutputs& b : bases)
    alone.push_back(blendsHeldOutMeans ? std::exchange(b.full, meanOfHeldOutRuns(b)) : b.full);
  const EnsembleGuides guides = guidesFromSources(sources, runs.heldOut);

  // Times. A base denoiser alone costs one run on the full buffer (what a user running only it
  // pays). A combination costs the runs of its members that the ensemble uses (A, B, full, or
  // the held-out inputs) plus the combine stages (solve, filter, blend): the base outputs are
  // shared across combinations here, but a user running that one ensemble pays all of it. Runs
  // are timed individually, so the figures are sequential costs even though the sweep runs the
  // bases in parallel.
  std::map<std::string, size_t> indexOf;       // member → its index in bases and plan.members
  std::map<std::string, double> ensembleCost;  // member → every run of it the ensemble uses
  for (const BaseOutputs& b : bases) {
    indexOf[b.name] = size_t(&b - bases.data());
    for (const StageTime& t : times)
      if (t.stage.rfind(b.name + "/", 0) == 0 &&
          !(blendsHeldOutMeans && t.stage == b.name + "/full"))
        ensembleCost[b.name] += t.seconds;
  }

  CaseResult result;
  result.rows.push_back(
      measuredRow(c.scene, c.spp, "noisy", "-", 0, guides.color, reference, renderSeconds, 0));
  for (size_t m = 0; m < bases.size(); ++m)
    result.rows.push_back(measuredRow(c.scene, c.spp, bases[m].name, "-", 1, alone[m], reference,
                                      renderSeconds, stageSeconds(times, bases[m].name + "/full")));

  const CropWindow window = worstWindow(guides.color, reference, config.cropSize);
  auto cropPng = [&](const Image& image) { return encodePng(cropImage(image, window)); };
  result.crops.scene = c.scene;
  result.crops.spp = c.spp;
  result.crops.images.push_back({"noisy", cropPng(guides.color)});
  for (size_t m = 0; m < bases.size(); ++m)
    result.crops.images.push_back({bases[m].name, cropPng(alone[m])});

  for (size_t i = 0; i < plan.combos.size(); ++i) {
    std::vector<const BaseOutputs*> members;
    std::vector<EnsembleMember> memberDenoisers;
    double membersSeconds = 0;
    for (const std::string& m : splitCombination(plan.combos[i])) {
      members.push_back(&bases[indexOf.at(m)]);
      memberDenoisers.push_back(plan.members[indexOf.at(m)]);
      membersSeconds += ensembleCost.at(m);
    }
    for (Combiner combiner : plan.combiners) {
      CombineOptions combineOptions =
          optionsForRuns(config.combine, blended, memberDenoisers, guides.width(), guides.height());
      combineOptions.combiner = combiner;
      const CombineResult combined =
          combine(guides, members, combineOptions, needsReference(combiner) ? &reference : nullptr);
      double seconds = membersSeconds;
      for (const StageTime& t : combined.times) seconds += t.seconds;
      result.rows.push_back(measuredRow(c.scene, c.spp, plan.combos[i],
                                        std::string(combinerName(combiner)), int(members.size()),
                                        combined.image, reference, renderSeconds, seconds));
      if (i == plan.largestCombo && combiner == Combiner::Ensemble) {
        result.crops.images.push_back(
            {"ensemble (" + plan.combos[i] + ")", cropPng(combined.image)});
        for (size_t m = 0; m < members.size(); ++m)
          result.crops.weightMaps.push_back(
              {members[m]->name,
               encodePng(falseColor(channelMean(cropImage(combined.weights[m], window))))});
      }
    }
  }
  result.crops.images.push_back({"reference", cropPng(reference)});
  return result;
}

std::string clockText(double seconds) {
  const long s = long(seconds + 0.5);
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  return buffer;
}

}  // namespace

int referenceSppFor(int spp, double seconds, int probeSpp, double probeSeconds) {
  if (seconds <= 0) return spp;
  const double rate = double(probeSpp) / std::max(probeSeconds, 1e-6);
  const double budget = std::clamp((seconds - probeSeconds) * rate, double(probeSpp), 1e8);
  return int(budget);
}

// The sweep proper, once DIR is claimed.
SweepRunStats runClaimedSweep(const SweepConfig& config, const Plan& plan) {
  const std::vector<SweepCase> all = planCases(config.scenes, config.spps);
  const std::vector<SweepCase> mine = casesOfShard(all, config.shard);
  SweepRunStats stats;
  stats.casesPlanned = int(mine.size());
  std::vector<SweepCase> pending;
  for (const SweepCase& c : mine)
    if (caseIsComplete(caseCsvPath(config.out, c), plan))
      ++stats.casesSkipped;
    else
      pending.push_back(c);
  ensureDirectory(config.out / "cases");
  if (config.progress)
    *config.progress << "sweep: " << mine.size() << " case(s) in this shard, " << stats.casesSkipped
                     << " already done, " << pending.size() << " to run\n"
                     << std::flush;

  std::function<render::Scene(const fs::path&)> loadScene = config.loadScene;
  if (!loadScene)
    loadScene = [&](const fs::path& path) {
      return render::buildScene(render::loadGltf(path), config.environment);
    };
  const Stopwatch sweepTime;
  std::vector<FinishedCase> finished;
  for (size_t s = 0; s < config.scenes.size(); ++s) {
    std::vector<SweepCase> cases;
    for (const SweepCase& c : pending)
      if (c.scenePath == config.scenes[s]) cases.push_back(c);
    if (cases.empty()) continue;
    const render::Scene scene = loadScene(config.scenes[s]);
    Image reference;
    const fs::path referenceFile =
        obtainReference(config, s, cases[0].scene, scene, &reference, &stats);
    for (const SweepCase& c : cases) {
      const Stopwatch caseTime;
      const CaseResult result = runCase(config, plan, c, scene, reference, referenceFile);
      writeCaseCrops(config.out, c, result.crops);
      writeCsv(caseCsvPath(config.out, c), result.rows);  // last: marks the case complete
      stats.ranCases.push_back(c.fileStem());
      ++stats.casesRun;
      finished.push_back({c.spp, caseTime.seconds()});
      if (config.progress) {
        std::vector<int> remainingSpps;
        for (size_t k = size_t(stats.casesRun); k < pending.size(); ++k)
          remainingSpps.push_back(pending[k].spp);
        const double remaining = estimateRemainingSeconds(finished, remainingSpps);
        *config.progress << "sweep: [" << stats.casesRun << "/" << pending.size() << "] " << c.scene
                         << " at " << c.spp << " spp: " << result.rows.size() << " rows, elapsed "
                         << clockText(sweepTime.seconds()) << ", ETA " << clockText(remaining)
                         << "\n"
                         << std::flush;
      }
    }
  }
  writeSweepSummary(config.out, config.report);
  return stats;
}

SweepRunStats runSweep(const SweepConfig& config) {
  if (config.scenes.empty()) throw Error("no scenes given");
  if (config.out.empty()) throw Error("no output directory given (--out)");
  for (const fs::path& scene : config.scenes)
    if (!fs::is_regular_file(scene)) throw fileError(scene, "no such file");
  if (!config.references.empty() && config.references.size() != config.scenes.size())
    throw Error("--reference given " + std::to_string(config.references.size()) + " times for " +
                std::to_string(config.scenes.size()) + " scenes (one per scene, in scene order)");
  for (const fs::path& reference : config.references) {
    if (!fs::is_regular_file(reference)) throw fileError(reference, "no such file");
    // A NaN in a reference makes every row's metrics NaN: refused before anything runs.
    requireFinitePixels(readRgbExr(reference), reference);
  }
  if (config.cropSize < 1) throw Error("crop size must be positive");
  const Plan plan = makePlan(config);
  const bool claimed = claimDirectory(config);
  try {
    return runClaimedSweep(config, plan);
  } catch (...) {
    if (claimed) releaseUnusedClaim(config.out);
    throw;
  }
}

}  // namespace chorus::sweep
