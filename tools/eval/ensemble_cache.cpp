// Caches what the ensemble's combination step reads for one case (scene, spp) of the evaluation
// corpus, so that combination options can be tried without rendering or running members again
// (tools/eval/cached_corpus.py, docs/evaluation.md "Combine-only runs"):
//
//   DIR/render.exr     the K = 4 render (`chorus render --denoise none` writes it; for a
//                      synthetic entry, --synthetic writes it and DIR/reference.exr, the truth)
//   DIR/guides.exr     layers color, colorA, colorB, albedo, normal, q0 … q3 (the quarters)
//   DIR/members/<m>.exr  layers A, B, full, heldOut0 … heldOut3 of every member m
//   DIR/members/<m>.tsv  the seconds of each of those runs
//
// Members already cached are kept (a rerun adds only missing members).
#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/thread_limit.h"
#include "denoise/base/registry.h"
#include "denoise/buffers/buffers_exr.h"
#include "denoise/pipeline/ensemble.h"
#include "tests/support/synthetic_cases.h"
#include "tools/eval/cached_case.h"
#include "tools/eval/tool_main.h"

namespace {

using namespace chorus;
namespace fs = std::filesystem;

struct Args {
  std::string dir, methods;
  std::string synthetic;  // scene,size,seed,noise,firefly-rate,spp
  int threads = 2;
};

std::shared_ptr<const BaseDenoiser> memberDenoiser(const std::string& spec) {
  for (const char* name : {"box3", "gauss3", "median5"})
    if (spec == name) return synthetic::createSyntheticDenoiser(spec == "box3" ? "box1" : spec);
  return createDenoiser(spec);
}

// The synthetic entry's render and truth, as tools/eval/synthetic_corpus.cpp makes them.
void writeSynthetic(const fs::path& dir, const std::string& spec) {
  std::vector<std::string> f;
  std::string item;
  std::istringstream text(spec);
  while (std::getline(text, item, ',')) f.push_back(item);
  if (f.size() != 6) throw Error("--synthetic: expected scene,size,seed,noise,firefly-rate,spp");
  synthetic::SceneKind kind = synthetic::SceneKind::Regions;
  bool known = false;
  for (auto k :
       {synthetic::SceneKind::Regions, synthetic::SceneKind::Shadows, synthetic::SceneKind::Hdr})
    if (synthetic::sceneName(k) == f[0]) kind = k, known = true;
  if (!known) throw Error("--synthetic: unknown scene '" + f[0] + "'");
  const int size = std::stoi(f[1]), spp = std::stoi(f[5]);
  const uint64_t seed = std::stoull(f[2]);
  if (size < 8 || size > 4096 || spp < 4 || spp % 4 != 0)
    throw Error("--synthetic: size in 8..4096 and spp a multiple of 4");
  const synthetic::Scene scene = synthetic::makeScene(kind, size, size);
  synthetic::NoiseModel model;
  model.noise = std::stof(f[3]);
  model.fireflyRate = std::stof(f[4]);
  model.sppPerSplit = spp / 4;
  ensureDirectory(dir);
  if (!fs::exists(dir / "reference.exr"))
    writeExr(dir / "reference.exr", synthetic::expectedValue(scene, model));
  if (!fs::exists(dir / "render.exr"))
    writeExr(dir / "render.exr", sampleBuffersToLayers(synthetic::renderBuffers(
                                     scene, model, 4, seed * 100003ull + uint64_t(spp))));
}

void run(const Args& args) {
  checkThreadCount(args.threads);
  const ThreadLimit threads(args.threads);
  const fs::path dir = args.dir;
  if (!args.synthetic.empty()) writeSynthetic(dir, args.synthetic);
  const fs::path renderFile = dir / "render.exr";
  const SampleBuffers buffers = sampleBuffersFromLayers(readExr(renderFile), renderFile);
  if (buffers.splitCount() != 4)
    throw fileError(renderFile, "has " + std::to_string(buffers.splitCount()) +
                                    " sub-buffers; the cache needs 4");
  const EnsembleSources sources = sourcesFromBuffers(buffers);
  const EnsembleGuides guides = guidesFromSources(sources, true);
  if (!fs::exists(cachedGuidesPath(dir))) writeCachedGuides(dir, guides);

  const std::vector<std::string> specs = splitMethodList(args.methods);
  std::vector<EnsembleMember> pending;
  for (const std::string& spec : specs)
    if (!fs::exists(cachedMemberPath(dir, spec))) pending.push_back({spec, memberDenoiser(spec)});
  if (!pending.empty()) {
    std::vector<StageTime> times;
    const std::vector<BaseOutputs> outputs =
        runBaseDenoisers(sources, pending, &times, {.full = true, .halves = true, .heldOut = true});
    for (const BaseOutputs& o : outputs) {
      std::vector<double> seconds;
      for (const StageTime& t : times)
        if (t.stage.rfind(o.name + "/", 0) == 0) seconds.push_back(t.seconds);
      writeCachedMember(dir, o, seconds);
    }
  }
  std::cerr << "ensemble_cache: " << dir.string() << ": " << pending.size() << " member(s) run, "
            << specs.size() - pending.size() << " cached\n";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Caches the ensemble's inputs of one corpus case (tools/eval/cached_corpus.py)"};
  Args args;
  app.add_option("--case", args.dir, "Case folder (holds render.exr)")->required();
  app.add_option("--methods", args.methods, "Comma-separated member specs")->required();
  app.add_option("--synthetic", args.synthetic,
                 "scene,size,seed,noise,firefly-rate,spp: write the synthetic render and truth");
  app.add_option("--threads", args.threads, "TBB threads (0: all cores)")->capture_default_str();
  return chorus::eval::parseAndRun(app, argc, argv, "ensemble_cache", [&] { run(args); });
}
