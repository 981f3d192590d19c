#pragma once
// The one exception type chorus throws for anything a user can cause (bad file, bad flag,
// unknown denoiser). The CLI prints what() as a single line and exits non-zero.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace chorus {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "scene.gltf: mesh 3 has no POSITION"
inline Error fileError(const std::filesystem::path& file, std::string_view problem) {
  return Error(file.string() + ": " + std::string(problem));
}

}  // namespace chorus
