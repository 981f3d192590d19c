// The sweep runner on a tiny real render: rows per case, errors that make sense (denoised below
// noisy, the ensemble row equal to an independent recomputation, oracle ≤ ensemble), resume,
// the cached reference, shards + merge equal to one run, and up-front errors.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <tuple>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "denoise/base/registry.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/ensemble.h"
#include "renderer/scene/gltf_loader.h"
#include "tests/support/test_support.h"
#include "tests/support/tiny_sweep.h"
#include "tools/sweep/sweep_directory.h"
#include "tools/sweep/sweep_runner.h"

namespace chorus::sweep {
namespace {

namespace fs = std::filesystem;

const SweepRow& findRow(const std::vector<SweepRow>& rows, int spp, const std::string& method,
                        const std::string& combiner) {
  for (const SweepRow& r : rows)
    if (r.spp == spp && r.method == method && r.combiner == combiner) return r;
  throw std::runtime_error("no row " + method + "/" + combiner);
}

TEST(SweepRunner, RowsPerCaseAndErrorsThatMakeSense) {
  test::TempDir dir;
  const SweepRunStats stats = runSweep(test::tinySweepConfig(dir.path()));
  EXPECT_EQ(stats.casesRun, 2);
  EXPECT_EQ(stats.referencesRendered, 1);
  const std::vector<SweepRow> rows = readCsv(dir / "results.csv");
  ASSERT_EQ(rows.size(), 2 * test::kTinySweepRowsPerCase);
  EXPECT_TRUE(fs::exists(dir / "report.html"));
  EXPECT_TRUE(fs::exists(dir / "cases" / "cornell-box_spp4" / "crops.tsv"));
  for (int spp : {4, 8}) {
    const double noisy = findRow(rows, spp, "noisy", "-").relMse;
    for (const char* base : {"atrous", "bilateral"})
      EXPECT_LT(findRow(rows, spp, base, "-").relMse, noisy) << base << " at " << spp;
    const SweepRow& ensemble = findRow(rows, spp, "atrous+bilateral", "ensemble");
    EXPECT_TRUE(std::isfinite(ensemble.relMse));
    EXPECT_LT(ensemble.relMse, noisy);
    EXPECT_LE(findRow(rows, spp, "atrous+bilateral", "oracle").relMse, ensemble.relMse);
    EXPECT_GE(ensemble.denoiseSeconds, findRow(rows, spp, "atrous", "-").denoiseSeconds);
    EXPECT_DOUBLE_EQ(ensemble.totalSeconds, ensemble.renderSeconds + ensemble.denoiseSeconds);
  }
  EXPECT_LT(findRow(rows, 8, "noisy", "-").relMse, findRow(rows, 4, "noisy", "-").relMse);
}

// The ensemble row equals the error of an ensemble computed here from a render with the same
// options (renders are deterministic for a seed) against the cached reference.
TEST(SweepRunner, EnsembleRowMatchesAnIndependentRecomputation) {
  test::TempDir dir;
  const SweepConfig config = test::tinySweepConfig(dir.path());
  runSweep(config);
  const Image reference = readExrLayer(dir / "references" / "cornell-box.exr");

  const render::Scene scene =
      render::buildScene(render::loadGltf(config.scenes[0]), render::EnvironmentDesc{});
  render::RenderOptions options = config.render;
  options.spp = 4;
  options.splits = 4;
  const Ensemble ensemble(
      {{"atrous", std::shared_ptr<const BaseDenoiser>(createDenoiser("atrous"))},
       {"bilateral", std::shared_ptr<const BaseDenoiser>(createDenoiser("bilateral"))}},
      CombineOptions{});
  const EnsembleResult result = ensemble.run(render::render(scene, options).buffers);
  const double expected = computeMetrics(result.combined.image, reference).relMse;

  const SweepRow& row = findRow(readCsv(dir / "results.csv"), 4, "atrous+bilateral", "ensemble");
  EXPECT_NEAR(row.relMse, expected, 1e-7 * expected);
}

TEST(SweepRunner, ResumesOnlyMissingCasesAndReusesTheReference) {
  test::TempDir dir;
  const SweepConfig config = test::tinySweepConfig(dir.path());
  runSweep(config);
  const fs::path reference = dir / "references" / "cornell-box.exr";
  const auto referenceTime = fs::last_write_time(reference);
  const auto keptTime = fs::last_write_time(dir / "cases" / "cornell-box_spp4.csv");
  fs::remove(dir / "cases" / "cornell-box_spp8.csv");

  const SweepRunStats stats = runSweep(config);
  EXPECT_EQ(stats.casesSkipped, 1);
  EXPECT_EQ(stats.casesRun, 1);
  EXPECT_EQ(stats.ranCases, std::vector<std::string>{"cornell-box_spp8"});
  EXPECT_EQ(stats.referencesRendered, 0);
  EXPECT_EQ(fs::last_write_time(reference), referenceTime);
  EXPECT_EQ(fs::last_write_time(dir / "cases" / "cornell-box_spp4.csv"), keptTime);
  EXPECT_EQ(readCsv(dir / "results.csv").size(), 2 * test::kTinySweepRowsPerCase);

  // Nothing missing: nothing rendered, the summary is rewritten all the same.
  EXPECT_EQ(runSweep(config).casesRun, 0);

  // Other combiners: the existing cases no longer hold the rows this sweep writes.
  SweepConfig fewer = config;
  fewer.combiners = {"ensemble", "average"};
  EXPECT_EQ(runSweep(fewer).casesRun, 2);
  EXPECT_EQ(readCsv(dir / "results.csv").size(), 2 * (1 + 2 + 2u));

  // Other scene settings (here the depth) would mix incomparable rows and reuse a stale
  // reference: refused, naming the settings file, with nothing changed.
  SweepConfig deeper = fewer;
  deeper.render.maxDepth = fewer.render.maxDepth + 1;
  try {
    runSweep(deeper);
    ADD_FAILURE() << "a sweep with other settings ran in the same directory";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("settings.txt"), std::string::npos) << e.what();
  }
  EXPECT_EQ(fs::last_write_time(reference), referenceTime);
}

TEST(SweepRunner, ShardsMergedEqualOneRun) {
  test::TempDir whole, shard0, shard1, merged;
  runSweep(test::tinySweepConfig(whole.path()));
  for (int i = 0; i < 2; ++i) {
    SweepConfig config = test::tinySweepConfig(i == 0 ? shard0.path() : shard1.path());
    config.shard = {i, 2};
    EXPECT_EQ(runSweep(config).casesRun, 1);
  }
  const std::vector<SweepRow> rows = mergeSweeps(merged.path(), {shard0.path(), shard1.path()}, {});
  const std::vector<SweepRow> expected = readCsv(whole / "results.csv");
  ASSERT_EQ(rows.size(), expected.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(
        std::tie(rows[i].scene, rows[i].spp, rows[i].method, rows[i].combiner),
        std::tie(expected[i].scene, expected[i].spp, expected[i].method, expected[i].combiner));
    EXPECT_EQ(rows[i].relMse, expected[i].relMse) << rows[i].label();
    EXPECT_EQ(rows[i].dssim, expected[i].dssim) << rows[i].label();
  }
  EXPECT_TRUE(fs::exists(merged / "report.html"));
  EXPECT_TRUE(fs::exists(merged / "references" / "cornell-box.exr"));
  EXPECT_TRUE(fs::exists(merged / "cases" / "cornell-box_spp8" / "crops.tsv"));
}

TEST(SweepRunner, MergeRefusesConflictingCases) {
  test::TempDir a, b, out;
  SweepRow row;
  row.scene = "room";
  row.spp = 4;
  row.method = "noisy";
  row.combiner = "-";
  for (const auto* dir : {&a, &b}) fs::create_directories(*dir / "cases");
  writeCsv(a / "cases" / "room_spp4.csv", {row});
  row.relMse = 1;
  writeCsv(b / "cases" / "room_spp4.csv", {row});
  try {
    mergeSweeps(out.path(), {a.path(), b.path()}, {});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("room_spp4.csv"), std::string::npos) << e.what();
  }
  EXPECT_THROW(mergeSweeps(out.path(), {out / "nowhere"}, {}), Error);
}

TEST(SweepRunner, BadConfigurationFailsBeforeWriting) {
  test::TempDir dir;
  const fs::path out = dir / "sweep";
  auto expectError = [&](SweepConfig config, const std::string& named) {
    try {
      runSweep(config);
      ADD_FAILURE() << "no error for " << named;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(out)) << named;
  };
  SweepConfig config = test::tinySweepConfig(out);
  config.methods = {"atrous", "nope"};
  expectError(config, "nope");
  config = test::tinySweepConfig(out);
  config.scenes.push_back(dir / "missing.gltf");
  expectError(config, "missing.gltf");
  config = test::tinySweepConfig(out);
  config.references = {dir / "a.exr", dir / "b.exr"};
  expectError(config, "--reference");
  config = test::tinySweepConfig(out);
  config.combiners = {"ensemble", "median"};
  expectError(config, "median");
}

TEST(SweepRunner, ReferenceOfTheWrongSizeIsNamed) {
  test::TempDir dir;
  const fs::path reference = dir / "small.exr";
  writeExr(reference, test::randomImage(16, 16, 3, 1));
  SweepConfig config = test::tinySweepConfig(dir / "sweep");
  config.references = {reference};
  try {
    runSweep(config);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("small.exr: is 16x16 but the renders are 32x32"),
              std::string::npos)
        << e.what();
  }
}

TEST(SweepRunner, ReferenceFromATimeBudget) {
  test::TempDir dir;
  SweepConfig config = test::tinySweepConfig(dir.path());
  config.spps = {4};
  config.referenceSeconds = 0.2;
  EXPECT_EQ(runSweep(config).referencesRendered, 1);
  EXPECT_TRUE(fs::exists(dir / "references" / "cornell-box.exr"));
}

TEST(SweepRunner, ReferenceSppFromATimeBudget) {
  EXPECT_EQ(referenceSppFor(1024, 0, 16, 0.5), 1024);
  EXPECT_EQ(referenceSppFor(1024, 10.5, 16, 0.5), 320);  // 16 spp per 0.5 s for 10 s
  EXPECT_EQ(referenceSppFor(1024, 0.1, 16, 0.5), 16);    // never below the probe
}

}  // namespace
}  // namespace chorus::sweep
