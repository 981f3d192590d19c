// `chorus denoise` end to end on synthetic inputs: a directory of base outputs (the ensemble
// paper's layout) and a render.exr with the registered base denoisers; the written files,
// stats.json, and clean failures (one line naming the problem, exit code ≠ 0).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/image/exr_io.h"
#include "common/image/output_values.h"
#include "denoise/base/nfor/nfor.h"
#include "denoise/base/registry.h"
#include "denoise/buffers/buffers_exr.h"
#include "denoise/buffers/tungsten_dir.h"
#include "denoise/ensemble/combiners.h"
#include "denoise/ensemble/outputs_directory.h"
#include "denoise/metrics/metrics.h"
#include "tests/support/synthetic_cases.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::readJson;
using test::runChorus;
using test::TempDir;

int lineCount(const std::string& s) {
  return int(std::count(s.begin(), s.end(), '\n'));
}

std::vector<std::string> layerNames(const fs::path& path) {
  std::vector<std::string> names;
  for (const ExrLayer& layer : readExr(path)) names.push_back(layer.name);
  return names;
}

// A synthetic case written in the outputs layout, with its expected value as reference.
struct OutputsFixture {
  TempDir dir{"chorus_denoise_cli"};
  synthetic::PreparedCase prepared;
  fs::path input, reference;
  OutputsFixture() {
    synthetic::Case c = synthetic::standardCases()[3];  // regions, noise 1, five members
    c.members = {"box1", "guided", "nlm"};
    prepared = synthetic::prepareCase(c, 40, 32);
    input = dir / "outputs";
    writeOutputsDirectory(input, prepared.guides, prepared.bases);
    reference = dir / "reference.exr";
    writeExr(reference, prepared.truth);
  }
};

TEST(DenoiseCli, OutputsDirectoryWithReference) {
  OutputsFixture f;
  const fs::path out = f.dir / "out";
  const auto r =
      runChorus({"denoise", f.input.string(), "--methods", "box1,guided,nlm", "--combine",
                 "ensemble,average,oracle", "--reference", f.reference.string(), "--keep",
                 "members,weights", "--out", out.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const char* name :
       {"ensemble.exr", "ensemble.png", "average.exr", "average.png", "oracle.exr", "weights.exr",
        "weights-average.exr", "box1.exr", "guided.exr", "nlm.exr", "stats.json"})
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  EXPECT_EQ(layerNames(out / "ensemble.exr"),
            (std::vector<std::string>{"", "A", "B", "mseEstimate"}));
  EXPECT_EQ(layerNames(out / "weights.exr"),
            (std::vector<std::string>{"box1", "guided", "nlm", "noisyFallback"}));
  EXPECT_EQ(layerNames(out / "weights-average.exr"),
            (std::vector<std::string>{"box1", "guided", "nlm"}));  // the ensemble's only
  EXPECT_EQ(layerNames(out / "box1.exr"), (std::vector<std::string>{"", "A", "B"}));

  // The file is what the library computes with the same (default) options.
  const Image written = readExrLayer(out / "ensemble.exr");
  const CombineResult direct =
      combine(f.prepared.guides, pointersTo(f.prepared.bases), CombineOptions{});
  EXPECT_TRUE(
      std::equal(written.values().begin(), written.values().end(), direct.image.values().begin()));

  const json stats = readJson(out / "stats.json");
  EXPECT_EQ(stats["input_kind"], "outputs directory");
  EXPECT_EQ(stats["width"], 40);
  EXPECT_EQ(stats["options"]["window_used"], 5);  // the wide window only from 2^17 pixels
  for (const char* stage : {"read", "ensemble/solve", "ensemble/filter", "ensemble/blend",
                            "average/solve", "oracle/solve", "total"})
    EXPECT_TRUE(stats["seconds"].contains(stage)) << stage;
  const json& m = stats["metrics"];
  for (const char* key : {"noisy", "box1", "guided", "nlm", "ensemble", "average", "oracle"})
    EXPECT_TRUE(m.contains(key)) << key;
  EXPECT_NEAR(m["ensemble"]["relmse"].get<double>(), relMse(written, f.prepared.truth), 1e-9);
  EXPECT_NEAR(m["guided"]["relmse"].get<double>(),
              relMse(f.prepared.bases[1].full, f.prepared.truth), 1e-9);
  EXPECT_LT(m["ensemble"]["relmse"].get<double>(), m["noisy"]["relmse"].get<double>());
  EXPECT_LE(m["oracle"]["relmse"].get<double>(), m["ensemble"]["relmse"].get<double>());
}

TEST(DenoiseCli, OptionsReachTheLibrary) {
  OutputsFixture f;
  const fs::path out = f.dir / "out";
  const auto r = runChorus({"denoise", f.input.string(), "--methods", "box1,nlm", "--mse",
                            "per-channel", "--window", "0", "--weight-filter", "none", "--solver",
                            "pairwise", "--solver-seed=5", "--relative", "--noisy-fallback", "1.5",
                            "--keep=weights", "--out", out.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  CombineOptions o;
  o.mse.noisyFallback = 1.5;
  o.mse.form = MseForm::PerChannel;
  o.mse.windowRadius = 0;
  o.mse.relative = true;
  o.filter.enabled = false;
  o.solver = SolverKind::Pairwise;
  o.seed = 5;
  const std::vector<const BaseOutputs*> bases = {&f.prepared.bases[0], &f.prepared.bases[2]};
  const CombineResult direct = combine(f.prepared.guides, bases, o);
  const Image written = readExrLayer(out / "ensemble.exr");
  Image expected = direct.image;
  repairForOutput(expected);  // as the writers do: the noisy fallback has negative values here
  EXPECT_TRUE(
      std::equal(written.values().begin(), written.values().end(), expected.values().begin()));
  EXPECT_EQ(readExrLayer(out / "weights.exr", "box1").channels(), 3);  // per channel
  const json stats = readJson(out / "stats.json");
  EXPECT_EQ(stats["options"]["noisy_fallback"], 1.5);
  EXPECT_EQ(stats["noisy_fallback_pixels"].get<size_t>(), direct.noisyFallbackPixels);
  // --window sets the one radius used everywhere, full-run blends included.
  EXPECT_EQ(stats["options"]["window"], 0);
  EXPECT_EQ(stats["options"]["full_run_window"], 0);
  EXPECT_EQ(stats["options"]["window_used"], 0);
}

TEST(DenoiseCli, CleanFailures) {
  OutputsFixture f;
  const fs::path out = f.dir / "out";
  const auto expectOneLine = [&](std::vector<std::string> args, const std::string& needle) {
    args.insert(args.begin(), "denoise");
    const auto r = runChorus(args);
    EXPECT_NE(r.exitCode, 0) << needle;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  };
  const std::string in = f.input.string();
  expectOneLine({in, "--methods", "box1,oidn", "--out", out.string()},
                "oidn: missing method folder");
  expectOneLine({in, "--methods", "box1", "--combine", "best", "--out", out.string()},
                "unknown combiner 'best'");
  expectOneLine({in, "--methods", "box1,nlm", "--combine", "none,average", "--out", out.string()},
                "--combine none runs each method alone");
  expectOneLine({in, "--methods", "box1", "--combine", "oracle", "--out", out.string()},
                "needs --reference");
  expectOneLine({in, "--methods", "box1", "--mse", "diagonal", "--out", out.string()},
                "unknown --mse");
  expectOneLine({in, "--methods", "box1", "--noisy-fallback", "0.5", "--out", out.string()},
                "--noisy-fallback: must be 0 (off) or a number in [1, 1e+06]");
  expectOneLine({(f.dir / "nothing").string(), "--methods", "box1", "--out", out.string()},
                "no such file or directory");
  // A method file of another size.
  writeExr(f.input / "nlm" / "nlmA.exr", Image(8, 8, 3));
  expectOneLine({in, "--methods", "box1,nlm", "--out", out.string()}, "nlmA.exr: is 8x8");
  // A reference of another size.
  writeExr(f.dir / "small.exr", Image(8, 8, 3));
  expectOneLine({in, "--methods", "box1", "--reference", (f.dir / "small.exr").string(), "--out",
                 out.string()},
                "small.exr: is 8x8x3");
  EXPECT_FALSE(fs::exists(out / "stats.json"));
}

// The synthetic scene and noise of the render.exr and Tungsten fixtures.
const synthetic::Scene& fixtureScene() {
  static const synthetic::Scene scene = synthetic::makeScene(synthetic::SceneKind::Shadows, 36, 28);
  return scene;
}
constexpr synthetic::NoiseModel kFixtureNoise{1.0f, 4, 0.0f};

SampleBuffers fixtureBuffers(int splits) {
  return synthetic::renderBuffers(fixtureScene(), kFixtureNoise, splits, 4);
}

// A render.exr written from K sub-buffers of a synthetic scene.
fs::path writeRender(const TempDir& dir, int splits) {
  const fs::path path = dir / ("render" + std::to_string(splits) + ".exr");
  writeExr(path, sampleBuffersToLayers(fixtureBuffers(splits)));
  return path;
}

// The expected value of the fixtures' pixels, as a reference file.
fs::path writeTruth(const TempDir& dir) {
  const fs::path path = dir / "truth.exr";
  writeExr(path, synthetic::expectedValue(fixtureScene(), kFixtureNoise));
  return path;
}

TEST(DenoiseCli, RenderExrWithRegisteredDenoisers) {
  std::vector<std::string> names;
  for (const DenoiserEntry& entry : builtinDenoisers())
    if (!createDenoiser(entry.name)->requirements().halves) names.push_back(entry.name);
  if (names.empty()) GTEST_SKIP() << "no registered base denoiser yet";
  if (names.size() > 2) names.resize(2);
  std::string methods;
  for (const std::string& n : names) methods += (methods.empty() ? "" : ",") + n;

  TempDir dir("chorus_denoise_render");
  const fs::path render = writeRender(dir, 4), out = dir / "out";
  const auto r = runChorus({"denoise", render.string(), "--methods", methods, "--keep", "members",
                            "--out", out.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const json stats = readJson(out / "stats.json");
  EXPECT_EQ(stats["input_kind"], "render.exr");
  for (const std::string& n : names) {
    EXPECT_TRUE(fs::is_regular_file(out / (n + ".exr"))) << n;
    // K = 4 and the quarters estimate: the held-out runs only (their mean is the blended
    // output), no half runs and no full run.
    for (const char* part : {"/without-q0", "/without-q3"})
      EXPECT_TRUE(stats["seconds"].contains(n + part)) << n << part;
    for (const char* part : {"/A", "/full"})
      EXPECT_FALSE(stats["seconds"].contains(n + part)) << n << part;
  }
  const Image result = readExrLayer(out / "ensemble.exr");
  EXPECT_EQ(result.width(), 36);
  for (float v : result.values()) ASSERT_TRUE(std::isfinite(v));

  // One sub-buffer cannot be split into halves; unknown methods are named.
  const fs::path single = writeRender(dir, 1);
  auto bad = runChorus({"denoise", single.string(), "--methods", methods, "--out", out.string()});
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_NE(bad.err.find("independent sub-buffers"), std::string::npos) << bad.err;
  bad =
      runChorus({"denoise", render.string(), "--methods", "nosuchdenoiser", "--out", out.string()});
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_NE(bad.err.find("unknown denoiser 'nosuchdenoiser'"), std::string::npos) << bad.err;
}

std::vector<std::string> filesIn(const fs::path& dir) {
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(dir)) files.push_back(entry.path().filename());
  std::sort(files.begin(), files.end());
  return files;
}

// relMSE of the image in `file` against the truth, recomputed from the written file.
double relMseOfFile(const fs::path& file, const fs::path& truth) {
  return relMse(readExrLayer(file), readRgbExr(truth));
}

// One method (no --combine) or --combine none: each member alone on the full buffer, no half
// runs, no ensemble; a K = 1 render feeds every member that needs no halves.
TEST(DenoiseCli, MembersAloneOnAOneSubBufferRender) {
  TempDir dir("chorus_denoise_alone");
  const fs::path render = writeRender(dir, 1), truth = writeTruth(dir);
  const fs::path one = dir / "one", two = dir / "two";
  auto r = runChorus({"denoise", render.string(), "--methods", "atrous", "--reference",
                      truth.string(), "--out", one.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(filesIn(one), (std::vector<std::string>{"atrous.exr", "atrous.png", "stats.json"}));
  EXPECT_EQ(layerNames(one / "atrous.exr"), std::vector<std::string>{""});
  // What the member computes on the full buffer, and nothing else ran.
  const Image expected = createDenoiser("atrous")->run(fixtureBuffers(1).input(BufferPart::Full));
  const Image written = readExrLayer(one / "atrous.exr");
  ASSERT_TRUE(written.sameSize(expected));
  EXPECT_TRUE(
      std::equal(written.values().begin(), written.values().end(), expected.values().begin()));
  const json stats = readJson(one / "stats.json");
  EXPECT_EQ(stats["input_kind"], "render.exr");
  EXPECT_EQ(stats["combine"], "none");
  EXPECT_TRUE(stats["seconds"].contains("atrous/full"));
  EXPECT_FALSE(stats["seconds"].contains("atrous/A"));
  const json& m = stats["metrics"];
  EXPECT_NEAR(m["atrous"]["relmse"].get<double>(), relMseOfFile(one / "atrous.exr", truth), 1e-9);
  EXPECT_NEAR(m["noisy"]["relmse"].get<double>(),
              relMse(fixtureBuffers(1).sub(0).color.mean, readRgbExr(truth)), 1e-9);
  EXPECT_LT(m["atrous"]["relmse"].get<double>(), 0.5 * m["noisy"]["relmse"].get<double>());
  for (const char* key : {"dssim", "psnr"}) EXPECT_TRUE(m["atrous"].contains(key)) << key;

  // Several methods, each alone: the same à-trous output beside the others'.
  r = runChorus({"denoise", render.string(), "--methods", "atrous,jnlm,sbf,bilateral", "--combine",
                 "none", "--out", two.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const char* name : {"atrous", "jnlm", "sbf", "bilateral"})
    EXPECT_TRUE(fs::is_regular_file(two / (std::string(name) + ".png"))) << name;
  EXPECT_FALSE(fs::exists(two / "weights.exr"));
  const Image again = readExrLayer(two / "atrous.exr");
  EXPECT_TRUE(std::equal(again.values().begin(), again.values().end(), written.values().begin()));
  EXPECT_EQ(lineCount(r.out), 5) << r.out;  // "wrote" each member's EXR and stats.json

  // --quiet: the same files, nothing on either stream (the progress line needs a terminal).
  const fs::path quiet = dir / "quiet";
  r = runChorus(
      {"denoise", render.string(), "--methods", "atrous", "--quiet", "--out", quiet.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out + r.err, "");
  EXPECT_EQ(filesIn(quiet), (std::vector<std::string>{"atrous.exr", "atrous.png", "stats.json"}));

  // A member that needs halves: one line naming the file, the member and the fix; nothing
  // written.
  const fs::path bad = dir / "bad";
  r = runChorus({"denoise", render.string(), "--methods", "atrous,nfor", "--combine", "none",
                 "--out", bad.string()});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  for (const char* part : {"render1.exr: base denoiser 'nfor' needs two independent halves",
                           "render without --splits 1"})
    EXPECT_NE(r.err.find(part), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(bad));
  // A member listed twice: that alone, not a hint about the input.
  r = runChorus({"denoise", render.string(), "--methods", "atrous,atrous", "--out", bad.string()});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(r.err, "chorus: base denoiser 'atrous' is listed twice\n");
  EXPECT_FALSE(fs::exists(bad));
}

// A render.exr below K spp (rendered with --denoise none, so K = 4): one warning line naming the
// file and how many sub-buffers are empty (stderr unless --quiet, and stats.json); none at K spp.
TEST(DenoiseCli, WarnsWhenSubBuffersHoldNoSamples) {
  TempDir dir("chorus_denoise_empty");
  const std::string scene = (test::sourceDir() / "scenes" / "cornell-box.gltf").string();
  for (const char* spp : {"2", "4"}) {
    const fs::path render = dir / (std::string("r") + spp);
    auto r = runChorus({"render", scene, "--width", "8", "--spp", spp, "--denoise", "none",
                        "--quiet", "--out", render.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::string input = (render / "render.exr").string();
    for (bool quiet : {false, true}) {
      const fs::path out = dir / (std::string("d") + spp + (quiet ? "q" : ""));
      std::vector<std::string> args = {"denoise", input,   "--methods",
                                       "atrous",  "--out", out.string()};
      if (quiet) args.push_back("--quiet");
      r = runChorus(args);
      ASSERT_EQ(r.exitCode, 0) << r.err;
      const json warnings = readJson(out / "stats.json")["warnings"];
      if (std::string(spp) == "4") {
        EXPECT_EQ(r.err, "");
        EXPECT_EQ(warnings, json::array());
        continue;
      }
      const std::string warning =
          input +
          ": 2 of its 4 sub-buffers hold no samples, which leaves the members and their weights "
          "less to work with: render at least 4 spp (or, below 3 spp, denoise in chorus render)";
      EXPECT_EQ(warnings, json({warning}));
      EXPECT_EQ(r.err, quiet ? "" : "chorus: warning: " + warning + "\n");
    }
    // A run that fails says its one error line only.
    r = runChorus(
        {"denoise", input, "--methods", "atrous,atrous", "--out", (dir / "bad").string()});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.err, "chorus: base denoiser 'atrous' is listed twice\n");
  }
}

// --threads T bounds the run's workers (stats.json says how many); the result is the same for
// any count; out-of-range counts are refused in one line.
TEST(DenoiseCli, ThreadsChangeNothingButTheWorkers) {
  TempDir dir("chorus_denoise_threads");
  const fs::path render = writeRender(dir, 4);
  const auto run = [&](const std::string& threads, const std::string& name) {
    std::vector<std::string> args = {
        "denoise", render.string(), "--methods",          "nfor,atrous",
        "--quiet", "--out",         (dir / name).string()};
    if (!threads.empty()) args.insert(args.end(), {"--threads", threads});
    return runChorus(args);
  };
  auto r = run("", "all");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = run("1", "one");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(readJson(dir / "one" / "stats.json")["threads"], 1);
  EXPECT_EQ(readJson(dir / "all" / "stats.json")["threads"], 0);
  const Image all = readExrLayer(dir / "all" / "ensemble.exr");
  const Image one = readExrLayer(dir / "one" / "ensemble.exr");
  ASSERT_TRUE(all.sameShape(one));
  EXPECT_TRUE(std::equal(all.values().begin(), all.values().end(), one.values().begin()));
  for (const char* bad : {"-1", "1025", "two"}) {
    r = run(bad, "bad");
    EXPECT_EQ(r.exitCode, 2) << bad;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("--threads"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "bad"));
  }
}

// NFOR, RDFC and dual-buffer NL-means alone on a K = 2 render (the full buffer's two halves);
// the ensemble needs K = 4 for them and says how to run them instead.
TEST(DenoiseCli, HalvesMembersAloneOnATwoSubBufferRender) {
  TempDir dir("chorus_denoise_alone");
  const fs::path render = writeRender(dir, 2), truth = writeTruth(dir), out = dir / "out";
  auto r = runChorus({"denoise", render.string(), "--methods", "nfor,rdfc,nlm", "--combine", "none",
                      "--reference", truth.string(), "--out", out.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const json m = readJson(out / "stats.json")["metrics"];
  for (const char* name : {"nfor", "rdfc", "nlm"}) {
    const double relmse = m[name]["relmse"].get<double>();
    EXPECT_NEAR(relmse, relMseOfFile(out / (std::string(name) + ".exr"), truth), 1e-9) << name;
    EXPECT_LT(relmse, 0.5 * m["noisy"]["relmse"].get<double>()) << name;
  }
  r = runChorus({"denoise", render.string(), "--methods", "nfor,atrous", "--out",
                 (dir / "ensemble").string()});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  for (const char* part :
       {"render2.exr: base denoiser 'nfor' needs two independent halves of its own input",
        "render with --splits 4, or run it alone with --combine none"})
    EXPECT_NE(r.err.find(part), std::string::npos) << r.err;
}

// A Tungsten buffer directory (T.exr, TA.exr, TB.exr, TVariance.exr per buffer) from the two
// sub-buffers of a synthetic render.
fs::path writeTungstenDirectory(const TempDir& dir) {
  const SampleBuffers buffers = fixtureBuffers(2);
  const SubBuffer full = buffers.part(BufferPart::Full);
  const fs::path path = dir / "tungsten";
  fs::create_directories(path);
  for (Quantity q : kAllQuantities) {
    const std::string name(quantityName(q));
    writeExr(path / (name + ".exr"), full.get(q).mean);
    writeExr(path / (name + "A.exr"), buffers.sub(0).get(q).mean);
    writeExr(path / (name + "B.exr"), buffers.sub(1).get(q).mean);
    writeExr(path / (name + "Variance.exr"), full.get(q).varianceOfMean);
  }
  return path;
}

TEST(DenoiseCli, NforAloneOnATungstenDirectory) {
  TempDir dir("chorus_denoise_tungsten");
  const fs::path input = writeTungstenDirectory(dir), truth = writeTruth(dir), out = dir / "out";
  auto r = runChorus({"denoise", input.string(), "--methods", "nfor", "--reference", truth.string(),
                      "--out", out.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(filesIn(out), (std::vector<std::string>{"nfor.exr", "nfor.png", "stats.json"}));
  const Image expected = NforDenoiser().run(readTungstenDirectory(input));
  const Image written = readExrLayer(out / "nfor.exr");
  ASSERT_TRUE(written.sameSize(expected));
  EXPECT_TRUE(
      std::equal(written.values().begin(), written.values().end(), expected.values().begin()));
  const json stats = readJson(out / "stats.json");
  EXPECT_EQ(stats["input_kind"], "tungsten directory");
  EXPECT_EQ(stats["combine"], "none");
  const json& m = stats["metrics"];
  EXPECT_NEAR(m["nfor"]["relmse"].get<double>(), relMseOfFile(out / "nfor.exr", truth), 1e-9);
  EXPECT_LT(m["nfor"]["relmse"].get<double>(), 0.5 * m["noisy"]["relmse"].get<double>());

  // In the ensemble NFOR would need halves of each half; members that need none blend.
  r = runChorus(
      {"denoise", input.string(), "--methods", "nfor,atrous", "--out", (dir / "bad").string()});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("run it alone on the full buffer with --combine none"), std::string::npos)
      << r.err;
  r = runChorus({"denoise", input.string(), "--methods", "atrous,jnlm", "--out",
                 (dir / "ensemble").string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(dir / "ensemble" / "ensemble.exr"));
}

// An outputs directory alone: each method's full-buffer output as it is, with its metrics.
TEST(DenoiseCli, OutputsDirectoryAlone) {
  OutputsFixture f;
  const fs::path out = f.dir / "out";
  const auto r = runChorus({"denoise", f.input.string(), "--methods", "box1,nlm", "--combine",
                            "none", "--reference", f.reference.string(), "--out", out.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(filesIn(out),
            (std::vector<std::string>{"box1.exr", "box1.png", "nlm.exr", "nlm.png", "stats.json"}));
  const Image box1 = readExrLayer(out / "box1.exr");
  const Image& given = f.prepared.bases[0].full;
  EXPECT_TRUE(std::equal(box1.values().begin(), box1.values().end(), given.values().begin()));
  const json m = readJson(out / "stats.json")["metrics"];
  EXPECT_NEAR(m["nlm"]["relmse"].get<double>(), relMse(f.prepared.bases[2].full, f.prepared.truth),
              1e-9);
}

}  // namespace
}  // namespace chorus
