// `chorus sweep` end to end: a tiny sweep, its shards merged, and clean failures (exit code 2,
// one line naming the bad flag or file, nothing written).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "tests/support/test_support.h"
#include "tools/sweep/sweep_results.h"

namespace chorus {
namespace {

namespace fs = std::filesystem;
using test::runChorus;
using test::TempDir;

// A tiny sweep's arguments; `extra` flags replace the defaults of the same name, and other
// words (scenes) are appended.
std::vector<std::string> tinySweep(const fs::path& out, std::vector<std::string> extra = {}) {
  std::vector<std::pair<std::string, std::string>> flags = {{"--width", "24"},
                                                            {"--height", "24"},
                                                            {"--spp", "4,8"},
                                                            {"--methods", "atrous,bilateral"},
                                                            {"--combiners", "ensemble,average"},
                                                            {"--reference-spp", "64"},
                                                            {"--out", out.string()}};
  std::vector<std::string> args = {"sweep",
                                   (test::sourceDir() / "scenes" / "cornell-box.gltf").string()};
  for (size_t i = 0; i < extra.size(); ++i) {
    const bool isFlag = extra[i].rfind("--", 0) == 0 && i + 1 < extra.size();
    if (!isFlag) {
      args.push_back(extra[i]);
      continue;
    }
    std::erase_if(flags, [&](const auto& f) { return f.first == extra[i]; });
    flags.emplace_back(extra[i], extra[i + 1]);
    ++i;
  }
  for (const auto& [flag, value] : flags) args.insert(args.end(), {flag, value});
  return args;
}

TEST(SweepCli, ShardsMergeIntoTheRowsOfOneRun) {
  TempDir dir;
  for (const char* shard : {"0", "1"}) {
    const auto r =
        runChorus(tinySweep(dir / shard, {"--shard", std::string(shard) + "/2", "--quiet"}));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.err, "");
  }
  const auto merged = runChorus({"sweep", "--merge", (dir / "0").string(), (dir / "1").string(),
                                 "--out", (dir / "all").string()});
  ASSERT_EQ(merged.exitCode, 0) << merged.err;
  EXPECT_NE(merged.out.find("report.html"), std::string::npos) << merged.out;
  EXPECT_NE(merged.out.find("ensemble beats average in"), std::string::npos) << merged.out;
  // 2 cases × (noisy + 2 bases + 1 combination × 2 combiners).
  EXPECT_EQ(sweep::readCsv(dir / "all" / "results.csv").size(), 2 * 5u);
  EXPECT_TRUE(fs::exists(dir / "all" / "report.html"));
}

TEST(SweepCli, ProgressLinesWithEta) {
  TempDir dir;
  const auto r = runChorus(tinySweep(dir / "out"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("sweep: [2/2] cornell-box at 8 spp"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ETA 0:00:00"), std::string::npos) << r.err;
}

// Sample counts below K = 4 leave sub-buffers empty: one warning line at the end of the sweep
// naming them (none unless some spp is below 4, none with --quiet).
TEST(SweepCli, WarnsAboutSampleCountsBelowFour) {
  TempDir dir;
  auto r = runChorus(tinySweep(dir / "low", {"--spp", "1,3,4"}));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const std::string warning =
      "chorus: warning: at 1, 3 spp some of the 4 sub-buffers get no samples, which left the "
      "members and their weights less to work with (chorus render denoises with the preview's "
      "members below 3 spp)\n";
  EXPECT_NE(r.err.find(warning), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("warning"), r.err.rfind("warning")) << r.err;  // once
  r = runChorus(tinySweep(dir / "quiet", {"--spp", "2", "--quiet"}));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err, "");
  r = runChorus(tinySweep(dir / "four", {"--spp", "4"}));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

TEST(SweepCli, BadInputIsOneLineNamingIt) {
  TempDir dir;
  const fs::path out = dir / "out";
  struct Case {
    std::vector<std::string> extra;
    std::string named;
  };
  const std::vector<Case> cases = {
      {{"--shard", "2/2"}, "--shard '2/2'"},
      {{"--methods", "atrous,nope"}, "nope"},
      {{"--spp", "4,x"}, "--spp '4,x': 'x' is not a positive integer"},
      {{"--combiners", "ensemble,median"}, "median"},
      {{"--combos", "atrous+nfor"}, "nfor"},
      {{(dir / "missing.gltf").string()}, "missing.gltf: no such file"},
      {{"--reference", (dir / "ref.exr").string()}, "ref.exr: no such file"},
      {{"--merge", (dir / "x").string()}, "--merge takes sweep directories"},
  };
  for (const Case& c : cases) {
    const auto r = runChorus(tinySweep(out, c.extra));
    EXPECT_EQ(r.exitCode, 2) << c.named;
    EXPECT_NE(r.err.find(c.named), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.named;
  }
  const auto merge =
      runChorus({"sweep", "--merge", (dir / "nowhere").string(), "--out", out.string()});
  EXPECT_EQ(merge.exitCode, 2);
  EXPECT_NE(merge.err.find("nowhere: is not a sweep directory"), std::string::npos) << merge.err;
  const auto none = runChorus({"sweep", "--out", out.string()});
  EXPECT_EQ(none.exitCode, 2);
  EXPECT_NE(none.err.find("no scenes given"), std::string::npos) << none.err;
}

}  // namespace
}  // namespace chorus
