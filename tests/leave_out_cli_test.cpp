// What `chorus render` and `chorus denoise` leave out (issue 28): features no chosen member
// reads are not rendered (the rest keeps its bits), member outputs and weight maps are written
// only with --keep, and stats.json says what was written and what was left out.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/image/exr_io.h"
#include "denoise/buffers/buffers_exr.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::cornellBox;
using test::readJson;
using test::runChorus;
using test::TempDir;

// The files in `dir` except the run's bookkeeping (.chorus-files), sorted.
std::vector<std::string> filesIn(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename() != ".chorus-files") names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::string> sorted(std::vector<std::string> names) {
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::string> keysOf(const json& object) {
  std::vector<std::string> keys;
  for (const auto& [key, value] : object.items()) keys.push_back(key);
  return sorted(keys);
}

bool sameBits(const Image& a, const Image& b) {
  return a.sameSize(b) && std::equal(a.values().begin(), a.values().end(), b.values().begin());
}

// À-trous reads no visibility and no feature variance: its render records neither, and the colour,
// features and counts it does record are the bits of a render that records everything.
TEST(LeaveOutCli, ARenderForMembersThatReadFewerFeaturesRecordsOnlyThose) {
  TempDir dir;
  const std::vector<std::string> common = {"render", cornellBox(), "--width", "16",     "--spp",
                                           "8",      "--seed",     "2",       "--quiet"};
  const auto render = [&](const fs::path& out, std::vector<std::string> extra) {
    std::vector<std::string> args = common;
    args.insert(args.end(), extra.begin(), extra.end());
    args.insert(args.end(), {"--out", out.string()});
    const auto r = runChorus(args);
    EXPECT_EQ(r.exitCode, 0) << r.err;
  };
  const fs::path some = dir / "atrous", all = dir / "all";
  render(some, {"--denoise", "atrous"});
  render(all, {"--denoise", "none", "--splits", "2"});

  const std::vector<ExrLayer> layers = readExr(some / "render.exr");
  for (const char* absent :
       {"sub0.visibility", "sub1.visibilityVariance", "sub0.albedoVariance", "sub1.depthVariance"})
    EXPECT_EQ(findLayer(layers, absent), nullptr) << absent;
  for (const char* present : {"", "sub1.color", "sub1.colorVariance", "sub0.albedo", "sub0.normal",
                              "sub1.depth", "sub1.sampleCount"})
    EXPECT_NE(findLayer(layers, present), nullptr) << present;

  const SampleBuffers a = sampleBuffersFromLayers(layers, some / "render.exr");
  const SampleBuffers b = sampleBuffersFromLayers(readExr(all / "render.exr"), all / "render.exr");
  ASSERT_EQ(a.splitCount(), 2);  // à-trous needs no halves of its own input
  ASSERT_EQ(b.splitCount(), 2);
  EXPECT_FALSE(b.sub(0).visibility.mean.empty());
  for (int k = 0; k < 2; ++k) {
    for (const auto& [kept, full] :
         {std::pair{&a.sub(k).color.mean, &b.sub(k).color.mean},
          std::pair{&a.sub(k).color.varianceOfMean, &b.sub(k).color.varianceOfMean},
          std::pair{&a.sub(k).albedo.mean, &b.sub(k).albedo.mean},
          std::pair{&a.sub(k).normal.mean, &b.sub(k).normal.mean},
          std::pair{&a.sub(k).depth.mean, &b.sub(k).depth.mean},
          std::pair{&a.sub(k).sampleCount, &b.sub(k).sampleCount}})
      EXPECT_TRUE(sameBits(*kept, *full)) << k;
    EXPECT_TRUE(a.sub(k).visibility.mean.empty());
  }
  // The full-buffer colour (the default layer, color.png's source) has the same bits too.
  EXPECT_TRUE(sameBits(readExrLayer(some / "render.exr"), readExrLayer(all / "render.exr")));

  const json stats = readJson(some / "stats.json");
  EXPECT_EQ(stats["planes"]["recorded"], json({"albedo", "normal", "depth"}));
  EXPECT_EQ(stats["planes"]["left_out"],
            json({"albedo variance", "normal variance", "depth variance", "visibility",
                  "visibility variance"}));
  EXPECT_EQ(readJson(all / "stats.json")["planes"]["left_out"], json::array());

  // A later `chorus denoise` with a member that reads what the file lacks: one line that says so.
  const auto r = runChorus({"denoise", (some / "render.exr").string(), "--methods", "jnlm", "--out",
                            (dir / "later").string()});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("render.exr: base denoiser 'jnlm' reads albedo variance, normal variance, "
                       "depth variance"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("--denoise none"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "later" / "stats.json"));
}

// A member that calibrates its colour variance to the halves (calibrate=R) reads them although
// it does not need them: a render for it keeps the full buffer's halves. It did not (a render
// with atrous:calibrate=3 wrote the bits of plain atrous: the option did nothing there).
TEST(LeaveOutCli, MembersThatCalibrateGetTheHalves) {
  TempDir dir;
  for (const std::string member : {"atrous", "sbf"}) {
    auto denoised = [&](const std::string& spec) {
      const fs::path out = dir / spec;
      const auto r = runChorus({"render", cornellBox(), "--width", "24", "--spp", "32", "--denoise",
                                spec, "--quiet", "--out", out.string()});
      EXPECT_EQ(r.exitCode, 0) << r.err;
      return readRgbExr(out / "denoised.exr");
    };
    const Image plain = denoised(member), off = denoised(member + ":calibrate=0");
    EXPECT_TRUE(sameBits(plain, off)) << member;  // calibrate=0 is the default
    EXPECT_FALSE(sameBits(plain, denoised(member + ":calibrate=3"))) << member;
  }
}

// By default a render writes what a user looks at and render.exr; --keep adds exactly the files
// it lists, and stats.json lists what was written and what was left out.
TEST(LeaveOutCli, RenderWritesMemberAndWeightFilesOnlyWithKeep) {
  TempDir dir;
  const std::vector<std::string> base = {"render", cornellBox(), "--width",   "12",
                                         "--spp",  "4",          "--denoise", "atrous,bilateral",
                                         "--quiet"};
  const std::vector<std::string> defaults = {"color.png", "denoised.exr", "denoised.png",
                                             "render.exr", "stats.json"};
  const std::vector<std::string> memberFiles = {"atrous.exr", "bilateral.exr"};
  struct Case {
    std::string keep;
    bool members, weights;
  };
  for (const Case& c : std::vector<Case>{{"", false, false},
                                         {"members", true, false},
                                         {"weights", false, true},
                                         {"members,weights", true, true},
                                         {"weights,members,weights", true, true}}) {
    const fs::path out = dir / ("keep-" + c.keep);
    std::vector<std::string> args = base;
    if (!c.keep.empty()) args.insert(args.end(), {"--keep", c.keep});
    args.insert(args.end(), {"--out", out.string()});
    const auto r = runChorus(args);
    ASSERT_EQ(r.exitCode, 0) << r.err;

    std::vector<std::string> expected = defaults, leftOut;
    for (const std::string& f : memberFiles) (c.members ? expected : leftOut).push_back(f);
    (c.weights ? expected : leftOut).push_back("weights.exr");
    EXPECT_EQ(filesIn(out), sorted(expected)) << c.keep;
    const json outputs = readJson(out / "stats.json")["outputs"];
    EXPECT_EQ(sorted(outputs["written"].get<std::vector<std::string>>()), sorted(expected));
    EXPECT_EQ(keysOf(outputs["left_out"]), sorted(leftOut)) << c.keep;
    if (!c.members) {
      EXPECT_EQ(outputs["left_out"]["atrous.exr"], "--keep members");
    }
    if (!c.weights) {
      EXPECT_EQ(outputs["left_out"]["weights.exr"], "--keep weights");
    }
  }
  // The denoised image does not depend on what is kept.
  EXPECT_TRUE(sameBits(readExrLayer(dir / "keep-" / "denoised.exr"),
                       readExrLayer(dir / "keep-members,weights" / "denoised.exr")));

  // A re-render into the same directory without --keep removes the kept files of the previous run.
  const fs::path out = dir / "keep-members,weights";
  std::vector<std::string> args = base;
  args.insert(args.end(), {"--out", out.string()});
  ASSERT_EQ(runChorus(args).exitCode, 0);
  EXPECT_EQ(filesIn(out), defaults);

  // A preview: denoised.png and stats.json, plus what --keep lists.
  const fs::path preview = dir / "preview";
  auto r = runChorus({"render", cornellBox(), "--width", "12", "--preview", "--keep", "weights",
                      "--quiet", "--out", preview.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(filesIn(preview),
            (std::vector<std::string>{"denoised.png", "stats.json", "weights.exr"}));
  const json previewOutputs = readJson(preview / "stats.json")["outputs"];
  EXPECT_EQ(previewOutputs["left_out"]["render.exr"], "without --preview");
  EXPECT_EQ(previewOutputs["left_out"]["denoised.exr"], "without --preview");
}

// `chorus denoise` takes the same flag: the combination by default, members and weight maps on
// request.
TEST(LeaveOutCli, DenoiseWritesMemberAndWeightFilesOnlyWithKeep) {
  TempDir dir;
  const fs::path render = dir / "render";
  ASSERT_EQ(runChorus({"render", cornellBox(), "--width", "12", "--spp", "4", "--denoise", "none",
                       "--quiet", "--out", render.string()})
                .exitCode,
            0);
  const auto denoise = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> args = {"denoise",   (render / "render.exr").string(),
                                     "--methods", "atrous,nlm",
                                     "--out",     (dir / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = runChorus(args);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return readJson(dir / name / "stats.json")["outputs"];
  };
  json outputs = denoise("plain", {});
  EXPECT_EQ(filesIn(dir / "plain"),
            (std::vector<std::string>{"ensemble.exr", "ensemble.png", "stats.json"}));
  EXPECT_EQ(keysOf(outputs["left_out"]),
            (std::vector<std::string>{"atrous.exr", "nlm.exr", "weights.exr"}));
  outputs = denoise("kept", {"--keep", "members,weights", "--combine", "ensemble,average"});
  EXPECT_EQ(filesIn(dir / "kept"),
            (std::vector<std::string>{"atrous.exr", "average.exr", "average.png", "ensemble.exr",
                                      "ensemble.png", "nlm.exr", "stats.json",
                                      "weights-average.exr", "weights.exr"}));
  EXPECT_EQ(sorted(outputs["written"].get<std::vector<std::string>>()), filesIn(dir / "kept"));
  EXPECT_TRUE(outputs["left_out"].empty());
  EXPECT_TRUE(sameBits(readExrLayer(dir / "plain" / "ensemble.exr"),
                       readExrLayer(dir / "kept" / "ensemble.exr")));
}

// `chorus info SCENE --methods LIST` says what a render for LIST records, leaves out and writes:
// à-trous reads feature means only and needs no halves of its own input (2 sub-buffers); NFOR
// reads every plane and needs halves of each of its three inputs (4).
TEST(LeaveOutCli, InfoListsWhatARenderForTheMembersRecordsAndLeavesOut) {
  auto r = runChorus({"info", cornellBox(), "--methods", "atrous"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const char* line :
       {"denoising   atrous: 2 sub-buffer(s)\n", "  records   colour, albedo, normal, depth\n",
        "  left out  albedo variance, normal variance, depth variance, "
        "visibility, visibility variance\n",
        "  writes    render.exr, color.png, denoised.exr, denoised.png, "
        "stats.json\n",
        "  only with weights.exr (--keep weights), atrous.exr (--keep members)"
        "\n",
        "needs       textures: none (no texture lookups)\n"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;

  r = runChorus({"info", cornellBox()});  // the default members
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("denoising   nfor,rdfc,atrous (default): 4 sub-buffer(s)\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  left out  nothing\n"), std::string::npos) << r.out;

  r = runChorus({"info", (test::sourceDir() / "scenes" / "punctual-lights.gltf").string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("textures: 1 material(s) look textures up"), std::string::npos) << r.out;
  // Point and spot lights only, never seen: no emission pass; the Cornell box's light is seen.
  EXPECT_NE(r.out.find("seen emission: none unless --env or --background"), std::string::npos)
      << r.out;
  r = runChorus({"info", cornellBox()});
  EXPECT_NE(r.out.find("seen emission: emissive surfaces seen directly or in mirrors kept out"),
            std::string::npos)
      << r.out;

  r = runChorus({"info", cornellBox(), "--methods", "atrous,nosuch"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("nosuch"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

}  // namespace
}  // namespace chorus
