#pragma once
// Helpers shared by the tests: temporary directories, running the chorus binary as a
// subprocess, locating ../shared (skipping cleanly without it), and small synthetic images.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "common/image/image.h"

namespace chorus::test {

// A fresh, empty directory under the system temp dir, removed when the object dies.
class TempDir {
 public:
  explicit TempDir(const std::string& tag = "chorus_test");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

struct ProcessResult {
  int exitCode = -1;
  std::string out, err;
};
// Runs the chorus binary built with the tests with these arguments, capturing both streams.
ProcessResult runChorus(const std::vector<std::string>& args);
// Runs `program` (a path) with these arguments and these variables added to the environment,
// capturing both streams.
ProcessResult runProgram(const std::filesystem::path& program, const std::vector<std::string>& args,
                         const std::vector<std::pair<std::string, std::string>>& environment = {});

// The project's source directory (for scenes/).
std::filesystem::path sourceDir();

// scenes/cornell-box.gltf of this source tree, as a command-line argument.
std::string cornellBox();

// The JSON document in `file` (stats.json and the like).
nlohmann::json readJson(const std::filesystem::path& file);
// ../shared next to the checkout (or $CHORUS_SHARED_DIR), when present.
std::optional<std::filesystem::path> sharedDir();

// Skips the current test when ../shared is absent.
#define CHORUS_REQUIRE_SHARED(var)                                 \
  const auto var##_opt = ::chorus::test::sharedDir();              \
  if (!var##_opt) GTEST_SKIP() << "../shared is absent; skipping"; \
  const std::filesystem::path var = *var##_opt

// An image with i.i.d. uniform values in [lo, hi), seeded.
Image randomImage(int width, int height, int channels, uint32_t seed, float lo = 0.0f,
                  float hi = 1.0f);

// The same size, channels and values bit for bit (two empty images are the same).
bool sameImage(const Image& a, const Image& b);

}  // namespace chorus::test
