#include "tests/support/test_support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace chorus::test {
namespace fs = std::filesystem;

TempDir::TempDir(const std::string& tag) {
  static int counter = 0;
  path_ = fs::temp_directory_path() /
          (tag + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  fs::remove_all(path_);
  fs::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

namespace {
std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

ProcessResult runChorus(const std::vector<std::string>& args) {
  return runProgram(CHORUS_BINARY, args);
}

ProcessResult runProgram(const fs::path& program, const std::vector<std::string>& args,
                         const std::vector<std::pair<std::string, std::string>>& environment) {
  TempDir capture("chorus_capture");
  const fs::path outPath = capture / "stdout", errPath = capture / "stderr";
  // Everything the child needs is built before fork: only exec-safe calls after it.
  std::vector<std::string> words = {program.string()};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<std::string> variables;
  for (char** v = environ; *v; ++v) {
    const std::string variable = *v;
    const std::string name = variable.substr(0, variable.find('='));
    bool replaced = false;
    for (const auto& e : environment) replaced = replaced || e.first == name;
    if (!replaced) variables.push_back(variable);
  }
  for (const auto& [name, value] : environment) variables.push_back(name + "=" + value);
  const auto pointers = [](std::vector<std::string>& strings) {
    std::vector<char*> p;
    for (std::string& s : strings) p.push_back(s.data());
    p.push_back(nullptr);
    return p;
  };
  const std::vector<char*> argv = pointers(words), envp = pointers(variables);
  // Else the child's freopen writes what the test printed so far a second time.
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (!std::freopen(outPath.c_str(), "w", stdout) || !std::freopen(errPath.c_str(), "w", stderr))
      std::_Exit(127);
    ::execve(argv[0], argv.data(), envp.data());
    std::_Exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ProcessResult result;
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.out = slurp(outPath);
  result.err = slurp(errPath);
  return result;
}

fs::path sourceDir() {
  return CHORUS_SOURCE_DIR;
}

std::optional<fs::path> sharedDir() {
  if (const char* env = std::getenv("CHORUS_SHARED_DIR"); env && *env) {
    if (fs::is_directory(env)) return fs::path(env);
    return std::nullopt;
  }
  const fs::path candidate = sourceDir().parent_path() / "shared";
  if (fs::is_directory(candidate)) return candidate;
  return std::nullopt;
}

bool sameImage(const Image& a, const Image& b) {
  return a.sameShape(b) &&
         std::equal(a.values().begin(), a.values().end(), b.values().begin(), b.values().end());
}

Image randomImage(int width, int height, int channels, uint32_t seed, float lo, float hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(lo, hi);
  Image image(width, height, channels);
  for (float& v : image.values()) v = dist(rng);
  return image;
}

std::string cornellBox() {
  return (sourceDir() / "scenes" / "cornell-box.gltf").string();
}

nlohmann::json readJson(const std::filesystem::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

}  // namespace chorus::test
