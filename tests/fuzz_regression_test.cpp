// The fuzzer's regression inputs (tests/fuzz/<target>/, one case per entry, see its README.md)
// replayed through the driver's own checks (tools/fuzz, docs/fuzzing.md), plus a short seeded
// fuzz run and the sandbox's self-test. Each runs build/fuzz/fuzz_inputs as a subprocess: a
// case that crashes or hangs is judged by the driver, not fatal to the test.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "tests/support/test_support.h"

namespace chorus {
namespace {
namespace fs = std::filesystem;

fs::path driver() {
  return fs::path(CHORUS_BINARY).parent_path() / "fuzz" / "fuzz_inputs";
}

fs::path regressionDir() {
  return test::sourceDir() / "tests" / "fuzz";
}

struct DriverRun {
  int exitCode = -1;
  std::string output;
};

DriverRun runDriver(const std::vector<std::string>& args) {
  std::string command = "'";
  command.append(driver().string()).append("'");
  for (const std::string& a : args) command.append(" '").append(a).append("'");
  DriverRun run;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return run;
  std::array<char, 4096> buffer;
  for (size_t n; (n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0;)
    run.output.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// "gltf/accessor-count-2p63.gltf" etc.: every entry of every target directory.
std::vector<std::string> regressionInputs() {
  std::vector<std::string> inputs;
  for (const char* target : {"gltf", "exr", "environment", "cli"}) {
    if (!fs::is_directory(regressionDir() / target)) continue;
    for (const auto& entry : fs::directory_iterator(regressionDir() / target))
      inputs.push_back(std::string(target) + "/" + entry.path().filename().string());
  }
  std::sort(inputs.begin(), inputs.end());
  return inputs;
}

class FuzzRegression : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzRegression, IsRejectedOrHandledCleanly) {
  ASSERT_TRUE(fs::is_regular_file(driver())) << "build the fuzz_inputs target";
  test::TempDir work("chorus_fuzz_regression");
  const DriverRun run = runDriver({"--replay", (regressionDir() / GetParam()).string(), "--work",
                                   work.path().string(), "--timeout", "30", "--cli-timeout", "60"});
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_EQ(run.output.find("FINDING"), std::string::npos) << run.output;
}

INSTANTIATE_TEST_SUITE_P(Inputs, FuzzRegression, ::testing::ValuesIn(regressionInputs()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

// The sandbox tells a clean rejection from a crash, a hang, a sanitizer-free abort and a
// foreign exception (each simulated in a forked child).
TEST(FuzzDriver, JudgesEveryKindOfOutcome) {
  ASSERT_TRUE(fs::is_regular_file(driver())) << "build the fuzz_inputs target";
  const DriverRun run = runDriver({"--self-test"});
  EXPECT_EQ(run.exitCode, 0) << run.output;
}

// The same (seed, target, index) gives the same input: the command in a finding reproduces it.
TEST(FuzzDriver, CasesAreDeterministic) {
  ASSERT_TRUE(fs::is_regular_file(driver())) << "build the fuzz_inputs target";
  for (const char* target : {"gltf", "exr", "environment"}) {
    test::TempDir a("chorus_fuzz_a"), b("chorus_fuzz_b");
    const DriverRun first = runDriver({"--target", target, "--seed", "7", "--case", "3", "--work",
                                       a.path().string(), "--out", (a / "findings").string()});
    const DriverRun second = runDriver({"--target", target, "--seed", "7", "--case", "3", "--work",
                                        b.path().string(), "--out", (b / "findings").string()});
    // The mutation lines between the outcome line (it names the work directory) and the table.
    const auto mutations = [](const std::string& output) {
      const size_t begin = output.find('\n');
      return output.substr(begin, output.find("\n\n") - begin);
    };
    EXPECT_EQ(mutations(first.output), mutations(second.output)) << target;
  }
}

// A short run over every target, fixed seed; bounded by count and, on a slow machine, time.
TEST(FuzzDriver, ShortRunFindsNothing) {
  ASSERT_TRUE(fs::is_regular_file(driver())) << "build the fuzz_inputs target";
  test::TempDir work("chorus_fuzz_short");
  const DriverRun run = runDriver({"--seed", "1", "--count", "240", "--seconds", "25", "--work",
                                   work.path().string(), "--out", (work / "findings").string()});
  EXPECT_EQ(run.exitCode, 0) << run.output;
}

}  // namespace
}  // namespace chorus
