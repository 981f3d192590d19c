// Hostile flags and faults, end to end through the chorus binary (issue 27): every bad flag is
// one line naming it with exit code 2 and nothing written; a run that cannot fit in memory says
// so before rendering; bad references fail before the render; an output directory belongs to
// one run at a time and holds one run's files, even after a kill -9.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "common/image/exr_io.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::cornellBox;
using test::readJson;
using test::runChorus;
using test::TempDir;

int lineCount(const std::string& s) {
  return int(std::count(s.begin(), s.end(), '\n'));
}

// Exit code 2, one short line on stderr that names `named`, and no output directory.
void expectRefused(const std::vector<std::string>& args, const std::string& named,
                   const fs::path& out) {
  std::string command;
  for (const std::string& a : args) command += "'" + a + "' ";
  const auto r = runChorus(args);
  EXPECT_EQ(r.exitCode, 2) << command << "\n" << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << command << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("chorus: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(named), std::string::npos) << command << "\n" << r.err;
  EXPECT_LT(r.err.size(), 200u) << r.err;  // no DBL_MAX spelt out in 309 digits
  EXPECT_FALSE(fs::exists(out)) << command;
}

struct BadFlag {
  std::string flag, value;
};

// Every numeric and path flag of render (which has the scene and ensemble flags too), with the
// values the fuzzing campaign found and the edges of each range.
const std::vector<BadFlag> kBadRenderFlags = {
    {"--threads", "2147483647"},
    {"--threads", "1e7"},
    {"--threads", "1e9"},
    {"--threads", "-1"},
    {"--threads", "1025"},
    {"--env-intensity", "nan"},
    {"--env-intensity", "-1"},
    {"--env-intensity", "inf"},
    {"--env-intensity", "1e7"},
    {"--env-rotate", "nan"},
    {"--env-rotate", "inf"},
    {"--env-rotate", "361"},
    {"--seed", "-1"},
    {"--seed", "18446744073709551616"},
    {"--seed", "1e23"},
    {"--seed", "1.5"},
    {"--seed", "0x10"},
    {"--out", ""},
    {"--out", "--image-prior=1,2"},
    {"--width", "100000"},
    {"--width", "0"},
    {"--width", "-5"},
    {"--width", "1e3"},
    {"--height", "65537"},
    {"--spp", "0"},
    {"--spp", "16777217"},
    {"--spp", "nan"},
    {"--max-depth", "0"},
    {"--max-depth", "1025"},
    {"--roulette-depth", "-1"},
    {"--camera", "-1"},
    {"--camera", "1e9"},
    {"--window", "1000000"},
    {"--window", "-1"},
    {"--window-color", "nan"},
    {"--outlier-cap", "nan"},
    {"--outlier-cap", "-1"},
    {"--consistency", "inf"},
    {"--plausibility", "0.5"},
    {"--plausibility", "nan"},
    {"--image-prior", "-0.1"},
    {"--noisy-fallback", "0.5"},
    {"--solver-seed", "-1"},
    {"--background", "1,nan,1"},
    {"--background", "1e7"},
    {"--env", ""},
    {"--env", "--spp"},
    {"--lens-radius", "-0.1"},
    {"--lens-radius", "nan"},
    {"--focus-distance", "inf"},
    {"--reference", ""},
    {"--splits", "3"},
    {"--tracer", "fast"},
    {"--keep", "everything"},
    {"--keep", "members,"},
};

TEST(CliHardening, EveryBadRenderFlagIsOneLineNamingIt) {
  TempDir dir;
  const fs::path out = dir / "out";
  for (const BadFlag& bad : kBadRenderFlags)
    expectRefused({"render", cornellBox(), "--width", "8", "--height", "8", "--spp", "1",
                   "--denoise", "none", "--out", out.string(), bad.flag, bad.value},
                  bad.flag + ":", out);
}

TEST(CliHardening, EveryBadSweepAndDenoiseFlagIsOneLineNamingIt) {
  TempDir dir;
  const fs::path out = dir / "out";
  const std::vector<std::string> sweep = {"sweep",    cornellBox(), "--width",   "8",
                                          "--height", "8",          "--methods", "atrous",
                                          "--combos", "none",       "--out",     out.string()};
  for (const BadFlag& bad : std::vector<BadFlag>{{"--reference-seconds", "nan"},
                                                 {"--reference-seconds", "0"},
                                                 {"--reference-spp", "0"},
                                                 {"--reference-spp", "1e9"},
                                                 {"--crop-size", "0"},
                                                 {"--threads", "1e9"},
                                                 {"--env-rotate", "nan"},
                                                 {"--seed", "-1"},
                                                 {"--out", ""}}) {
    std::vector<std::string> args = sweep;
    args.insert(args.end(), {bad.flag, bad.value});
    expectRefused(args, bad.flag + ":", out);
  }
  std::vector<std::string> args = sweep;
  args.insert(args.end(), {"--spp", "4,16777217"});
  expectRefused(args, "--spp '4,16777217': 16777217 is above 16777216", out);
  for (const BadFlag& bad : std::vector<BadFlag>{{"--out", ""},
                                                 {"--out", "--image-prior=1,2"},
                                                 {"--window", "1000000"},
                                                 {"--noisy-fallback", "nan"},
                                                 {"--keep", "render"}})
    expectRefused({"denoise", (dir / "render.exr").string(), "--methods", "atrous", "--out",
                   out.string(), bad.flag, bad.value},
                  bad.flag + ":", out);
}

// Values at the ends of the ranges are accepted, and seeds are read exactly (no saturation:
// 2^64 − 1 is its own seed; a leading zero is not octal).
TEST(CliHardening, RangeEndsAreAcceptedAndSeedsReadExactly) {
  TempDir dir;
  const auto render = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> args = {
        "render",    cornellBox(), "--width", "4",     "--height",           "4", "--spp", "1",
        "--denoise", "none",       "--quiet", "--out", (dir / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = runChorus(args);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return readJson(dir / name / "stats.json");
  };
  EXPECT_EQ(render("max", {"--seed", "18446744073709551615"})["seed"].get<uint64_t>(),
            std::numeric_limits<uint64_t>::max());
  EXPECT_EQ(render("octal", {"--seed", "010"})["seed"].get<uint64_t>(), 10u);
  const json edges = render("edges", {"--threads", "1024", "--max-depth", "1024", "--env-rotate",
                                      "-360", "--env-intensity", "0", "--background", "1"});
  EXPECT_EQ(edges["threads"], 1024);
  EXPECT_EQ(edges["max_depth"], 1024);
}

// 65536² pixels need terabytes: refused before the render with how much it needs. The film alone
// is 65536² pixels × 4 sub-buffers × 23 float planes.
TEST(CliHardening, ARunThatCannotFitInMemoryIsRefusedBeforeRendering) {
  TempDir dir;
  const fs::path out = dir / "out";
  const double filmGib = 65536.0 * 65536.0 * 4 * 23 * 4 / double(1ull << 30);
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"render", cornellBox(), "--width", "65536", "--height", "65536", "--out", out.string()},
           {"sweep", cornellBox(), "--width", "65536", "--height", "65536", "--methods", "atrous",
            "--out", out.string()}}) {
    const auto r = runChorus(args);
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.err, m,
                                  std::regex("rendering 65536x65536 with 4 sub-buffer\\(s\\) and "
                                             "[13] denoiser\\(s\\) needs ([0-9.]+) GiB, this "
                                             "machine has ([0-9.]+) GiB available")))
        << r.err;
    EXPECT_GE(std::stod(m[1].str()), filmGib);
    EXPECT_FALSE(fs::exists(out));
  }
}

void writeImageWithNan(const fs::path& file, int width, int height, bool allNan) {
  Image image(width, height, 3, 0.5f);
  if (allNan)
    image.fill(std::numeric_limits<float>::quiet_NaN());
  else
    image(1, 1, 2) = std::numeric_limits<float>::quiet_NaN();
  writeExr(file, image);
}

TEST(CliHardening, BadReferencesFailBeforeTheRender) {
  TempDir dir;
  const fs::path out = dir / "out";
  writeExr(dir / "small.exr", Image(8, 8, 3, 0.5f));
  writeImageWithNan(dir / "nan.exr", 16, 16, false);
  // Without --quiet a finished render prints a "rendered" line: one line in all means none ran.
  expectRefused(
      {"render", cornellBox(), "--width", "16", "--height", "16", "--spp", "4096", "--denoise",
       "atrous", "--reference", (dir / "small.exr").string(), "--out", out.string()},
      "small.exr: is 8x8x3, expected 16x16x3", out);
  expectRefused(
      {"render", cornellBox(), "--width", "16", "--height", "16", "--spp", "4", "--denoise",
       "atrous", "--reference", (dir / "nan.exr").string(), "--out", out.string()},
      "nan.exr: 1 pixel(s) are NaN or infinite (the first at x 1, y 1)", out);
}

TEST(CliHardening, AnAllNanSweepReferenceFailsBeforeTheSweep) {
  TempDir dir;
  const fs::path out = dir / "out";
  writeImageWithNan(dir / "nan.exr", 8, 8, true);
  expectRefused(
      {"sweep", cornellBox(), "--width", "8", "--height", "8", "--spp", "4", "--methods", "atrous",
       "--combos", "none", "--reference", (dir / "nan.exr").string(), "--out", out.string()},
      "nan.exr: 64 pixel(s) are NaN or infinite", out);
}

// Holds DIR/.chorus.lock as a chorus run would (flock + pid) while alive.
class HeldLock {
 public:
  explicit HeldLock(const fs::path& dir) {
    fs::create_directories(dir);
    fd_ = ::open((dir / ".chorus.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    EXPECT_EQ(::flock(fd_, LOCK_EX | LOCK_NB), 0);
    const std::string pid = std::to_string(::getpid()) + "\n";
    EXPECT_EQ(::write(fd_, pid.data(), pid.size()), ssize_t(pid.size()));
  }
  ~HeldLock() { ::close(fd_); }

 private:
  int fd_ = -1;
};

TEST(CliHardening, ADirectoryInUseIsRefusedByEveryCommandNamingTheHolder) {
  TempDir dir;
  const fs::path out = dir / "out";
  const HeldLock lock(out);
  const std::string inUse =
      out.string() + ": is in use by another chorus run (pid " + std::to_string(::getpid()) + ")";
  writeExr(dir / "ref.exr", Image(8, 8, 3, 0.5f));
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"render", cornellBox(), "--width", "8", "--height", "8", "--spp", "1", "--out",
            out.string()},
           {"sweep", cornellBox(), "--width", "8", "--height", "8", "--spp", "4", "--methods",
            "atrous", "--combos", "none", "--out", out.string()},
           {"sweep", "--merge", dir.path().string(), "--out", out.string()},
           {"denoise", (dir / "ref.exr").string(), "--methods", "atrous", "--out", out.string()}}) {
    const auto r = runChorus(args);
    EXPECT_EQ(r.exitCode, 2) << args[0] << r.err;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(inUse), std::string::npos) << r.err;
    std::vector<std::string> files;
    for (const auto& entry : fs::directory_iterator(out)) files.push_back(entry.path().filename());
    EXPECT_EQ(files, std::vector<std::string>{".chorus.lock"}) << args[0];
  }
}

// Starts chorus without waiting for it (its output discarded).
pid_t spawnChorus(const std::vector<std::string>& args) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<std::string> copies = args;
    std::string binary = CHORUS_BINARY;
    std::vector<char*> argv = {binary.data()};
    for (std::string& a : copies) argv.push_back(a.data());
    argv.push_back(nullptr);
    if (!std::freopen("/dev/null", "w", stdout) || !std::freopen("/dev/null", "w", stderr))
      std::_Exit(127);
    ::execv(binary.c_str(), argv.data());
    std::_Exit(127);
  }
  return pid;
}

// Waits (bounded) until `pid` holds DIR's lock: the lock file names it.
bool waitForLock(const fs::path& dir, pid_t pid) {
  for (int i = 0; i < 6000; ++i) {
    std::ifstream lock(dir / ".chorus.lock");
    std::string text;
    if (lock >> text && text == std::to_string(pid)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

std::vector<std::string> exrFiles(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".exr") names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

// A finished run P; a long run A into the same directory, a concurrent run B refused naming A,
// then A killed with SIGKILL mid-render (P's files untouched, still consistent) beside a
// temporary file a run killed mid-write left; then run C with other members: it succeeds,
// removes P's member file that C does not write and the stale temporary file.
TEST(CliHardening, ConcurrentRunsKillsAndReRendersLeaveOneRunsFiles) {
  TempDir dir;
  const fs::path out = dir / "out";
  const std::vector<std::string> tiny = {"render",   cornellBox(), "--width",   "8",
                                         "--height", "8",          "--spp",     "4",
                                         "--quiet",  "--out",      out.string()};
  auto withDenoise = [&](const std::string& members) {
    std::vector<std::string> args = tiny;
    args.insert(args.end(), {"--denoise", members, "--keep", "members,weights"});
    return args;
  };
  auto r = runChorus(withDenoise("atrous,jnlm"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(exrFiles(out), (std::vector<std::string>{"atrous.exr", "denoised.exr", "jnlm.exr",
                                                     "render.exr", "weights.exr"}));

  // About a minute of rendering on one thread: it is killed long before it ends.
  const pid_t a =
      spawnChorus({"render", cornellBox(), "--width", "128", "--height", "128", "--spp", "4096",
                   "--threads", "1", "--denoise", "none", "--quiet", "--out", out.string()});
  ASSERT_TRUE(waitForLock(out, a));
  r = runChorus(withDenoise("atrous"));
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("is in use by another chorus run (pid " + std::to_string(a) + ")"),
            std::string::npos)
      << r.err;
  ::kill(a, SIGKILL);
  int status = 0;
  ::waitpid(a, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(readJson(out / "stats.json")["width"], 8);  // P's result, whole
  EXPECT_EQ(readJson(out / "stats.json")["denoise"]["methods"], json({"atrous", "jnlm"}));
  std::ofstream(out / "denoised.exr.tmp4194305_3") << "half-written";

  r = runChorus(withDenoise("atrous,bilateral"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(exrFiles(out), (std::vector<std::string>{"atrous.exr", "bilateral.exr", "denoised.exr",
                                                     "render.exr", "weights.exr"}));
  EXPECT_FALSE(fs::exists(out / "denoised.exr.tmp4194305_3"));
  EXPECT_FALSE(fs::exists(out / ".chorus.lock"));
  EXPECT_EQ(readJson(out / "stats.json")["denoise"]["methods"], json({"atrous", "bilateral"}));

  // A render without denoising leaves no denoised or member file of the previous run either.
  r = runChorus(withDenoise("none"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(exrFiles(out), std::vector<std::string>{"render.exr"});
}

}  // namespace
}  // namespace chorus
