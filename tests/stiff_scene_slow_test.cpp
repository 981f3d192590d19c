// The stiff rendered scene (scenes/stiff-caustics.gltf: a tiny emitter sealed in a glass ball,
// so that everything it lights is found by rare caustic paths, samples thousands of times the
// mean) at 64×64 and 4, 16 and 64 spp (K = 4), against a 4096-spp reference rendered here with
// its own seed. Every registered member must beat the noisy input on the full buffer and
// write finite, non-negative values on A, B and the full buffer; the ensemble of all of them
// must stay within 1.1× of its best member at 16 and 64 spp and within 1.3× at 4 spp (measured
// 1.23×: at 64×64 and 4 spp its estimate from the half buffers is the weak point, issue 25).
// docs/outliers.md has the figures at 256×256.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "denoise/base/registry.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/ensemble.h"
#include "renderer/render.h"
#include "renderer/scene/gltf_loader.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

constexpr int kSize = 64;

const render::Scene& stiffScene() {
  static const render::Scene scene =
      render::buildScene(render::loadGltf(test::sourceDir() / "scenes/stiff-caustics.gltf"),
                         render::EnvironmentDesc{});
  return scene;
}

SampleBuffers renderStiff(int spp, int splits, uint64_t seed) {
  render::RenderOptions options;
  options.width = options.height = kSize;
  options.spp = spp;
  options.splits = splits;
  options.seed = seed;
  return render::render(stiffScene(), options).buffers;
}

bool finiteNonNegative(const Image& image) {
  for (float v : image.values())
    if (!std::isfinite(v) || v < 0.0f) return false;
  return true;
}

TEST(StiffScene, MembersBeatTheNoisyInputAndTheEnsembleTracksTheBest) {
  const Image reference = renderStiff(4096, 1, 1000).part(BufferPart::Full).color.mean;
  std::vector<std::string> names;
  for (const DenoiserEntry& entry : builtinDenoisers()) names.push_back(entry.name);
  const Ensemble ensemble(membersFromSpecs(names), {});
  for (int spp : {4, 16, 64}) {
    const SampleBuffers buffers = renderStiff(spp, 4, uint64_t(spp));
    const double noisy = relMse(buffers.part(BufferPart::Full).color.mean, reference);
    const EnsembleResult result = ensemble.run(buffers);
    std::printf("%3d spp: noisy %.4g", spp, noisy);
    double best = std::numeric_limits<double>::infinity();
    for (const BaseOutputs& base : result.bases) {
      for (const Image* out : {&base.full, &base.a, &base.b})
        EXPECT_TRUE(finiteNonNegative(*out)) << base.name << " at " << spp << " spp";
      const double e = relMse(base.full, reference);
      std::printf("  %s %.4g", base.name.c_str(), e);
      EXPECT_LT(e, noisy) << base.name << " at " << spp << " spp";
      best = std::min(best, e);
    }
    const double combined = relMse(result.combined.image, reference);
    std::printf("  ensemble %.4g\n", combined);
    EXPECT_TRUE(finiteNonNegative(result.combined.image)) << spp << " spp";
    EXPECT_LE(combined, (spp == 4 ? 1.3 : 1.1) * best) << spp << " spp";
  }
}

}  // namespace
}  // namespace chorus
