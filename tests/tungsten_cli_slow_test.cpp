// `chorus denoise TUNGSTEN_DIR --methods nfor:guard=0 --reference REF` on every case of the NFOR
// peer data, ../shared/peers/tungsten-nfor/<scene>/spp<N> (skipped without ../shared): the
// command runs NFOR alone on the directory's full buffer with its halves A/B, writes its output
// and its relMSE, and that relMSE is at most 1.03 × that of Tungsten's own NFOR (nfor.exr, the
// NFOR author's implementation on the same inputs), the bound tests/nfor_peer_slow_test.cpp
// holds the library to. With the outlier guard (plain `nfor`, docs/outliers.md) the output is
// no longer the author's algorithm: it must stay within 1.05 × Tungsten's relMSE on every case
// (room 16 spp measured 1.032: the bound on well-measured pixels costs a little there) and be
// better on the glossy scene's fireflies (measured 0.51–0.59×).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/image/exr_io.h"
#include "denoise/metrics/metrics.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

namespace fs = std::filesystem;

constexpr double kMaxRatioToTungsten = 1.03;
constexpr double kMaxGuardedRatio = 1.05;

std::vector<fs::path> sortedDirectories(const fs::path& dir, const std::string& prefix) {
  std::vector<fs::path> dirs;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_directory() && entry.path().filename().string().rfind(prefix, 0) == 0)
      dirs.push_back(entry.path());
  std::sort(dirs.begin(), dirs.end());
  return dirs;
}

TEST(TungstenCli, NforAloneOnEveryPeerCase) {
  CHORUS_REQUIRE_SHARED(shared);
  const fs::path root = shared / "peers/tungsten-nfor";
  test::TempDir out("chorus_tungsten_cli");
  std::printf("%-11s %-6s %-13s %12s %12s %7s\n", "scene", "spp", "method", "relMSE ours",
              "tungsten", "ratio");
  int cases = 0;
  for (const fs::path& scene : sortedDirectories(root, "")) {
    const fs::path referenceFile = scene / "reference.exr";
    const Image reference = readExrLayer(referenceFile);
    for (const fs::path& dir : sortedDirectories(scene, "spp")) {
      const std::string name = scene.filename().string() + " " + dir.filename().string();
      const fs::path caseOut = out / (scene.filename().string() + "-" + dir.filename().string());
      const double tungsten = relMse(readExrLayer(dir / "nfor.exr"), reference);
      for (const bool guarded : {false, true}) {
        const std::string method = guarded ? "nfor" : "nfor:guard=0";
        const std::string label = guarded ? "nfor" : "nfor_guard=0";  // its files and metrics
        const fs::path caseDir = caseOut / (guarded ? "guarded" : "plain");
        const auto r = test::runChorus({"denoise", dir.string(), "--methods", method, "--reference",
                                        referenceFile.string(), "--out", caseDir.string()});
        ASSERT_EQ(r.exitCode, 0) << name << ": " << r.err;
        std::ifstream statsFile(caseDir / "stats.json");
        const nlohmann::json stats = nlohmann::json::parse(statsFile);
        const double ours = stats["metrics"][label]["relmse"].get<double>();
        EXPECT_NEAR(ours, relMse(readExrLayer(caseDir / (label + ".exr")), reference), 1e-9 * ours)
            << name;
        std::printf("%-11s %-6s %-13s %12.6f %12.6f %7.4f\n", scene.filename().c_str(),
                    dir.filename().c_str(), method.c_str(), ours, tungsten, ours / tungsten);
        EXPECT_LE(ours, (guarded ? kMaxGuardedRatio : kMaxRatioToTungsten) * tungsten)
            << name << " " << method;
        if (guarded && scene.filename() == "glossy") {
          EXPECT_LT(ours, tungsten) << name;
        }
      }
      ++cases;
    }
  }
  EXPECT_GE(cases, 6);  // room and glossy at 4, 16 and 64 spp at least
}

}  // namespace
}  // namespace chorus
