// `chorus compare` run as a subprocess: exit codes, text and JSON output, error lines.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <limits>

#include "common/image/exr_io.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {
using test::runChorus;

class CompareCli : public ::testing::Test {
 protected:
  void SetUp() override {
    // image = reference + 0.1 everywhere: MSE 0.01, PSNR 20 dB.
    writeExr(dir / "ref.exr", {{"", Image(16, 12, 3, 0.5f)}, {"albedo", Image(16, 12, 3, 1.0f)}});
    writeExr(dir / "img.exr", {{"", Image(16, 12, 3, 0.6f)}, {"albedo", Image(16, 12, 3, 1.0f)}});
    writeExr(dir / "small.exr", Image(8, 8, 3, 0.5f));
  }
  test::TempDir dir;
};

TEST_F(CompareCli, PrintsJsonWithEveryMetric) {
  const auto r =
      runChorus({"compare", (dir / "img.exr").string(), (dir / "ref.exr").string(), "--json"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("mse").get<double>(), 0.01, 1e-6);
  EXPECT_NEAR(j.at("relmse").get<double>(), 0.01 / 0.26, 1e-6);
  EXPECT_NEAR(j.at("psnr").get<double>(), 20.0, 1e-4);
  for (const char* key : {"ssim", "dssim", "smape", "width", "height"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j.at("width").get<int>(), 16);
}

TEST_F(CompareCli, ComparesANamedLayer) {
  const auto r = runChorus({"compare", (dir / "img.exr").string(), (dir / "ref.exr").string(),
                            "--layer", "albedo", "--json"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("mse").get<double>(), 0.0);
}

TEST_F(CompareCli, PrintsText) {
  const auto r = runChorus({"compare", (dir / "img.exr").string(), (dir / "ref.exr").string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("relmse"), std::string::npos);
  EXPECT_NE(r.out.find("dssim"), std::string::npos);
}

// Every error is one line on stderr naming the offending file, with exit code 2.
void expectOneLineError(const test::ProcessResult& r, const std::string& mention) {
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find(mention), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST_F(CompareCli, ErrorsNameTheFile) {
  expectOneLineError(
      runChorus({"compare", (dir / "small.exr").string(), (dir / "ref.exr").string()}),
      "small.exr");
  expectOneLineError(
      runChorus({"compare", (dir / "missing.exr").string(), (dir / "ref.exr").string()}),
      "missing.exr");
  std::ofstream(dir / "fake.exr") << "P3 1 1 255 0 0 0";
  expectOneLineError(
      runChorus({"compare", (dir / "img.exr").string(), (dir / "fake.exr").string()}), "fake.exr");
  expectOneLineError(runChorus({"compare", (dir / "img.exr").string(), (dir / "ref.exr").string(),
                                "--layer", "nope"}),
                     "nope");
}

// One NaN would make every metric NaN (printed as null, exit 0 before): the file is refused
// instead, with the count and place of its non-finite pixels.
TEST_F(CompareCli, NonFinitePixelsAreRefusedNamingTheFile) {
  Image image(16, 12, 3, 0.6f);
  image(3, 2, 1) = std::numeric_limits<float>::quiet_NaN();
  writeExr(dir / "nan.exr", image);
  expectOneLineError(
      runChorus({"compare", (dir / "nan.exr").string(), (dir / "ref.exr").string(), "--json"}),
      "nan.exr: 1 pixel(s) are NaN or infinite (the first at x 3, y 2)");
  Image reference(16, 12, 3, 0.5f);
  reference(15, 11, 0) = std::numeric_limits<float>::infinity();
  reference(0, 5, 2) = -std::numeric_limits<float>::infinity();
  writeExr(dir / "inf.exr", reference);
  expectOneLineError(runChorus({"compare", (dir / "img.exr").string(), (dir / "inf.exr").string()}),
                     "inf.exr: 2 pixel(s) are NaN or infinite (the first at x 0, y 5)");
}

TEST(Cli, HelpAndVersion) {
  const auto version = runChorus({"--version"});
  EXPECT_EQ(version.exitCode, 0);
  EXPECT_NE(version.out.find("chorus 0."), std::string::npos) << version.out;
  const auto help = runChorus({"--help"});
  EXPECT_EQ(help.exitCode, 0);
  EXPECT_NE(help.out.find("compare"), std::string::npos);
  const auto compareHelp = runChorus({"compare", "--help"});
  EXPECT_EQ(compareHelp.exitCode, 0);
  EXPECT_NE(compareHelp.out.find("--json"), std::string::npos);
  EXPECT_EQ(runChorus({"no-such-command"}).exitCode, 2);
}

}  // namespace
}  // namespace chorus
