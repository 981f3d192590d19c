// The Slurm recipe (tools/slurm/) end to end, without Slurm: tools/slurm/submit_sweep.sh with a
// stand-in sbatch (tests/support/fake_sbatch.sh) that runs the array's four tasks as parallel
// processes, each one shard of the sweep, then the merge job. The merged results.csv must hold
// exactly the rows of the same sweep run in one process (every metric equal; only the times
// differ), and each shard must have run one case of the four.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/support/test_support.h"
#include "tools/sweep/sweep_results.h"

namespace chorus {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::string readText(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Two scenes × two spp: four cases, one per shard.
std::vector<std::string> sweepArguments(const std::string& methods = "atrous,bilateral") {
  const fs::path scenes = test::sourceDir() / "scenes";
  return {(scenes / "cornell-box.gltf").string(),
          (scenes / "glass-and-metal.gltf").string(),
          "--width",
          "20",
          "--height",
          "16",
          "--spp",
          "2,4",
          "--methods",
          methods,
          "--combiners",
          "ensemble,average",
          "--reference-spp",
          "32"};
}

// Runs tools/slurm/submit_sweep.sh with `args`, `sbatch` being the stand-in, which records every
// job's outcome in DIR/state/<job id> (ids from 1000 on).
test::ProcessResult submit(const TempDir& dir, const std::vector<std::string>& args) {
  const fs::path bin = dir / "bin", state = dir / "state";
  fs::create_directories(bin);
  fs::create_directories(state);
  if (!fs::exists(bin / "sbatch"))
    fs::create_symlink(test::sourceDir() / "tests" / "support" / "fake_sbatch.sh", bin / "sbatch");
  std::vector<std::string> words = {(test::sourceDir() / "tools" / "slurm" / "submit_sweep.sh")};
  words.insert(words.end(), args.begin(), args.end());
  const char* path = std::getenv("PATH");
  return test::runProgram("/bin/bash", words,
                          {{"PATH", bin.string() + ":" + (path ? path : "/usr/bin:/bin")},
                           {"FAKE_SBATCH_STATE", state.string()},
                           {"CHORUS", CHORUS_BINARY},
                           {"SLURM_CPUS_PER_TASK", "1"}});
}

std::string jobOutcome(const TempDir& dir, int job) {
  return readText(dir / "state" / std::to_string(job));
}

TEST(SlurmSweep, FourParallelShardsMergeIntoTheRowsOfOneRun) {
  TempDir dir("chorus_slurm");
  std::vector<std::string> one = {"sweep"};
  for (const std::string& a : sweepArguments()) one.push_back(a);
  one.insert(one.end(), {"--quiet", "--out", (dir / "one").string()});
  const auto single = test::runChorus(one);
  ASSERT_EQ(single.exitCode, 0) << single.err;

  const fs::path out = dir / "cluster";
  std::vector<std::string> args = {"4", out.string()};
  for (const std::string& a : sweepArguments()) args.push_back(a);
  const auto r = submit(dir, args);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("job array 1000 (4 tasks); merge: job 1001"), std::string::npos) << r.out;
  EXPECT_EQ(jobOutcome(dir, 1000), "ok\n") << readText(out / "logs" / "shard-0.out");
  ASSERT_EQ(jobOutcome(dir, 1001), "ok\n") << readText(out / "logs" / "merge.out");

  for (int shard = 0; shard < 4; ++shard) {
    const fs::path shardDir = out / "shards" / std::to_string(shard);
    int cases = 0;
    for (const auto& entry : fs::directory_iterator(shardDir / "cases"))
      cases += entry.path().extension() == ".csv";
    EXPECT_EQ(cases, 1) << shard;
    EXPECT_NE(readText(out / "logs" / ("shard-" + std::to_string(shard) + ".out"))
                  .find("sweep: 1 case(s) in this shard"),
              std::string::npos)
        << shard;
  }
  const std::vector<sweep::SweepRow> merged = sweep::readCsv(out / "results.csv");
  const std::vector<sweep::SweepRow> reference = sweep::readCsv(dir / "one" / "results.csv");
  ASSERT_EQ(merged.size(), 4 * 5u);  // 4 cases × (noisy, 2 members, 1 combination × 2 combiners)
  ASSERT_EQ(merged.size(), reference.size());
  for (size_t i = 0; i < merged.size(); ++i) {
    const sweep::SweepRow &a = merged[i], &b = reference[i];
    const std::string row = b.scene + " " + std::to_string(b.spp) + " " + b.label();
    EXPECT_EQ(a.scene, b.scene) << row;
    EXPECT_EQ(a.spp, b.spp) << row;
    EXPECT_EQ(a.method, b.method) << row;
    EXPECT_EQ(a.combiner, b.combiner) << row;
    EXPECT_EQ(a.members, b.members) << row;
    EXPECT_EQ(a.relMse, b.relMse) << row;
    EXPECT_EQ(a.dssim, b.dssim) << row;
    EXPECT_EQ(a.psnr, b.psnr) << row;
    EXPECT_EQ(a.smape, b.smape) << row;
  }
  EXPECT_TRUE(fs::is_regular_file(out / "report.html"));
}

TEST(SlurmSweep, AFailedShardLeavesTheMergeUnrun) {
  TempDir dir("chorus_slurm");
  const fs::path out = dir / "cluster";
  std::vector<std::string> args = {"2", out.string()};
  for (const std::string& a : sweepArguments("atrous,nope")) args.push_back(a);
  const auto r = submit(dir, args);
  ASSERT_EQ(r.exitCode, 0) << r.err;  // submitting succeeds; the tasks fail
  EXPECT_EQ(jobOutcome(dir, 1000), "failed\n");
  EXPECT_EQ(jobOutcome(dir, 1001), "never ran\n");
  EXPECT_NE(readText(out / "logs" / "shard-1.out").find("unknown denoiser 'nope'"),
            std::string::npos)
      << readText(out / "logs" / "shard-1.out");
  EXPECT_FALSE(fs::exists(out / "results.csv"));
}

TEST(SlurmSweep, DryRunPrintsEveryJobsCommandAndSubmitsNothing) {
  TempDir dir("chorus_slurm");
  const fs::path out = dir / "cluster";
  const auto r = submit(dir, {"--dry-run", "3", out.string(), "s.gltf", "--spp", "8"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const std::string o = out.string();
  for (const std::string& expected :
       {"sbatch --parsable --array=0-2 --output=" + o + "/logs/shard-%a.out",
        "task 0: " + std::string(CHORUS_BINARY) + " sweep s.gltf --spp 8 --shard 0/3 --out " + o +
            "/shards/0 --threads 1\n",
        "task 2: " + std::string(CHORUS_BINARY) + " sweep s.gltf --spp 8 --shard 2/3 --out " + o +
            "/shards/2 --threads 1\n",
        "sbatch --parsable --dependency=afterok:ARRAY_JOB_ID --output=" + o + "/logs/merge.out",
        "merge: " + std::string(CHORUS_BINARY) + " sweep --merge " + o + "/shards/0 " + o +
            "/shards/1 " + o + "/shards/2 --out " + o + "\n"})
    EXPECT_NE(r.out.find(expected), std::string::npos) << expected << "\nin:\n" << r.out;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(fs::is_empty(dir / "state"));

  const auto bad = submit(dir, {"four", out.string(), "s.gltf"});
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_NE(bad.err.find("usage: tools/slurm/submit_sweep.sh"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace chorus
