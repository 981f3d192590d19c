// The stiff rendered scene (scenes/stiff-caustics.gltf: a tiny emitter sealed in a glass ball,
// so that everything it lights is found by rare caustic paths, samples thousands of times the
// mean) as issue 26 first met it: with depth of field (a lens of radius 8 cm focused on the gold
// sphere, 1.6 m away: the wall, the floor and the clear sphere are defocused, their features
// blurred) and an environment (a constant sky, radiance 0.3), at 64×64 and 4, 16 and 64 spp
// (K = 4), against a 4096-spp reference rendered here with its own seed. Every registered member,
// run alone on the full buffer, must beat the noisy input; every run (alone, and the held-out runs
// the ensemble blends) writes finite, non-negative values; the ensemble of all of them must stay
// within 1.1× of its best member. Measured on 2026-12-07, after the guard began to spread a
// sparse tail over an area instead of dropping it: 0.99×, 1.00× and 0.93× at 4, 16 and 64 spp
// (from 2026-12-06 until then 1.12× had to be allowed at 16 spp, where it was 1.06–1.11×).
// docs/outliers.md has the history and the figures at 128×128 against a 2048-spp reference.
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
                         render::EnvironmentDesc::constant(render::Rgb(0.3f)));
  return scene;
}

SampleBuffers renderStiff(int spp, int splits, uint64_t seed) {
  render::RenderOptions options;
  options.width = options.height = kSize;
  options.spp = spp;
  options.splits = splits;
  options.seed = seed;
  options.lensRadius = 0.08f;
  options.focusDistance = 1.6f;
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
  const std::vector<EnsembleMember> members = membersFromSpecs(names);
  const Ensemble ensemble(members, {});
  for (int spp : {4, 16, 64}) {
    const SampleBuffers buffers = renderStiff(spp, 4, uint64_t(spp));
    const double noisy = relMse(buffers.part(BufferPart::Full).color.mean, reference);
    const EnsembleResult result = ensemble.run(buffers);
    // A member is what a user running it alone gets: its run on the full buffer (the ensemble
    // blends the mean of its held-out runs instead).
    const std::vector<Image> alone = runMembersAlone(buffers.input(BufferPart::Full), members);
    std::printf("%3d spp: noisy %.4g", spp, noisy);
    double best = std::numeric_limits<double>::infinity();
    for (size_t m = 0; m < members.size(); ++m) {
      const BaseOutputs& base = result.bases[m];
      for (const Image* out : {&alone[m], &base.full, &base.a, &base.b})
        EXPECT_TRUE(finiteNonNegative(*out)) << base.name << " at " << spp << " spp";
      for (const Image& run : base.heldOut)
        EXPECT_TRUE(finiteNonNegative(run)) << base.name << " at " << spp << " spp";
      const double e = relMse(alone[m], reference);
      std::printf("  %s %.4g", base.name.c_str(), e);
      EXPECT_LT(e, noisy) << base.name << " at " << spp << " spp";
      best = std::min(best, e);
    }
    const double combined = relMse(result.combined.image, reference);
    std::printf("  ensemble %.4g\n", combined);
    EXPECT_TRUE(finiteNonNegative(result.combined.image)) << spp << " spp";
    EXPECT_LE(combined, 1.1 * best) << spp << " spp";
  }
}

}  // namespace
}  // namespace chorus
