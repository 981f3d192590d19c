#include "tests/support/tiny_sweep.h"

#include "tests/support/test_support.h"

namespace chorus::test {

sweep::SweepConfig tinySweepConfig(const std::filesystem::path& out) {
  sweep::SweepConfig config;
  config.scenes = {sourceDir() / "scenes" / "cornell-box.gltf"};
  config.spps = {4, 8};
  config.methods = {"atrous", "bilateral"};
  config.referenceSpp = 256;
  config.render.width = 32;
  config.render.height = 32;
  config.cropSize = 16;
  config.out = out;
  return config;
}

}  // namespace chorus::test
